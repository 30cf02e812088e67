// puncture-app as a program, offscreen under Xvfb: the screenshot shows the
// three layers (pixel colours, not an exact image); the statistics file is
// sane and its puncture events are those of the offline model run; the tuned
// preset opens and runs its own calibrated values; a recorded
// session replays bit for bit (and a changed scene does not); the stability
// guard clamps the force sent to the device; a UDP bridge drives the app; a
// bad scene exits 2 naming the file and JSON path.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <nlohmann/json.hpp>
#include <thread>

#include "puncture/model/realtime_model.hpp"
#include "puncture/realtime/recording.hpp"
#include "puncture/realtime/udp_protocol.hpp"
#include "puncture/scene_io.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace puncture::realtime {
namespace {

const std::string kApp = PUNCTURE_APP;
const std::string kDefaultScene = std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json";

fs::path work_dir(const std::string& name) {
  const fs::path d = fs::path(PUNCTURE_BINARY_DIR) / "test_output" / "realtime_app" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

struct ProcessResult {
  int exit_code = -1;
  std::string output;
};

/// Runs a shell command, capturing stdout and stderr.
ProcessResult run(const std::string& command) {
  ProcessResult r;
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), buf.size(), p)) r.output += buf.data();
  const int status = pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

/// puncture-app under a private Xvfb display (the display number is derived from the pid).
ProcessResult app(const std::string& args) {
  const int server = 100 + static_cast<int>(getpid() % 800);
  return run("xvfb-run -a -n " + std::to_string(server) + " -s '-screen 0 1280x1024x24' " + kApp + " " + args);
}

json read_json(const fs::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

/// Fraction of pixels whose chromaticity (r, g)/(r + g + b) lies within `tol` of the colour's.
struct PixelStats {
  double skin = 0, fat = 0, muscle = 0, mean = 0, stddev = 0;
};
PixelStats pixel_stats(const fs::path& png) {
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(png.c_str());
  reader->Update();
  vtkImageData* img = reader->GetOutput();
  int dims[3];
  img->GetDimensions(dims);
  const int nc = img->GetNumberOfScalarComponents();
  auto chroma = [](double r, double g, double b) {
    const double s = r + g + b;
    return std::array<double, 2>{r / s, g / s};
  };
  // Layer colours of the view (apps/README.md): skin, fat, muscle.
  const auto skin = chroma(0.93, 0.74, 0.62), fat = chroma(0.98, 0.86, 0.40), muscle = chroma(0.72, 0.20, 0.22);
  auto near = [](const std::array<double, 2>& a, const std::array<double, 2>& b) {
    return std::hypot(a[0] - b[0], a[1] - b[1]) < 0.025;
  };
  PixelStats s;
  double sum = 0, sum2 = 0;
  const long n = static_cast<long>(dims[0]) * dims[1];
  for (int y = 0; y < dims[1]; ++y)
    for (int x = 0; x < dims[0]; ++x) {
      const auto* p = static_cast<const unsigned char*>(img->GetScalarPointer(x, y, 0));
      const double r = p[0], g = p[1], b = p[2];
      const double v = (r + g + b) / 3.0;
      sum += v;
      sum2 += v * v;
      if (r + g + b < 60) continue;  // too dark to tell
      const auto c = chroma(r, g, b);
      s.skin += near(c, skin);
      s.fat += near(c, fat);
      s.muscle += near(c, muscle);
    }
  (void)nc;
  s.skin /= n;
  s.fat /= n;
  s.muscle /= n;
  s.mean = sum / n;
  s.stddev = std::sqrt(std::max(0.0, sum2 / n - s.mean * s.mean));
  return s;
}

TEST(PunctureApp, OffscreenScriptedRunScreenshotAndStatistics) {
  const fs::path dir = work_dir("scripted");
  const ProcessResult r = app("--device scripted --offscreen --duration 2.0 --size 800x500 --screenshot " +
                    (dir / "view.png").string() + " --screenshot-at 0.3 --stats " + (dir / "stats.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;

  // The screenshot: not blank, and all three layer colours present.
  ASSERT_TRUE(fs::exists(dir / "view.png"));
  const PixelStats px = pixel_stats(dir / "view.png");
  EXPECT_GT(px.stddev, 20.0) << "blank image";
  EXPECT_GT(px.skin, 0.01) << "skin";
  EXPECT_GT(px.fat, 0.01) << "fat";
  EXPECT_GT(px.muscle, 0.01) << "muscle";

  // The statistics: consistent numbers.
  const json s = read_json(dir / "stats.json");
  const json& h = s.at("haptic");
  EXPECT_EQ(h.at("target_rate_Hz").get<double>(), 1000.0);
  EXPECT_EQ(h.at("ticks").get<long>(), 2000);
  const double rate = h.at("achieved_rate_Hz").get<double>();
  EXPECT_GT(rate, 500.0);
  EXPECT_LT(rate, 1050.0);
  const json& p = h.at("tick_period_us");
  EXPECT_LE(p.at("p50").get<double>(), p.at("p99").get<double>());
  EXPECT_LE(p.at("p99").get<double>(), p.at("max").get<double>() + 1e-9);
  EXPECT_GT(p.at("p50").get<double>(), 500.0);
  EXPECT_LE(h.at("tick_compute_us").at("p50").get<double>(), h.at("tick_compute_us").at("p99").get<double>());
  // Missed deadlines: a count of ticks, so an integer in [0, ticks]; a skipped period follows only a
  // missed deadline (haptic_loop.cpp: a tick ending past next + dt also ends past next); and the file
  // holds the number the summary line printed.
  const json& missed = h.at("missed_deadlines");
  ASSERT_TRUE(missed.is_number_integer()) << missed;
  EXPECT_GE(missed.get<long>(), 0);
  EXPECT_LE(missed.get<long>(), h.at("ticks").get<long>());
  if (h.at("skipped_periods").get<long>() > 0) EXPECT_GE(missed.get<long>(), 1);
  EXPECT_NE(r.output.find("missed deadlines " + std::to_string(missed.get<long>()) + ";"), std::string::npos)
      << r.output;
  EXPECT_GT(s.at("view").at("frames").get<long>(), 2);
  EXPECT_GT(s.at("view").at("achieved_fps").get<double>(), 0.0);
  EXPECT_TRUE(s.at("provenance").contains("machine"));
  EXPECT_TRUE(s.at("load_average").at("before").is_array());
  EXPECT_FALSE(s.at("stability").at("warnings").empty());  // the default scene's damping is not passive on a Touch

  // The puncture events are the offline model's (`puncture run`): same model, same ticks.
  const Scene scene = load_scene(kDefaultScene);
  RealtimeModel model = build_realtime_model(scene);
  const ScriptedRunResult offline = run_scripted_insertion(model, scene);
  const json& events = s.at("puncture_events");
  ASSERT_EQ(events.size(), offline.events.size());
  for (std::size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i].at("layer").get<std::string>(), scene.layers[offline.events[i].layer].name);
    EXPECT_EQ(events[i].at("depth_mm").get<double>(), offline.events[i].depth_m * 1e3);
    EXPECT_EQ(events[i].at("total_force_N").get<double>(), offline.events[i].total_force_N);
  }
}

TEST(PunctureApp, TunedPresetOpensAndRunsItsOwnParameters) {
  // The committed tuned preset (written by `puncture calibrate`) is a scene file with calibrated force-mesh
  // values: the app opens it, shows three layers, and punctures where the offline model of the preset does,
  // not where the default scene's does.
  const std::string preset = std::string(PUNCTURE_SOURCE_DIR) + "/results/tuned_preset/default_tuned.json";
  ASSERT_TRUE(fs::exists(preset)) << preset;
  const fs::path dir = work_dir("tuned_preset");
  const ProcessResult r = app(preset + " --device scripted --offscreen --duration 2.0 --size 640x400 --screenshot " +
                              (dir / "view.png").string() + " --screenshot-at 0.3 --stats " +
                              (dir / "stats.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const PixelStats px = pixel_stats(dir / "view.png");
  EXPECT_GT(px.stddev, 20.0) << "blank image";
  EXPECT_GT(px.skin, 0.01) << "skin";
  EXPECT_GT(px.fat, 0.01) << "fat";
  EXPECT_GT(px.muscle, 0.01) << "muscle";

  const json s = read_json(dir / "stats.json");
  EXPECT_EQ(s.at("scene").at("name").get<std::string>(), "default_tuned");
  const Scene tuned = load_scene(preset);
  RealtimeModel tuned_model = build_realtime_model(tuned);
  const ScriptedRunResult offline = run_scripted_insertion(tuned_model, tuned);
  const json& events = s.at("puncture_events");
  // The app ran 2 s of the scripted trajectory, the offline model all of it:
  // the app's events are the offline events of those 2 s (a layer that breaks
  // later, e.g. the tuned muscle at about 18 mm = 2.02 s, is not among them).
  const double duration_s = 2.0;
  std::size_t within = 0;
  for (const auto& e : offline.events) within += e.time_s < duration_s - 0.01 ? 1 : 0;
  ASSERT_GE(events.size(), within);
  ASSERT_LE(events.size(), offline.events.size());
  ASSERT_FALSE(events.empty());
  for (std::size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i].at("layer").get<std::string>(), tuned.layers[offline.events[i].layer].name);
    EXPECT_EQ(events[i].at("depth_mm").get<double>(), offline.events[i].depth_m * 1e3);
    EXPECT_EQ(events[i].at("total_force_N").get<double>(), offline.events[i].total_force_N);
  }
  const Scene plain = load_scene(kDefaultScene);
  RealtimeModel plain_model = build_realtime_model(plain);
  const ScriptedRunResult plain_run = run_scripted_insertion(plain_model, plain);
  ASSERT_FALSE(plain_run.events.empty());
  EXPECT_NE(events[0].at("total_force_N").get<double>(), plain_run.events[0].total_force_N)
      << "the app ran the default scene's values, not the preset's";
}

TEST(PunctureApp, RecordedSessionReplaysBitForBit) {
  const fs::path dir = work_dir("replay");
  const fs::path rec = dir / "session.pncrec";
  ProcessResult r = app("--device scripted --offscreen --duration 1.5 --size 480x300 --record " + rec.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_EQ(read_recording(rec).records.size(), 1500u);

  // Replayed in real time through the app (with the view running).
  r = app("--device replay --recording " + rec.string() + " --offscreen --size 480x300 --stats " +
          (dir / "replay.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json s = read_json(dir / "replay.json");
  EXPECT_TRUE(s.at("replay").at("bit_for_bit").get<bool>());
  EXPECT_EQ(s.at("replay").at("compared_ticks").get<long>(), 1500);
  EXPECT_EQ(s.at("replay").at("mismatched_ticks").get<long>(), 0);

  // Offline check, and a scene one part in a billion stiffer does not replay.
  r = run(kApp + " --recording " + rec.string() + " --verify");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("identical bit for bit"), std::string::npos) << r.output;
  std::ifstream in(kDefaultScene);
  json scene = json::parse(in);
  scene["layers"][0]["force_mesh"]["K_N_per_mm"] = 0.16 * (1.0 + 1e-9);
  std::ofstream(dir / "stiffer.json") << scene.dump(2);
  r = run(kApp + " " + (dir / "stiffer.json").string() + " --recording " + rec.string() + " --verify");
  EXPECT_EQ(r.exit_code, 3) << r.output;

  // CSV export: one row per tick.
  r = run(kApp + " --recording " + rec.string() + " --export-csv " + (dir / "session.csv").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream csv(dir / "session.csv");
  std::string line;
  long rows = -1;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 1500);
}

TEST(PunctureApp, GuardClampsTheForceSentToTheDevice) {
  const fs::path dir = work_dir("guard");
  std::ifstream in(kDefaultScene);
  json scene = json::parse(in);
  scene["haptics"] = {{"max_force_N", 0.5}, {"max_force_rate_N_per_s", 50.0}};  // 0.05 N per tick
  std::ofstream(dir / "limited.json") << scene.dump(2);
  const fs::path rec = dir / "limited.pncrec";
  const ProcessResult r = app((dir / "limited.json").string() + " --device scripted --offscreen --duration 1.5 --size 480x300 "
                    "--record " + rec.string() + " --stats " + (dir / "stats.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json s = read_json(dir / "stats.json");
  EXPECT_GT(s.at("guard").at("magnitude_clamped_ticks").get<long>(), 0);
  EXPECT_GT(s.at("guard").at("rate_clamped_ticks").get<long>(), 0);
  EXPECT_LE(s.at("guard").at("max_force_sent_N").get<double>(), 0.5 + 1e-12);
  EXPECT_GT(s.at("guard").at("max_tissue_force_N").get<double>(), 2.0);  // the model's own force is not clamped

  const Recording recording = read_recording(rec);
  double previous[3] = {0, 0, 0};
  double largest_request = 0.0;
  for (const TickRecord& t : recording.records) {
    const double sent = std::hypot(t.force_sent_N[0], t.force_sent_N[1], t.force_sent_N[2]);
    ASSERT_LE(sent, 0.5 + 1e-12) << "tick " << t.tick;
    const double step = std::hypot(t.force_sent_N[0] - previous[0], t.force_sent_N[1] - previous[1],
                                   t.force_sent_N[2] - previous[2]);
    ASSERT_LE(step, 0.05 + 1e-12) << "tick " << t.tick;
    std::copy(t.force_sent_N, t.force_sent_N + 3, previous);
    largest_request = std::max(largest_request, std::hypot(t.force_raw_N[0], t.force_raw_N[1], t.force_raw_N[2]));
  }
  EXPECT_GT(largest_request, 2.0);
}

std::uint16_t free_udp_port() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

/// A UDP client of the app on `port`: sends POSE messages (numbered in order).
struct PoseClient {
  int fd = -1;
  sockaddr_in to{};
  std::uint32_t sequence = 0;
  long replies = 0;
  explicit PoseClient(std::uint16_t port, std::uint32_t first_sequence = 1)
      : fd(::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0)), sequence(first_sequence - 1) {
    to.sin_family = AF_INET;
    to.sin_port = htons(port);
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  ~PoseClient() { ::close(fd); }
  void send(double z_m) {
    udp::PoseMessage m;
    m.sequence = ++sequence;
    m.position_m = Eigen::Vector3d(0.0, 0.0, z_m);
    std::uint8_t b[udp::kPoseSize];
    udp::encode(m, b);
    ::sendto(fd, b, sizeof b, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
  }
  long drain() {
    std::uint8_t reply[256];
    long n = 0;
    while (::recv(fd, reply, sizeof reply, 0) > 0) ++n;
    replies += n;
    return n;
  }
  /// Sends poses at z_m until the app answers (its haptic loop runs) or the
  /// session ends: building the models takes seconds under a sanitizer on a
  /// loaded machine, so a fixed start-up wait is not enough.
  bool wait_for_app(double z_m, const std::future<ProcessResult>& session) {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (std::chrono::steady_clock::now() < give_up &&
           session.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
      send(z_m);
      if (drain() > 0) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return false;
  }
};

TEST(PunctureApp, UdpBridgeDrivesTheApp) {
  const fs::path dir = work_dir("udp");
  const std::uint16_t port = free_udp_port();
  auto session = std::async(std::launch::async, [&] {
    return app("--device udp --udp-port " + std::to_string(port) + " --offscreen --duration 3.5 --size 480x300 "
               "--stats " + (dir / "stats.json").string());
  });
  // The tiny bridge: once the app answers, the scene's insertion to 12 mm at
  // 20 mm/s as POSE messages at ~1 kHz.
  PoseClient client(port);
  ASSERT_TRUE(client.wait_for_app(0.002, session)) << "the app never answered a pose";
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 3000 && session.wait_for(std::chrono::seconds(0)) != std::future_status::ready; ++i) {
    const double t = 1e-3 * i;
    client.send(0.002 - 0.02 * std::max(0.0, std::min(t - 0.2, 0.7)));
    client.drain();
    std::this_thread::sleep_until(start + std::chrono::microseconds(1000 * (i + 1)));
  }
  const long replies = client.replies;
  const ProcessResult r = session.get();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json s = read_json(dir / "stats.json");
  EXPECT_GT(s.at("udp").at("received").get<long>(), 500);
  EXPECT_GT(s.at("udp").at("sent").get<long>(), 500);
  EXPECT_GT(replies, 500);
  // 12 mm deep: skin, fat and muscle (at 11.5 mm) punctured.
  EXPECT_GE(s.at("puncture_events").size(), 2u);
  EXPECT_EQ(s.at("puncture_events")[0].at("layer").get<std::string>(), "skin");
}

TEST(PunctureApp, PythonBridgeExampleDrivesTheApp) {
  const fs::path dir = work_dir("python_bridge");
  const std::uint16_t port = free_udp_port();
  auto session = std::async(std::launch::async, [&] {
    return app("--device udp --udp-port " + std::to_string(port) + " --offscreen --duration 4 --size 480x300 "
               "--stats " + (dir / "stats.json").string());
  });
  {  // the app builds its models first; the handshake's sequence numbers lie
     // 2^30 behind the script's (which starts at 1), so none of the script's is stale
    PoseClient client(port, 0xC0000001u);
    ASSERT_TRUE(client.wait_for_app(0.002, session)) << "the app never answered a pose";
  }
  const ProcessResult bridge = run("python3 " + std::string(PUNCTURE_SOURCE_DIR) +
                                   "/realtime/tools/udp_bridge_example.py --port " + std::to_string(port) +
                                   " --seconds 1.5 --speed-mm-s 20");
  const ProcessResult r = session.get();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(bridge.exit_code, 0) << bridge.output;
  EXPECT_NE(bridge.output.find("received"), std::string::npos) << bridge.output;
  const json s = read_json(dir / "stats.json");
  EXPECT_GT(s.at("udp").at("received").get<long>(), 500);
  EXPECT_EQ(s.at("udp").at("malformed").get<long>(), 0);  // the script's packing matches the protocol
  EXPECT_EQ(s.at("puncture_events").at(0).at("layer").get<std::string>(), "skin");
}

TEST(PunctureApp, BadSceneExitsTwoNamingFileAndPath) {
  const fs::path dir = work_dir("bad_scene");
  std::ifstream in(kDefaultScene);
  json scene = json::parse(in);
  scene["haptics"] = {{"max_force_N", -1.0}};
  std::ofstream(dir / "bad.json") << scene.dump(2);
  const ProcessResult r = run(kApp + " " + (dir / "bad.json").string() + " --device scripted --offscreen --duration 1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("bad.json"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("/haptics/max_force_N"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "stats.json"));
}

TEST(PunctureApp, NoDisplayIsAClearError) {
  const ProcessResult r = run("env -u DISPLAY " + kApp + " --device scripted --offscreen --duration 1");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("xvfb-run"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace puncture::realtime
