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
#include "puncture/realtime/force_guard.hpp"
#include "puncture/realtime/haptic_loop.hpp"
#include "puncture/realtime/model_supplier.hpp"
#include "puncture/realtime/pointer_device.hpp"
#include "puncture/realtime/realtime_clock.hpp"
#include "puncture/realtime/recording.hpp"
#include "puncture/realtime/replay.hpp"
#include "puncture/realtime/scripted_device.hpp"
#include "puncture/realtime/session_report.hpp"
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

int run(const Options& o, const std::string& command) {
  if ((o.verify || !o.export_csv.empty()) && o.recording.empty())
    throw std::runtime_error("--verify and --export-csv need --recording FILE");
  for (const std::string* f : {&o.record, &o.stats, &o.screenshot, &o.export_csv}) prepare_output(*f);

  // ---- offline recording tools
  if (!o.recording.empty() && (o.verify || !o.export_csv.empty())) {
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

  // ---- scene (the recording's own scene for a replay, unless one is given)
  std::optional<Recording> recording;
  std::string scene_text, scene_file;
  if (o.device == "replay") {
    if (o.recording.empty()) throw std::runtime_error("--device replay needs --recording FILE");
    recording = read_recording(o.recording);
  }
  if (recording && o.scene.empty()) {
    scene_text = recording->scene_text();
    scene_file = o.recording + " (recorded scene)";
  } else {
    scene_file = (o.scene.empty() ? default_scene_path() : fs::path(o.scene)).string();
    scene_text = read_text(scene_file);
  }
  const Scene scene = parse_scene(scene_text, scene_file);
  // VTK's X11 render window (also offscreen) needs a display; without one it crashes.
  const char* display = std::getenv("DISPLAY");
  if (!display || !*display)
    throw std::runtime_error(std::string("no X display (DISPLAY is not set): run in a desktop session") +
                             (o.offscreen ? ", or under xvfb-run -a" : ", or use --offscreen under xvfb-run -a"));
  if (scene.layers.size() > 16) throw std::runtime_error("puncture-app shows at most 16 layers");
  const double rate = scene.realtime.haptic_rate_Hz;
  const double dt = 1.0 / rate;
  if (o.offscreen && o.duration_s <= 0.0 && o.device != "replay")
    throw std::runtime_error("--offscreen needs --duration S (or a replay)");

  // ---- stability check of what the model renders against the device
  const RenderedImpedance impedance = probe_rendered_impedance(scene);
  const StabilityAssessment stability = assess_stability(scene.haptics, dt, impedance);
  if (!o.quiet) {
    std::cout << "[app] scene " << scene_file << " (" << scene.layers.size() << " layers, SH degree "
              << scene.realtime.sh_degree << ", " << rate << " Hz, integrator " << scene.realtime.integrator << ")\n";
    std::cout << std::setprecision(3) << "[app] rendered stiffness K = " << impedance.stiffness_N_per_m * 1e-3
              << " N/mm, shaft damping B = " << impedance.damping_N_s_per_m << " N s/m, device damping b = "
              << scene.haptics.device_damping_N_s_per_m << " N s/m: K T/2 + B = "
              << stability.passivity_demand_N_s_per_m << " N s/m\n";
    for (const std::string& w : stability.warnings) std::cout << "[app] warning: " << w << "\n";
  }

  // ---- keep this process's other threads (view, renderer, recorder, model
  // builder: all created after this point inherit it) off the haptic CPU
  if (o.haptic_cpu >= 0) {
    cpu_set_t others;
    CPU_ZERO(&others);
    const int n = static_cast<int>(std::thread::hardware_concurrency());
    if (o.haptic_cpu >= n) throw std::runtime_error("--haptic-cpu " + std::to_string(o.haptic_cpu) + ": this machine has " +
                                                    std::to_string(n) + " CPUs");
    for (int c = 0; c < n; ++c)
      if (c != o.haptic_cpu) CPU_SET(c, &others);
    if (n > 1) pthread_setaffinity_np(pthread_self(), sizeof others, &others);
  }

  // ---- models, device, sinks
  ModelSupplier models([&] { return std::make_unique<RealtimeModel>(build_realtime_model(scene)); });
  std::unique_ptr<HapticDevice> device;
  PointerDevice* pointer = nullptr;
  UdpDevice* udp = nullptr;
  if (o.device == "mouse") {
    auto d = std::make_unique<PointerDevice>(scene, dt);
    pointer = d.get();
    device = std::move(d);
  } else if (o.device == "scripted") {
    device = std::make_unique<ScriptedDevice>(scene.insertion, dt, !o.no_repeat);
  } else if (o.device == "replay") {
    device = std::make_unique<ReplayDevice>(*recording);
  } else if (o.device == "udp") {
    UdpDeviceOptions u;
    u.bind_address = o.udp_bind;
    u.port = static_cast<std::uint16_t>(o.udp_port);
    u.timeout_s = o.udp_timeout_s;
    auto d = std::make_unique<UdpDevice>(u);
    udp = d.get();
    if (!o.quiet) std::cout << "[app] udp device listening on " << o.udp_bind << ":" << d->port() << "\n";
    device = std::move(d);
  } else {
    throw std::runtime_error("unknown device '" + o.device + "'");
  }

  std::unique_ptr<RecordingWriter> recorder;
  if (!o.record.empty()) {
    nlohmann::json header = {{"format", "puncture-recording"},
                             {"version", 1},
                             {"scene_file", scene_file},
                             {"scene_text", scene_text},
                             {"device", device->name()},
                             {"haptic_rate_Hz", rate},
                             {"provenance", io::provenance_json(io::make_provenance(command))}};
    nlohmann::json names = nlohmann::json::array();
    for (const Layer& l : scene.layers) names.push_back(l.name);
    header["layers"] = names;
    recorder = std::make_unique<RecordingWriter>(o.record, header);
  }
  TripleBuffer<ViewSnapshot> snapshots([&](ViewSnapshot& s) { init_snapshot(s, *models.initial()->simulator); });
  SpscRing<TickSample> samples(8192);
  TripleBuffer<ViewSnapshot> capture([&](ViewSnapshot& s) { init_snapshot(s, *models.initial()->simulator); });

  int width = 1280, height = 800;
  if (std::sscanf(o.size.c_str(), "%dx%d", &width, &height) != 2 || width < 200 || height < 150)
    throw std::runtime_error("--size must be WIDTHxHEIGHT (at least 200x150), got '" + o.size + "'");
  ViewOptions vo;
  vo.offscreen = o.offscreen;
  vo.width = width;
  vo.height = height;
  vo.title = "puncture-app: " + scene.name;
  vo.graph_max_force_N = 1.15 * std::max(impedance.peak_force_N, 0.1);
  RealtimeView view(scene, *models.initial(), vo, pointer);

  HapticLoopOptions lo;
  lo.max_ticks = o.duration_s > 0.0 ? static_cast<std::int64_t>(std::llround(o.duration_s * rate)) : 0;
  lo.spin_margin_s = o.spin_us * 1e-6;
  lo.realtime_priority = o.rt_priority;
  lo.cpu = o.haptic_cpu;
  lo.snapshot_rate_Hz = std::min(rate, 2.0 * o.fps);
  lo.velocity_cutoff_Hz = o.velocity_cutoff_Hz;
  lo.stability_warning = !stability.warnings.empty();
  lo.capture_at_s = o.screenshot.empty() ? -1.0 : o.screenshot_at_s;
  HapticLoop loop(scene, models, *device, ForceGuard(scene.haptics, dt), lo,
                  HapticLoopSinks{recorder.get(), &snapshots, &samples, &capture});

  const nlohmann::json load_before = load_average_json();
  const std::string started = io::utc_timestamp();
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  // ---- run: haptic thread + view on this thread
  ViewStatus status;
  status.scene_name = scene.name;
  status.device_name = device->name();
  status.warnings = stability.warnings;
  ViewStatistics view_stats;
  std::deque<std::pair<double, std::int64_t>> recent;  // (frame start, haptic ticks done)
  bool screenshot_taken = false, final_frame = false;
  auto frame = [&]() -> bool {
    const double start = monotonic_now_s();
    TickSample s;
    while (samples.try_pop(s)) view.add_sample(s);
    snapshots.update();
    // Live rates over the last second (the first frames include start-up).
    const std::int64_t ticks = loop.ticks_done();
    recent.push_back({start, ticks});
    while (recent.size() > 2 && start - recent.front().first > 1.0) recent.pop_front();
    const double span = start - recent.front().first;
    status.haptic_rate_Hz = span > 0.2 ? (ticks - recent.front().second) / span : 0.0;
    status.view_fps = span > 0.2 ? (recent.size() - 1) / span : 0.0;
    status.missed_deadlines = loop.missed_so_far();
    if (recording)
      status.note = "replay: tick " + std::to_string(ticks) + " of " + std::to_string(recording->records.size());
    if (!screenshot_taken && capture.update()) {
      // The state at --screenshot-at, captured by the haptic thread at that tick.
      view.render(capture.front(), status, true, capture.front().needle.time_s);
      view.screenshot(o.screenshot);
      screenshot_taken = true;
    }
    view.render(snapshots.front(), status, final_frame);
    view_stats.add_frame(start, monotonic_now_s());
    return !loop.finished() && !interrupted;
  };

  loop.start();
  if (o.offscreen) {
    double next = monotonic_now_s();
    while (frame()) {
      next += 1.0 / o.fps;
      const double now = monotonic_now_s();
      if (next < now) next = now;  // behind: render the next frame at once, no burst
      sleep_until_s(next);
    }
  } else {
    view.run_interactive(static_cast<int>(std::lround(1000.0 / o.fps)), frame);
  }
  loop.request_stop();
  loop.join();
  // Offscreen (or for a screenshot): one last frame with the final state. An
  // interactive window may be closed already: it is not drawn again.
  if (o.offscreen || (!o.screenshot.empty() && !screenshot_taken)) {
    final_frame = true;
    frame();
  }
  if (!o.screenshot.empty() && !screenshot_taken) view.screenshot(o.screenshot);

  const nlohmann::json load_after = load_average_json();
  const std::vector<std::vector<PunctureEvent>> events = models.finish();
  std::int64_t recorded = 0;
  if (recorder) recorded = recorder->finish();
  if (!loop.error().empty()) throw std::runtime_error("haptic loop stopped: " + loop.error());
  const std::string supplier_error = models.error();

  // ---- report
  const LoopStatistics& st = loop.statistics();
  const HapticLoopCounters& c = loop.counters();
  nlohmann::json j;
  j["provenance"] = io::provenance_json(io::make_provenance(command));
  j["provenance"]["session_start_utc"] = started;
  j["scene"] = {{"name", scene.name}, {"file", scene_file}};
  j["device"] = device->name();
  j["duration_requested_s"] = o.duration_s;
  j["offscreen"] = o.offscreen;
  j["haptic"] = haptic_statistics_json(st, rate);
  j["haptic"]["scheduling"] = loop.scheduling();
  j["haptic"]["spin_margin_us"] = o.spin_us;
  j["haptic"]["model_ticks"] = c.model_ticks;
  j["haptic"]["held_ticks"] = c.held_ticks;
  j["haptic"]["no_pose_ticks"] = c.no_pose_ticks;
  j["haptic"]["fresh_tissues"] = c.fresh_tissues;
  j["view"] = view_statistics_json(view_stats, o.fps);
  j["view"]["samples_dropped"] = c.samples_dropped;
  j["view"]["snapshots"] = c.snapshots;
  j["guard"] = {{"max_force_N", scene.haptics.max_force_N},
                {"max_force_rate_N_per_s", scene.haptics.max_force_rate_N_per_s},
                {"magnitude_clamped_ticks", c.magnitude_clamped},
                {"rate_clamped_ticks", c.rate_clamped},
                {"max_tissue_force_N", c.max_tissue_force_N},
                {"max_force_sent_N", c.max_sent_force_N}};
  j["stability"] = {{"criterion", "Colgate-Brown passivity: K T / 2 + B <= b"},
                    {"stiffness_K_N_per_m", impedance.stiffness_N_per_m},
                    {"stiffness_layer", impedance.stiffness_layer},
                    {"damping_B_N_s_per_m", impedance.damping_N_s_per_m},
                    {"device_damping_b_N_s_per_m", scene.haptics.device_damping_N_s_per_m},
                    {"tick_period_s", dt},
                    {"passivity_demand_N_s_per_m", stability.passivity_demand_N_s_per_m},
                    {"max_passive_stiffness_N_per_m", stability.max_passive_stiffness_N_per_m},
                    {"passive", stability.passive},
                    {"within_device_stiffness", stability.within_device_stiffness},
                    {"peak_force_scripted_N", impedance.peak_force_N},
                    {"warnings", stability.warnings}};
  nlohmann::json ev = nlohmann::json::array();
  for (std::size_t g = 0; g < events.size(); ++g)
    for (const PunctureEvent& e : events[g])
      ev.push_back({{"tissue", g}, {"layer", scene.layers.at(static_cast<std::size_t>(e.layer)).name}, {"time_s", e.time_s},
                    {"depth_mm", e.depth_m * 1e3}, {"total_force_N", e.total_force_N}});
  j["puncture_events"] = ev;
  if (recorder) j["recording"] = {{"file", o.record}, {"ticks", recorded}};
  if (recording)
    j["replay"] = {{"file", o.recording},
                   {"recorded_ticks", recording->records.size()},
                   {"compared_ticks", c.replay_compared},
                   {"mismatched_ticks", c.replay_mismatches},
                   {"first_mismatch_tick", c.first_mismatch_tick},
                   {"bit_for_bit", c.replay_mismatches == 0 &&
                                       c.replay_compared == static_cast<std::int64_t>(recording->records.size())}};
  if (udp) {
    const UdpDeviceCounters u = udp->counters();
    j["udp"] = {{"port", udp->port()},     {"received", u.received}, {"malformed", u.malformed},
                {"stale", u.stale},        {"lost", u.lost},         {"sent", u.sent},
                {"send_errors", u.send_errors}};
  }
  j["load_average"] = {{"before", load_before}, {"after", load_after}};
  if (!supplier_error.empty()) j["model_supplier_error"] = supplier_error;
  if (!o.stats.empty()) write_file(o.stats, j.dump(2) + "\n");

  if (!o.quiet) {
    const nlohmann::json& h = j["haptic"];
    std::cout << std::fixed << std::setprecision(1) << "[app] haptic " << h["achieved_rate_Hz"].get<double>()
              << " Hz over " << st.ticks << " ticks; period p50 " << h["tick_period_us"]["p50"].get<double>()
              << " us, p99 " << h["tick_period_us"]["p99"].get<double>() << " us, max "
              << h["tick_period_us"]["max"].get<double>() << " us; compute p50 "
              << h["tick_compute_us"]["p50"].get<double>() << " us, p99 " << h["tick_compute_us"]["p99"].get<double>()
              << " us; missed deadlines " << st.missed_deadlines << "; " << loop.scheduling() << "\n";
    std::cout << "[app] view " << view_stats.achieved_fps() << " fps over " << view_stats.frames << " frames\n";
    std::cout << "[app] guard: magnitude clamped " << c.magnitude_clamped << " ticks, rate clamped " << c.rate_clamped
              << " ticks\n";
    if (recorder) std::cout << "[app] recorded " << recorded << " ticks to " << o.record << "\n";
    if (recording)
      std::cout << "[app] replay: " << c.replay_compared << " of " << recording->records.size()
                << " ticks compared, " << c.replay_mismatches << " differ"
                << (c.replay_mismatches == 0 ? " (forces identical bit for bit)" : "") << "\n";
    if (!o.screenshot.empty()) std::cout << "[app] screenshot " << o.screenshot << "\n";
    if (!o.stats.empty()) std::cout << "[app] statistics " << o.stats << "\n";
  }
  if (!supplier_error.empty()) throw std::runtime_error("building a fresh tissue failed: " + supplier_error);
  if (recording && (c.replay_mismatches > 0 || c.replay_compared != static_cast<std::int64_t>(recording->records.size())))
    return 3;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"puncture-app: real-time needle puncture (1 kHz haptic thread, 60 Hz VTK view)"};
  app.add_option("scene", o.scene, "Scene or tuned preset (JSON); default: scenes/default.json "
                                   "(a replay uses the recorded scene)");
  app.add_option("--device", o.device, "mouse (default), scripted, replay or udp")
      ->check(CLI::IsMember({"mouse", "scripted", "replay", "udp"}));
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
