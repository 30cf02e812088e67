// The haptic loop: no heap allocation in the haptic path (counted on the
// haptic thread only, with every sink attached, across a fresh-tissue swap);
// the paced loop runs the requested number of ticks and reports them; and a
// tiny UDP sender over loopback drives the loop like a haptic-device bridge.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <thread>

#include "puncture/model/realtime_model.hpp"
#include "puncture/realtime/haptic_loop.hpp"
#include "puncture/realtime/pointer_device.hpp"
#include "puncture/realtime/scripted_device.hpp"
#include "puncture/realtime/udp_device.hpp"
#include "../core/allocation_counter.hpp"
#include "realtime_test_scenes.hpp"

namespace puncture::realtime {
namespace {

namespace fs = std::filesystem;

TEST(HapticLoop, CountersSeeThisThreadsAllocationsOnly) {
  using namespace puncture::test;
  // Another thread allocating while this one counts is not counted.
  std::atomic<bool> go{false}, done{false};
  std::thread other([&] {
    while (!go.load()) std::this_thread::yield();
    int* volatile p = new int(1);
    delete p;
    done = true;
  });
  reset_allocation_count();
  count_this_threads_allocations(true);
  go = true;
  while (!done.load()) std::this_thread::yield();
  count_this_threads_allocations(false);
  other.join();
  EXPECT_EQ(allocation_count(), 0);
  // This thread's own allocation is.
  count_this_threads_allocations(true);
  std::vector<int>* volatile v = new std::vector<int>(10);
  count_this_threads_allocations(false);
  delete v;
  EXPECT_GE(allocation_count(), 1);  // the instrument works
  reset_allocation_count();
}

/// One whole scripted cycle, a fresh-tissue swap and the next insertion with a
/// view snapshot every tick: nothing in the haptic path allocates.
void expect_no_allocation_in_the_haptic_path(const std::string& text, const std::string& name) {
  const Scene scene = parse_scene(text, "short_insertion.json");
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  const fs::path dir = fs::path(PUNCTURE_BINARY_DIR) / "test_output" / "realtime" / name;
  fs::create_directories(dir);

  ModelSupplier models([&] { return std::make_unique<RealtimeModel>(build_realtime_model(scene)); });
  ScriptedDevice device(scene.insertion, dt, /*repeat=*/true, /*rest_s=*/0.02);
  RecordingWriter recorder(dir / "session.pncrec", {{"format", "puncture-recording"}, {"scene_text", text}});
  TripleBuffer<ViewSnapshot> snapshots([&](ViewSnapshot& s) { init_snapshot(s, *models.initial()->simulator); });
  SpscRing<TickSample> samples(1024);
  TripleBuffer<ViewSnapshot> capture([&](ViewSnapshot& s) { init_snapshot(s, *models.initial()->simulator); });
  HapticLoopSinks sinks{&recorder, &snapshots, &samples, &capture};
  HapticLoopOptions options;
  options.snapshot_rate_Hz = 1000.0;  // a snapshot every tick: the worst case
  options.capture_at_s = 0.3;
  HapticLoop loop(scene, models, device, ForceGuard(scene.haptics, dt), options, sinks);
  // Let the builder thread finish the spare so the fresh-tissue swap happens without holding.
  while (models.models_built() < 2) std::this_thread::sleep_for(std::chrono::milliseconds(5));

  std::int64_t n = 0;
  puncture::test::reset_allocation_count();
  puncture::test::count_this_threads_allocations(true);
  for (; n < 1400; ++n) loop.step(n, n * dt);  // one whole cycle, a swap, and the next insertion
  puncture::test::count_this_threads_allocations(false);
  EXPECT_EQ(puncture::test::allocation_count(), 0);
  EXPECT_EQ(loop.counters().fresh_tissues, 1);
  EXPECT_EQ(loop.counters().held_ticks, 0);
  EXPECT_EQ(loop.counters().snapshots, 1400);
  EXPECT_GT(loop.counters().samples_dropped, 0);  // nobody drained the view ring: dropped, never grown
  TickSample s;
  EXPECT_TRUE(samples.try_pop(s));
  // The capture holds the state of the first tick at or after 0.3 s, published once.
  ASSERT_TRUE(capture.update());
  EXPECT_GE(capture.front().needle.time_s, 0.3);
  EXPECT_LT(capture.front().needle.time_s, 0.3 + dt);
  EXPECT_FALSE(capture.update());
  recorder.finish();
  models.finish();
}

TEST(HapticLoop, NoAllocationInTheHapticPath) {
  expect_no_allocation_in_the_haptic_path(testing::short_insertion_scene_text(), "no_alloc");
}

TEST(HapticLoop, NoAllocationWithCoupledSurfacesInTheView) {
  // The view's snapshot reads the drawn surfaces in the haptic thread.
  Scene scene = parse_scene(testing::short_insertion_scene_text(), "short_insertion.json");
  scene.effects.coupled_surfaces = true;
  scene.effects.layer_interaction = false;
  expect_no_allocation_in_the_haptic_path(scene_to_json_text(scene), "no_alloc_coupled");
}

TEST(HapticLoop, NoAllocationWithTheUdpAndMouseDevices) {
  const Scene scene = testing::short_insertion_scene();
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  ModelSupplier models([&] { return std::make_unique<RealtimeModel>(build_realtime_model(scene)); });
  UdpDeviceOptions uo;
  uo.port = 0;
  UdpDevice udp(uo);
  PointerDevice mouse(scene, dt);
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(udp.port());
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  for (HapticDevice* device : {static_cast<HapticDevice*>(&udp), static_cast<HapticDevice*>(&mouse)}) {
    HapticLoop loop(scene, models, *device, ForceGuard(scene.haptics, dt), HapticLoopOptions{}, HapticLoopSinks{});
    mouse.set_target(Eigen::Vector3d(0.0, 0.0, -0.003));  // the view thread's part (allocation-free too)
    puncture::test::reset_allocation_count();
    for (std::int64_t n = 0; n < 600; ++n) {
      udp::PoseMessage m;
      m.sequence = static_cast<std::uint32_t>(n + 1);
      m.position_m = Eigen::Vector3d(0.0, 0.0, 0.002 - 1e-5 * n);
      std::uint8_t b[udp::kPoseSize];
      udp::encode(m, b);
      ::sendto(fd, b, sizeof b, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
      puncture::test::count_this_threads_allocations(true);
      loop.step(n, n * dt);
      puncture::test::count_this_threads_allocations(false);
    }
    EXPECT_EQ(puncture::test::allocation_count(), 0) << device->name();
    EXPECT_GT(loop.counters().model_ticks, 0);
  }
  ::close(fd);
  EXPECT_GT(udp.counters().received, 0);
  EXPECT_GT(udp.counters().sent, 0);
  models.finish();
}

TEST(HapticLoop, PacedRunReportsItsTicks) {
  const Scene scene = testing::short_insertion_scene();
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  ModelSupplier models([&] { return std::make_unique<RealtimeModel>(build_realtime_model(scene)); });
  ScriptedDevice device(scene.insertion, dt, false);
  HapticLoopOptions options;
  options.max_ticks = 300;
  options.realtime_priority = 0;
  HapticLoop loop(scene, models, device, ForceGuard(scene.haptics, dt), options, HapticLoopSinks{});
  loop.start();
  loop.join();
  EXPECT_TRUE(loop.finished());
  EXPECT_TRUE(loop.error().empty()) << loop.error();
  EXPECT_EQ(loop.statistics().count, 300);
  EXPECT_EQ(loop.statistics().period.count(), 299);
  EXPECT_EQ(loop.counters().model_ticks, 300);
  EXPECT_GT(loop.statistics().achieved_rate_Hz(), 0.0);
  EXPECT_NE(loop.scheduling().find("normal scheduling"), std::string::npos);
  models.finish();
}

TEST(HapticLoop, UdpSenderOverLoopbackDrivesTheModel) {
  // A tiny bridge: streams the scene's scripted insertion as POSE messages at
  // about 1 kHz (with velocities) and collects the FORCE replies.
  const Scene scene = testing::short_insertion_scene();
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  UdpDeviceOptions uo;
  uo.port = 0;
  UdpDevice device(uo);
  ModelSupplier models([&] { return std::make_unique<RealtimeModel>(build_realtime_model(scene)); });
  HapticLoopOptions options;
  options.realtime_priority = 0;
  HapticLoop loop(scene, models, device, ForceGuard(scene.haptics, dt), options, HapticLoopSinks{});
  loop.start();

  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(device.port());
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ScriptedTrajectory trajectory(scene.insertion);
  const int poses = static_cast<int>(trajectory.insertion_end_s() / dt) + 100;
  double max_force = 0.0, max_sent_z = 0.0;
  std::uint32_t last_echo = 0, final_states = 0;
  bool echo_ordered = true;
  int replies = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < poses; ++i) {
    const NeedleState s = trajectory.sample(i * dt);
    udp::PoseMessage m;
    m.sequence = static_cast<std::uint32_t>(i + 1);
    m.flags = udp::kPoseVelocityValid;
    m.position_m = s.tip_position_m;
    m.velocity_m_per_s = s.direction * s.axial_velocity_m_per_s;
    std::uint8_t b[udp::kPoseSize];
    udp::encode(m, b);
    ::sendto(fd, b, sizeof b, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
    std::this_thread::sleep_until(start + std::chrono::microseconds(1000 * (i + 1)));
    std::uint8_t r[256];
    ssize_t n;
    while ((n = ::recv(fd, r, sizeof r, 0)) > 0) {
      udp::ForceMessage f;
      if (!udp::decode(r, static_cast<std::size_t>(n), f)) continue;
      ++replies;
      echo_ordered &= !udp::sequence_newer(last_echo, f.echo_sequence);
      last_echo = f.echo_sequence;
      max_force = std::max(max_force, f.tissue_force_N);
      max_sent_z = std::max(max_sent_z, f.force_N.z());
      final_states = f.layer_states;
    }
  }
  ::close(fd);
  loop.request_stop();
  loop.join();
  ASSERT_TRUE(loop.error().empty()) << loop.error();

  RealtimeModel offline = build_realtime_model(scene);
  double offline_peak = 0.0;
  for (const TickResult& t : run_scripted_insertion(offline, scene).ticks)
    offline_peak = std::max(offline_peak, t.total_force_N);

  EXPECT_GT(replies, poses / 2);  // one FORCE per haptic tick once the bridge is known
  EXPECT_TRUE(echo_ordered);
  EXPECT_GT(last_echo, static_cast<std::uint32_t>(poses / 2));
  EXPECT_EQ(unpack_layer_state(final_states, 0), LayerState::Punctured);  // skin
  EXPECT_EQ(unpack_layer_state(final_states, 1), LayerState::Punctured);  // fat
  EXPECT_GT(max_sent_z, 0.0);  // the device is pushed back out of the tissue (+z)
  EXPECT_GT(max_force, 0.5 * offline_peak);
  EXPECT_LT(max_force, 1.5 * offline_peak);
  EXPECT_GT(device.counters().received, poses / 2);
  models.finish();
}

}  // namespace
}  // namespace puncture::realtime
