// puncture-app: the real-time puncture app. A 1 kHz haptic thread runs the
// SHF + MSM model driven by a device (mouse and keyboard, the scene's
// scripted insertion, a recorded session, or a UDP bridge to a haptic
// device); the main thread renders the view at 60 Hz. See apps/README.md.
//
//   puncture-app [SCENE] [--device mouse|scripted|replay|udp] [--record FILE]
//                [--offscreen --duration S --screenshot PNG --stats JSON] ...
//   puncture-app --recording FILE --verify        offline bit-for-bit check
//   puncture-app --recording FILE --export-csv F  recording as CSV
// Exit codes: 0 success, 1 error, 2 bad scene (file and JSON path named),
// 3 a replay whose forces differ from the recording.
#include <CLI/CLI.hpp>

#include <pthread.h>
#include <sched.h>

#include <csignal>
#include <deque>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <thread>

#include "puncture/io/provenance.hpp"
#include "puncture/io/provenance_json.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/realtime/device_registry.hpp"
#include "puncture/realtime/force_guard.hpp"
#include "puncture/realtime/haptic_loop.hpp"
#include "puncture/realtime/model_supplier.hpp"
#include "puncture/realtime/pointer_device.hpp"
#include "puncture/realtime/realtime_clock.hpp"
#include "puncture/realtime/recording.hpp"
#include "puncture/realtime/replay.hpp"
#include "puncture/realtime/session_report.hpp"
#include "puncture/realtime/session_statistics.hpp"
#include "puncture/realtime/udp_device.hpp"
#include "puncture/scene_io.hpp"
#include "realtime_view.hpp"

namespace fs = std::filesystem;
using namespace puncture;
using namespace puncture::realtime;

namespace {

struct Options {
  std::string scene;
  std::string device = "mouse";
  std::string recording;    // replay input
  std::string record;       // session output
  bool offscreen = false;
  double duration_s = 0.0;
  std::string screenshot;
  double screenshot_at_s = -1.0;
  std::string stats;
  double fps = 60.0;
  std::string size = "1280x800";
  std::string udp_bind = "127.0.0.1";
  int udp_port = 47011;
  double udp_timeout_s = 0.1;
  bool no_repeat = false;
  double spin_us = 100.0;
  int rt_priority = 80;
  int haptic_cpu = -1;
  double velocity_cutoff_Hz = 100.0;
  std::string export_csv;
  bool verify = false;
  bool quiet = false;
};

std::atomic<bool> interrupted{false};
extern "C" void on_signal(int) { interrupted = true; }

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw SceneError(path.string(), "", "cannot open scene file");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path default_scene_path() {
  const fs::path local = "scenes/default.json";
  if (fs::exists(local)) return local;
  return fs::path(PUNCTURE_SOURCE_DIR) / "scenes" / "default.json";
}

/// Writes `text` to `path` through a temporary name.
void write_file(const fs::path& path, const std::string& text) {
  const fs::path partial = path.string() + ".partial";
  {
    std::ofstream out(partial);
    out << text;
    if (!out.flush()) {
      std::error_code ec;
      fs::remove(partial, ec);
      throw std::runtime_error(path.string() + ": cannot write");
    }
  }
  fs::rename(partial, path);
}

std::string command_line(int argc, char** argv) {
  std::string s;
  for (int i = 0; i < argc; ++i) s += (i ? " " : "") + std::string(i == 0 ? "puncture-app" : argv[i]);
  return s;
}

/// Creates the folder an output file goes to, before the session (not after it).
void prepare_output(const std::string& file) {
  if (file.empty()) return;
  const fs::path parent = fs::path(file).parent_path();
  std::error_code ec;
  if (!parent.empty()) fs::create_directories(parent, ec);
  if (ec) throw std::runtime_error(file + ": cannot create its folder: " + ec.message());
}

// ---------------------------------------------------------------- recording tools

/// --export-csv and --verify on a recording, no session. Exit code 0, or 3
/// when the offline replay's forces differ from the recording.
int run_recording_tools(const Options& o) {
  const Recording rec = read_recording(o.recording);
  if (!o.export_csv.empty()) {
    write_recording_csv(rec, o.export_csv);
    std::cout << "wrote " << o.export_csv << " (" << rec.records.size() << " ticks)\n";
  }
  if (!o.verify) return 0;
  const std::string text = o.scene.empty() ? rec.scene_text() : read_text(o.scene);
  const Scene scene = parse_scene(text, o.scene.empty() ? o.recording + " (recorded scene)" : o.scene);
  const ReplayComparison c = replay_recording(rec, scene);
  std::cout << "replay of " << o.recording << ": " << c.ticks << " ticks, " << c.fresh_tissues
            << " fresh tissues, " << c.mismatches << " ticks differ";
  if (c.mismatches) std::cout << " (first at tick " << c.first_mismatch_tick << ", " << c.first_mismatch_field << ")";
  std::cout << (c.mismatches ? "" : ": forces identical bit for bit") << "\n";
  return c.mismatches ? 3 : 0;
}

// ---------------------------------------------------------------- session set-up

/// The scene of a session and, for a replay, the recording it replays.
struct SessionScene {
  std::optional<Recording> recording;  ///< --device replay: the recorded session
  std::string text, file;              ///< the scene file's text and its name
  Scene scene;
};

/// The recording's own scene for a replay (unless a SCENE is given), else
/// SCENE or scenes/default.json.
SessionScene load_session_scene(const Options& o) {
  SessionScene s;
  if (o.device == "replay") {
    if (o.recording.empty()) throw std::runtime_error("--device replay needs --recording FILE");
    s.recording = read_recording(o.recording);
  }
  if (s.recording && o.scene.empty()) {
    s.text = s.recording->scene_text();
    s.file = o.recording + " (recorded scene)";
  } else {
    s.file = (o.scene.empty() ? default_scene_path() : fs::path(o.scene)).string();
    s.text = read_text(s.file);
  }
  s.scene = parse_scene(s.text, s.file);
  return s;
}

/// What a session needs beyond a valid scene: a display, at most 16 layers,
/// and a duration when offscreen (unless replaying).
void check_session(const Options& o, const Scene& scene) {
  // VTK's X11 render window (also offscreen) needs a display; without one it crashes.
  const char* display = std::getenv("DISPLAY");
  if (!display || !*display)
    throw std::runtime_error(std::string("no X display (DISPLAY is not set): run in a desktop session") +
                             (o.offscreen ? ", or under xvfb-run -a" : ", or use --offscreen under xvfb-run -a"));
  if (scene.layers.size() > 16) throw std::runtime_error("puncture-app shows at most 16 layers");
  if (o.offscreen && o.duration_s <= 0.0 && o.device != "replay")
    throw std::runtime_error("--offscreen needs --duration S (or a replay)");
}

/// What the model renders against the device, and the passivity check of it.
struct StabilityCheck {
  RenderedImpedance impedance;
  StabilityAssessment assessment;
};

/// Probes the scene's rendered impedance, assesses it at tick period `dt` (s)
/// and prints both (unless --quiet).
StabilityCheck check_stability(const Options& o, const SessionScene& s, double dt) {
  const Scene& scene = s.scene;
  StabilityCheck c;
  c.impedance = probe_rendered_impedance(scene);
  c.assessment = assess_stability(scene.haptics, dt, c.impedance);
  if (o.quiet) return c;
  std::cout << "[app] scene " << s.file << " (" << scene.layers.size() << " layers, SH degree "
            << scene.realtime.sh_degree << ", " << scene.realtime.haptic_rate_Hz << " Hz, integrator "
            << scene.realtime.integrator << ")\n";
  std::cout << std::setprecision(3) << "[app] rendered stiffness K = " << c.impedance.stiffness_N_per_m * 1e-3
            << " N/mm, shaft damping B = " << c.impedance.damping_N_s_per_m << " N s/m, device damping b = "
            << scene.haptics.device_damping_N_s_per_m << " N s/m: K T/2 + B = "
            << c.assessment.passivity_demand_N_s_per_m << " N s/m\n";
  for (const std::string& w : c.assessment.warnings) std::cout << "[app] warning: " << w << "\n";
  return c;
}

/// Keeps this process's other threads (view, renderer, recorder, model
/// builder: all created after this call inherit it) off the haptic CPU.
void keep_threads_off_haptic_cpu(int haptic_cpu) {
  cpu_set_t others;
  CPU_ZERO(&others);
  const int n = static_cast<int>(std::thread::hardware_concurrency());
  if (haptic_cpu >= n)
    throw std::runtime_error("--haptic-cpu " + std::to_string(haptic_cpu) + ": this machine has " + std::to_string(n) +
                             " CPUs");
  for (int c = 0; c < n; ++c)
    if (c != haptic_cpu) CPU_SET(c, &others);
  if (n > 1) pthread_setaffinity_np(pthread_self(), sizeof others, &others);
}

/// The device of --device; `pointer` and `udp` point at it when it is one of those.
struct DeviceChoice {
  std::unique_ptr<HapticDevice> device;
  PointerDevice* pointer = nullptr;
  UdpDevice* udp = nullptr;
};

DeviceChoice make_device(const Options& o, const SessionScene& s, double dt) {
  DeviceSetup setup;
  setup.scene = &s.scene;
  setup.tick_period_s = dt;
  setup.repeat = !o.no_repeat;
  setup.recording = s.recording ? &*s.recording : nullptr;
  setup.udp.bind_address = o.udp_bind;
  setup.udp.port = static_cast<std::uint16_t>(o.udp_port);
  setup.udp.timeout_s = o.udp_timeout_s;
  DeviceChoice d;
  d.device = realtime::make_device(o.device, setup);
  d.pointer = dynamic_cast<PointerDevice*>(d.device.get());
  d.udp = dynamic_cast<UdpDevice*>(d.device.get());
  if (d.udp && !o.quiet) std::cout << "[app] udp device listening on " << o.udp_bind << ":" << d.udp->port() << "\n";
  return d;
}

/// The writer of --record (null without it).
std::unique_ptr<RecordingWriter> start_recording(const Options& o, const SessionScene& s, const HapticDevice& device,
                                                 const std::string& command) {
  if (o.record.empty()) return nullptr;
  const nlohmann::json provenance = io::provenance_json(io::make_provenance(command));
  return std::make_unique<RecordingWriter>(o.record, recording_header(s.scene, s.file, s.text, device.name(), provenance));
}

/// What the haptic thread hands the view: snapshots, the graph's tick samples,
/// and the state at --screenshot-at.
struct ViewChannels {
  explicit ViewChannels(const RealtimeModel& model)
      : snapshots([&](ViewSnapshot& s) { init_snapshot(s, *model.simulator); }),
        samples(8192),
        capture([&](ViewSnapshot& s) { init_snapshot(s, *model.simulator); }) {}
  HapticLoopSinks sinks(RecordingWriter* recorder) { return {recorder, &snapshots, &samples, &capture}; }

  TripleBuffer<ViewSnapshot> snapshots;
  SpscRing<TickSample> samples;
  TripleBuffer<ViewSnapshot> capture;
};

ViewOptions view_options(const Options& o, const Scene& scene, const RenderedImpedance& impedance) {
  int width = 1280, height = 800;
  if (std::sscanf(o.size.c_str(), "%dx%d", &width, &height) != 2 || width < 200 || height < 150)
    throw std::runtime_error("--size must be WIDTHxHEIGHT (at least 200x150), got '" + o.size + "'");
  ViewOptions vo;
  vo.offscreen = o.offscreen;
  vo.width = width;
  vo.height = height;
  vo.title = "puncture-app: " + scene.name;
  vo.graph_max_force_N = 1.15 * std::max(impedance.peak_force_N, 0.1);
  return vo;
}

HapticLoopOptions loop_options(const Options& o, const Scene& scene, const StabilityAssessment& stability) {
  const double rate = scene.realtime.haptic_rate_Hz;
  HapticLoopOptions lo;
  lo.max_ticks = o.duration_s > 0.0 ? static_cast<std::int64_t>(std::llround(o.duration_s * rate)) : 0;
  lo.spin_margin_s = o.spin_us * 1e-6;
  lo.realtime_priority = o.rt_priority;
  lo.cpu = o.haptic_cpu;
  lo.snapshot_rate_Hz = std::min(rate, 2.0 * o.fps);
  lo.velocity_cutoff_Hz = o.velocity_cutoff_Hz;
  lo.stability_warning = !stability.warnings.empty();
  lo.capture_at_s = o.screenshot.empty() ? -1.0 : o.screenshot_at_s;
  return lo;
}

// ---------------------------------------------------------------- the view (main thread)

/// Renders the frames of a session on this thread while the haptic thread runs.
class FrameDriver {
 public:
  FrameDriver(const Options& o, HapticLoop& loop, RealtimeView& view, ViewChannels& channels, ViewStatus status,
              const std::optional<Recording>& recording)
      : o_(o), loop_(loop), view_(view), channels_(channels), status_(std::move(status)), recording_(recording) {}

  /// Frames at --fps until the loop finishes, the window closes or a signal arrives.
  void run() {
    if (!o_.offscreen) {
      view_.run_interactive(static_cast<int>(std::lround(1000.0 / o_.fps)), [this] { return frame(); });
      return;
    }
    double next = monotonic_now_s();
    while (frame()) {
      next += 1.0 / o_.fps;
      const double now = monotonic_now_s();
      if (next < now) next = now;  // behind: render the next frame at once, no burst
      sleep_until_s(next);
    }
  }

  /// After the loop stopped. Offscreen (or for a screenshot): one last frame
  /// with the final state. An interactive window may be closed already: it is
  /// not drawn again.
  void finish() {
    if (o_.offscreen || (!o_.screenshot.empty() && !screenshot_taken_)) {
      final_frame_ = true;
      frame();
    }
    if (!o_.screenshot.empty() && !screenshot_taken_) view_.screenshot(o_.screenshot);
  }

  const ViewStatistics& statistics() const { return statistics_; }

 private:
  /// One frame; false when the session is over.
  bool frame() {
    const double start = monotonic_now_s();
    TickSample s;
    while (channels_.samples.try_pop(s)) view_.add_sample(s);
    channels_.snapshots.update();
    update_status(start);
    if (!screenshot_taken_ && channels_.capture.update()) {
      // The state at --screenshot-at, captured by the haptic thread at that tick.
      view_.render(channels_.capture.front(), status_, true, channels_.capture.front().needle.time_s);
      view_.screenshot(o_.screenshot);
      screenshot_taken_ = true;
    }
    view_.render(channels_.snapshots.front(), status_, final_frame_);
    statistics_.add(start, monotonic_now_s());
    return !loop_.finished() && !interrupted;
  }

  /// Live rates over the last second (the first frames include start-up).
  void update_status(double start) {
    const std::int64_t ticks = loop_.ticks_done();
    recent_.push_back({start, ticks});
    while (recent_.size() > 2 && start - recent_.front().first > 1.0) recent_.pop_front();
    const double span = start - recent_.front().first;
    status_.haptic_rate_Hz = span > 0.2 ? (ticks - recent_.front().second) / span : 0.0;
    status_.view_fps = span > 0.2 ? (recent_.size() - 1) / span : 0.0;
    status_.missed_deadlines = loop_.missed_so_far();
    if (recording_)
      status_.note = "replay: tick " + std::to_string(ticks) + " of " + std::to_string(recording_->records.size());
  }

  const Options& o_;
  HapticLoop& loop_;
  RealtimeView& view_;
  ViewChannels& channels_;
  ViewStatus status_;
  const std::optional<Recording>& recording_;
  ViewStatistics statistics_;
  std::deque<std::pair<double, std::int64_t>> recent_;  // (frame start, haptic ticks done)
  bool screenshot_taken_ = false, final_frame_ = false;
};

ViewStatus initial_status(const Scene& scene, const HapticDevice& device, const StabilityAssessment& stability) {
  ViewStatus status;
  status.scene_name = scene.name;
  status.device_name = device.name();
  status.warnings = stability.warnings;
  return status;
}

// ---------------------------------------------------------------- the end of a session

/// What a session leaves once the loop stopped.
struct SessionEnd {
  std::string started_utc;
  nlohmann::json load_before, load_after;  ///< load averages around the session
  std::vector<std::vector<PunctureEvent>> events;  ///< per tissue, in order
  std::int64_t recorded_ticks = 0;
  std::string supplier_error;  ///< empty unless building a fresh tissue failed
};

/// Stops the model builder and the recorder; throws if the haptic loop stopped on an error.
void end_session(ModelSupplier& models, RecordingWriter* recorder, const HapticLoop& loop, SessionEnd& end) {
  end.load_after = load_average_json();
  end.events = models.finish();
  if (recorder) end.recorded_ticks = recorder->finish();
  if (!loop.error().empty()) throw std::runtime_error("haptic loop stopped: " + loop.error());
  end.supplier_error = models.error();
}

/// The --stats JSON (README: Statistics); its sections come from session_statistics.hpp.
nlohmann::json session_statistics(const Options& o, const std::string& command, const SessionScene& s,
                                  const DeviceChoice& device, const StabilityCheck& stability, double dt,
                                  const HapticLoop& loop, const ViewStatistics& view, const SessionEnd& end) {
  const Scene& scene = s.scene;
  const HapticLoopCounters& c = loop.counters();
  nlohmann::json j;
  j["provenance"] = io::provenance_json(io::make_provenance(command));
  j["provenance"]["session_start_utc"] = end.started_utc;
  j["scene"] = {{"name", scene.name}, {"file", s.file}};
  j["device"] = device.device->name();
  j["duration_requested_s"] = o.duration_s;
  j["offscreen"] = o.offscreen;
  j["haptic"] = haptic_session_json(loop, scene.realtime.haptic_rate_Hz, o.spin_us);
  j["view"] = view_session_json(view, o.fps, c);
  j["guard"] = guard_json(scene.haptics, c);
  j["stability"] = stability_json(scene.haptics, dt, stability.impedance, stability.assessment);
  j["puncture_events"] = puncture_events_json(scene, end.events);
  if (!o.record.empty()) j["recording"] = {{"file", o.record}, {"ticks", end.recorded_ticks}};
  if (s.recording) j["replay"] = replay_json(o.recording, s.recording->records.size(), c);
  if (device.udp) j["udp"] = udp_json(*device.udp);
  j["load_average"] = {{"before", end.load_before}, {"after", end.load_after}};
  if (!end.supplier_error.empty()) j["model_supplier_error"] = end.supplier_error;
  return j;
}

/// The console summary of a session (`stats` is session_statistics()).
void print_summary(const Options& o, const nlohmann::json& stats, const HapticLoop& loop, const ViewStatistics& view,
                   const SessionEnd& end, const std::optional<Recording>& recording) {
  const LoopStatistics& st = loop.statistics();
  const HapticLoopCounters& c = loop.counters();
  const nlohmann::json& h = stats["haptic"];
  std::cout << std::fixed << std::setprecision(1) << "[app] haptic " << h["achieved_rate_Hz"].get<double>()
            << " Hz over " << st.count << " ticks; period p50 " << h["tick_period_us"]["p50"].get<double>()
            << " us, p99 " << h["tick_period_us"]["p99"].get<double>() << " us, max "
            << h["tick_period_us"]["max"].get<double>() << " us; compute p50 "
            << h["tick_compute_us"]["p50"].get<double>() << " us, p99 " << h["tick_compute_us"]["p99"].get<double>()
            << " us; missed deadlines " << st.missed_deadlines << "; " << loop.scheduling() << "\n";
  std::cout << "[app] view " << view.achieved_rate_Hz() << " fps over " << view.count << " frames\n";
  std::cout << "[app] guard: magnitude clamped " << c.magnitude_clamped << " ticks, rate clamped " << c.rate_clamped
            << " ticks\n";
  if (!o.record.empty()) std::cout << "[app] recorded " << end.recorded_ticks << " ticks to " << o.record << "\n";
  if (recording)
    std::cout << "[app] replay: " << c.replay_compared << " of " << recording->records.size()
              << " ticks compared, " << c.replay_mismatches << " differ"
              << (c.replay_mismatches == 0 ? " (forces identical bit for bit)" : "") << "\n";
  if (!o.screenshot.empty()) std::cout << "[app] screenshot " << o.screenshot << "\n";
  if (!o.stats.empty()) std::cout << "[app] statistics " << o.stats << "\n";
}

// ---------------------------------------------------------------- the session

/// A live session: haptic thread + view on this thread, then the report.
/// Exit code 0, or 3 when a replay's forces differ from the recording.
int run_session(const Options& o, const std::string& command) {
  const SessionScene s = load_session_scene(o);
  const Scene& scene = s.scene;
  check_session(o, scene);
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  const StabilityCheck stability = check_stability(o, s, dt);
  if (o.haptic_cpu >= 0) keep_threads_off_haptic_cpu(o.haptic_cpu);

  ModelSupplier models(scene_model_builder(scene));
  const DeviceChoice device = make_device(o, s, dt);
  std::unique_ptr<RecordingWriter> recorder = start_recording(o, s, *device.device, command);
  ViewChannels channels(*models.initial());
  RealtimeView view(scene, *models.initial(), view_options(o, scene, stability.impedance), device.pointer);
  HapticLoop loop(scene, models, *device.device, ForceGuard(scene.haptics, dt),
                  loop_options(o, scene, stability.assessment), channels.sinks(recorder.get()));

  SessionEnd end;
  end.load_before = load_average_json();
  end.started_utc = io::utc_timestamp();
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  FrameDriver frames(o, loop, view, channels, initial_status(scene, *device.device, stability.assessment),
                     s.recording);
  loop.start();
  frames.run();
  loop.request_stop();
  loop.join();
  frames.finish();
  end_session(models, recorder.get(), loop, end);

  const nlohmann::json stats =
      session_statistics(o, command, s, device, stability, dt, loop, frames.statistics(), end);
  if (!o.stats.empty()) write_file(o.stats, stats.dump(2) + "\n");
  if (!o.quiet) print_summary(o, stats, loop, frames.statistics(), end, s.recording);
  if (!end.supplier_error.empty()) throw std::runtime_error("building a fresh tissue failed: " + end.supplier_error);
  if (s.recording && !replay_identical(loop.counters(), s.recording->records.size())) return 3;
  return 0;
}

int run(const Options& o, const std::string& command) {
  if ((o.verify || !o.export_csv.empty()) && o.recording.empty())
    throw std::runtime_error("--verify and --export-csv need --recording FILE");
  for (const std::string* f : {&o.record, &o.stats, &o.screenshot, &o.export_csv}) prepare_output(*f);
  if (!o.recording.empty() && (o.verify || !o.export_csv.empty())) return run_recording_tools(o);
  return run_session(o, command);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"puncture-app: real-time needle puncture (1 kHz haptic thread, 60 Hz VTK view)"};
  app.add_option("scene", o.scene, "Scene or tuned preset (JSON); default: scenes/default.json "
                                   "(a replay uses the recorded scene)");
  std::string devices_help = "The needle device (realtime/README.md, devices):";
  for (const DeviceEntry& e : registered_devices()) devices_help += "\n  " + e.name + ": " + e.description;
  app.add_option("--device", o.device, devices_help + "\ndefault: mouse")->check(CLI::IsMember(device_names()));
  app.add_option("--recording", o.recording, "Recorded session to replay (--device replay), --verify or --export-csv");
  app.add_option("--record", o.record, "Record the session (every haptic tick) to this file");
  app.add_flag("--offscreen", o.offscreen, "Render without a window (under Xvfb in CI); needs --duration");
  app.add_option("--duration", o.duration_s, "Stop after this many seconds of haptic time (0: until the window closes)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--screenshot", o.screenshot, "Write a PNG of the view (at the end, or at --screenshot-at)");
  app.add_option("--screenshot-at", o.screenshot_at_s,
                 "Screenshot of the state at this needle time (s), captured by the haptic thread at that tick");
  app.add_option("--stats", o.stats, "Write the loop statistics (JSON)");
  app.add_option("--fps", o.fps, "View frame rate (default 60)")->check(CLI::Range(1.0, 240.0));
  app.add_option("--size", o.size, "Window size WIDTHxHEIGHT (default 1280x800)");
  app.add_option("--udp-bind", o.udp_bind, "UDP device: local IPv4 address (default 127.0.0.1)");
  app.add_option("--udp-port", o.udp_port, "UDP device: port (default 47011)")->check(CLI::Range(0, 65535));
  app.add_option("--udp-timeout", o.udp_timeout_s, "UDP device: no pose for this long = no pose (s, default 0.1)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--no-repeat", o.no_repeat, "Scripted device: one insertion, no fresh tissue afterwards");
  app.add_option("--spin-us", o.spin_us, "Haptic pacing: spin this long before each deadline (default 100)")
      ->check(CLI::Range(0.0, 1000.0));
  app.add_option("--rt-priority", o.rt_priority, "SCHED_FIFO priority of the haptic thread (0: normal; default 80)")
      ->check(CLI::Range(0, 99));
  app.add_option("--haptic-cpu", o.haptic_cpu,
                 "Pin the haptic thread to this CPU and keep the app's other threads off it (default: no pinning)");
  app.add_option("--velocity-cutoff", o.velocity_cutoff_Hz,
                 "Low-pass cut-off (Hz) for velocities differentiated from device positions (default 100; 0: none)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--export-csv", o.export_csv, "With --recording: write the recording as CSV and exit");
  app.add_flag("--verify", o.verify, "With --recording: replay offline and compare the forces bit for bit; exit 3 if they differ");
  app.add_flag("-q,--quiet", o.quiet, "Print nothing but errors");
  CLI11_PARSE(app, argc, argv);

  try {
    return run(o, command_line(argc, argv));
  } catch (const SceneError& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 1;
  }
}
