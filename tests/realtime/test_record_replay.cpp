// Record and replay: a session recorded tick by tick replays through a fresh
// model bit for bit (offline and through the haptic loop with the replay
// device), a different scene does not, the app feeds the model exactly what
// `puncture run` feeds it, and broken files are rejected with a reason.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "puncture/model/realtime_model.hpp"
#include "puncture/realtime/haptic_loop.hpp"
#include "puncture/realtime/replay.hpp"
#include "puncture/realtime/scripted_device.hpp"
#include "realtime_test_scenes.hpp"

namespace puncture::realtime {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::path(PUNCTURE_BINARY_DIR) / "test_output" / "realtime" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

nlohmann::json header_for(const std::string& scene_text, const Scene& scene) {
  return {{"format", "puncture-recording"}, {"version", 1},        {"scene_file", "short_insertion.json"},
          {"scene_text", scene_text},       {"device", "scripted"}, {"haptic_rate_Hz", scene.realtime.haptic_rate_Hz},
          {"provenance", {{"command", "test"}}}};
}

/// Runs the scripted device (repeating cycles) through HapticLoop::step until
/// `cycles` fresh tissues have been used; records every model tick.
HapticLoopCounters record_session(const Scene& scene, const std::string& scene_text, const fs::path& file,
                                  int fresh_tissues) {
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  ModelSupplier models([&] { return std::make_unique<RealtimeModel>(build_realtime_model(scene)); });
  ScriptedDevice device(scene.insertion, dt, /*repeat=*/true, /*rest_s=*/0.05);
  RecordingWriter recorder(file, header_for(scene_text, scene));
  HapticLoopSinks sinks;
  sinks.recorder = &recorder;
  HapticLoop loop(scene, models, device, ForceGuard(scene.haptics, dt), HapticLoopOptions{}, sinks);
  std::int64_t n = 0;
  while (loop.counters().fresh_tissues < fresh_tissues && n < 20000) {
    const std::int64_t held = loop.counters().held_ticks;
    loop.step(n, n * dt);
    ++n;
    if (loop.counters().held_ticks > held) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  // Finish the last cycle's insertion part.
  for (int i = 0; i < 300; ++i, ++n) loop.step(n, n * dt);
  EXPECT_EQ(recorder.finish(), loop.counters().model_ticks);
  models.finish();
  return loop.counters();
}

TEST(RecordReplay, OfflineReplayIsBitForBit) {
  const fs::path dir = temp_dir("offline");
  const std::string text = testing::short_insertion_scene_text();
  const Scene scene = parse_scene(text, "short_insertion.json");
  const HapticLoopCounters recorded = record_session(scene, text, dir / "session.pncrec", 2);
  ASSERT_EQ(recorded.fresh_tissues, 2);
  EXPECT_FALSE(fs::exists(dir / "session.pncrec.partial"));

  const Recording rec = read_recording(dir / "session.pncrec");
  ASSERT_EQ(static_cast<std::int64_t>(rec.records.size()), recorded.model_ticks);
  const Scene replay_scene = parse_scene(rec.scene_text(), "recording");
  const ReplayComparison c = replay_recording(rec, replay_scene);
  EXPECT_EQ(c.ticks, recorded.model_ticks);
  EXPECT_EQ(c.fresh_tissues, 2);
  EXPECT_EQ(c.mismatches, 0) << "first at tick " << c.first_mismatch_tick << " (" << c.first_mismatch_field << ")";
  EXPECT_EQ(c.max_abs_force_difference_N, 0.0);
  // The recording really contains punctures and forces (not a trivially equal zero run).
  double peak = 0.0;
  bool all_punctured = false;
  for (const TickRecord& r : rec.records) {
    peak = std::max(peak, r.tissue_force_N);
    all_punctured |= unpack_layer_state(r.layer_states, 1) == LayerState::Punctured;
  }
  EXPECT_GT(peak, 0.1);
  EXPECT_TRUE(all_punctured);
}

TEST(RecordReplay, AnotherSceneDoesNotReplay) {
  const fs::path dir = temp_dir("other_scene");
  const std::string text = testing::short_insertion_scene_text();
  const Scene scene = parse_scene(text, "short_insertion.json");
  record_session(scene, text, dir / "session.pncrec", 1);
  const Recording rec = read_recording(dir / "session.pncrec");
  Scene stiffer = scene;
  stiffer.layers[0].force_mesh.virtual_stiffness_N_per_m *= 1.0 + 1e-9;  // a one-in-a-billion change
  const ReplayComparison c = replay_recording(rec, stiffer);
  EXPECT_GT(c.mismatches, 0);
  EXPECT_GE(c.first_mismatch_tick, 0);
  EXPECT_EQ(c.first_mismatch_field, "tissue_force_N");
}

TEST(RecordReplay, ReplayDeviceThroughTheHapticLoopIsBitForBit) {
  const fs::path dir = temp_dir("loop_replay");
  const std::string text = testing::short_insertion_scene_text();
  const Scene scene = parse_scene(text, "short_insertion.json");
  record_session(scene, text, dir / "session.pncrec", 1);
  const Recording rec = read_recording(dir / "session.pncrec");

  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  ModelSupplier models([&] { return std::make_unique<RealtimeModel>(build_realtime_model(scene)); });
  ReplayDevice device(rec);
  HapticLoop loop(scene, models, device, ForceGuard(scene.haptics, dt), HapticLoopOptions{}, HapticLoopSinks{});
  std::int64_t n = 0;
  while (loop.step(n, n * dt)) {
    ++n;
    if (loop.counters().held_ticks > 0 && device.position() < rec.records.size())
      std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  EXPECT_EQ(loop.counters().replay_compared, static_cast<std::int64_t>(rec.records.size()));
  EXPECT_EQ(loop.counters().replay_mismatches, 0) << "first at loop tick " << loop.counters().first_mismatch_tick;
  models.finish();
}

TEST(RecordReplay, FirstCycleFeedsTheModelAsPunctureRunDoes) {
  const fs::path dir = temp_dir("as_run");
  const std::string text = testing::short_insertion_scene_text();
  const Scene scene = parse_scene(text, "short_insertion.json");
  record_session(scene, text, dir / "session.pncrec", 1);
  const Recording rec = read_recording(dir / "session.pncrec");
  RealtimeModel model = build_realtime_model(scene);
  const ScriptedRunResult run = run_scripted_insertion(model, scene);  // the `puncture run` path
  ASSERT_GT(rec.records.size(), run.ticks.size());
  for (std::size_t i = 0; i < run.ticks.size(); ++i) {
    ASSERT_EQ(rec.records[i].tissue_force_N, run.ticks[i].total_force_N) << "tick " << i;
    ASSERT_EQ(rec.records[i].depth_m, run.ticks[i].depth_m) << "tick " << i;
  }
}

TEST(RecordingFile, RoundTripsEveryField) {
  const fs::path dir = temp_dir("roundtrip");
  TickRecord r;
  r.tick = 123456789012ull;
  r.flags = kRecFreshTissue | kRecRateClamped;
  r.layer_states = 0b011001;
  r.wall_time_s = 1.0 / 3.0;
  r.needle_time_s = 0.123;
  r.tip_m[2] = -0.0042;
  r.direction[0] = 1e-300;
  r.axial_velocity_m_per_s = -0.0;
  r.pose_orientation_wxyz[3] = -0.25;
  r.tissue_force_N = 0.7071;
  r.force_raw_N[2] = 0.7071;
  r.force_sent_N[1] = 5e-324;  // a denormal survives
  r.depth_m = 0.0042;
  {
    RecordingWriter w(dir / "one.pncrec", {{"format", "puncture-recording"}, {"scene_text", "{}"}});
    EXPECT_TRUE(w.push(r));
    EXPECT_EQ(w.finish(), 1);
  }
  const Recording rec = read_recording(dir / "one.pncrec");
  ASSERT_EQ(rec.records.size(), 1u);
  std::uint8_t a[kRecordSize], b[kRecordSize];
  encode_record(r, a);
  encode_record(rec.records[0], b);
  EXPECT_EQ(std::memcmp(a, b, kRecordSize), 0);
  EXPECT_TRUE(std::signbit(rec.records[0].axial_velocity_m_per_s));
  EXPECT_EQ(rec.records[0].tick, 123456789012ull);

  // The documented offsets: tick at 0, tissue force at 144, depth at 200 (little-endian).
  std::ifstream in(dir / "one.pncrec", std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(std::string(bytes.data(), 8), std::string("PNCREC1\n"));
  std::uint64_t header_length = 0;
  std::memcpy(&header_length, bytes.data() + 16, 8);
  const char* rec0 = bytes.data() + 24 + header_length;
  double force = 0, depth = 0;
  std::memcpy(&force, rec0 + 144, 8);
  std::memcpy(&depth, rec0 + 200, 8);
  EXPECT_EQ(force, 0.7071);
  EXPECT_EQ(depth, 0.0042);
  EXPECT_EQ(bytes.size(), 24 + header_length + kRecordSize);
}

TEST(RecordingFile, BrokenFilesAreRejectedWithAReason) {
  const fs::path dir = temp_dir("broken");
  {
    RecordingWriter w(dir / "ok.pncrec", {{"format", "puncture-recording"}, {"scene_text", "{}"}});
    w.push(TickRecord{});
    w.push(TickRecord{});
    w.finish();
  }
  auto error_of = [](const fs::path& p) -> std::string {
    try {
      read_recording(p);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "accepted";
  };
  fs::copy_file(dir / "ok.pncrec", dir / "truncated.pncrec");
  fs::resize_file(dir / "truncated.pncrec", fs::file_size(dir / "ok.pncrec") - 5);
  EXPECT_NE(error_of(dir / "truncated.pncrec").find("truncated record"), std::string::npos);
  std::ofstream(dir / "text.pncrec") << "time,force\n0,0\n";
  EXPECT_NE(error_of(dir / "text.pncrec").find("bad magic"), std::string::npos);
  EXPECT_NE(error_of(dir / "missing.pncrec").find("cannot open"), std::string::npos);
  EXPECT_NE(error_of(dir / "text.pncrec").find("text.pncrec"), std::string::npos);  // names the file
}

TEST(RecordingFile, DroppedRecordsDiscardTheRecording) {
  const fs::path dir = temp_dir("dropped");
  RecordingWriter w(dir / "lossy.pncrec", {{"format", "puncture-recording"}, {"scene_text", "{}"}}, 4);
  // Push far faster than the writer thread drains (it wakes every 5 ms).
  int refused = 0;
  for (int i = 0; i < 100000 && refused == 0; ++i) refused += w.push(TickRecord{}) ? 0 : 1;
  ASSERT_GT(refused, 0);
  EXPECT_THROW(w.finish(), std::runtime_error);
  EXPECT_FALSE(fs::exists(dir / "lossy.pncrec"));
  EXPECT_FALSE(fs::exists(dir / "lossy.pncrec.partial"));
}

TEST(RecordingFile, CsvExportHasOneRowPerTick) {
  const fs::path dir = temp_dir("csv");
  const std::string text = testing::short_insertion_scene_text();
  const Scene scene = parse_scene(text, "short_insertion.json");
  record_session(scene, text, dir / "session.pncrec", 1);
  const Recording rec = read_recording(dir / "session.pncrec");
  write_recording_csv(rec, dir / "session.csv");
  std::ifstream in(dir / "session.csv");
  std::string line;
  std::size_t rows = 0;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("tick,flags,layer_states,", 0), 0u);
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, rec.records.size());
}

}  // namespace
}  // namespace puncture::realtime
