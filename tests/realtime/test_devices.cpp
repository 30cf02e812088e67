// Devices: pose -> needle conversion, the scripted insertion (one cycle is
// exactly the scene's trajectory; repeated cycles ask for fresh tissue), and
// the mouse/keyboard follower (critically damped, speed limited, clamped).
#include <gtest/gtest.h>

#include <cmath>

#include "puncture/realtime/pointer_device.hpp"
#include "puncture/realtime/scripted_device.hpp"
#include "realtime_test_scenes.hpp"

namespace puncture::realtime {
namespace {

TEST(NeedleFromPose, AxisFromOrientation) {
  NeedleFromPose convert(1e-3, 0.0);
  DevicePose pose;
  // 90 degrees about +x turns the needle axis (0, 0, -1) into (0, 1, 0).
  pose.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));
  pose.velocity_m_per_s = Eigen::Vector3d(0.0, 0.02, 0.5);
  pose.has_velocity = true;
  const NeedleState s = convert.convert(pose, 0.25);
  EXPECT_NEAR((s.direction - Eigen::Vector3d(0, 1, 0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(s.axial_velocity_m_per_s, 0.02, 1e-15);  // only the component along the axis
  EXPECT_EQ(s.time_s, 0.25);
}

TEST(NeedleFromPose, DifferentiatesPositionsWhenNoVelocity) {
  const double dt = 1e-3, speed = 0.01;
  NeedleFromPose raw(dt, 0.0);
  DevicePose pose;
  for (int n = 0; n < 5; ++n) {
    pose.position_m = Eigen::Vector3d(0.0, 0.0, 0.002 - speed * n * dt);  // moving down: inserting
    const NeedleState s = raw.convert(pose, n * dt);
    EXPECT_NEAR(s.axial_velocity_m_per_s, n == 0 ? 0.0 : speed, 1e-12) << n;
  }
  // Low-pass at fc: the step response after k ticks is 1 - (1 - alpha)^k,
  // alpha = T / (T + 1 / (2 pi fc)).
  const double fc = 50.0, alpha = dt / (dt + 1.0 / (2 * M_PI * fc));
  NeedleFromPose filtered(dt, fc);
  for (int n = 0; n < 30; ++n) {
    pose.position_m = Eigen::Vector3d(0.0, 0.0, -speed * n * dt);
    const NeedleState s = filtered.convert(pose, n * dt);
    const double expected = n == 0 ? 0.0 : speed * (1.0 - std::pow(1.0 - alpha, n));
    EXPECT_NEAR(s.axial_velocity_m_per_s, expected, 1e-12) << n;
  }
}

TEST(ScriptedDevice, OneCycleIsTheScenesTrajectory) {
  const Scene scene = testing::short_insertion_scene();
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  ScriptedDevice device(scene.insertion, dt, /*repeat=*/false);
  ScriptedTrajectory trajectory(scene.insertion);
  NeedleFromPose convert(dt, 0.0);
  DeviceInput in;
  const auto ticks = static_cast<int>(trajectory.duration() / dt) + 200;
  for (int n = 0; n < ticks; ++n) {
    device.read(n, n * dt, in);
    ASSERT_EQ(in.status, DeviceInput::Status::Pose);
    ASSERT_FALSE(in.fresh_tissue);
    const NeedleState got = convert.convert(in.pose, n * dt);
    const NeedleState want = trajectory.sample(n * dt);
    ASSERT_EQ(got.tip_position_m, want.tip_position_m) << n;
    ASSERT_EQ(got.direction, want.direction) << n;
    ASSERT_EQ(got.axial_velocity_m_per_s, want.axial_velocity_m_per_s) << n;  // bit for bit, as in `puncture run`
  }
}

TEST(ScriptedDevice, AnInclinedInsertionIsPosedAlongItsLine) {
  Scene scene = testing::short_insertion_scene();
  scene.insertion.angle_deg = 30.0;
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  ScriptedDevice device(scene.insertion, dt, /*repeat=*/false);
  ScriptedTrajectory trajectory(scene.insertion);
  NeedleFromPose convert(dt, 0.0);
  DeviceInput in;
  const Eigen::Vector3d d(0.5, 0.0, -std::sqrt(3.0) / 2.0);  // 30 deg from -z towards +x
  for (int n = 0; n < static_cast<int>(trajectory.duration() / dt); ++n) {
    device.read(n, n * dt, in);
    const NeedleState got = convert.convert(in.pose, n * dt);
    const NeedleState want = trajectory.sample(n * dt);
    ASSERT_EQ(got.tip_position_m, want.tip_position_m) << n;
    ASSERT_NEAR((got.direction - d).norm(), 0.0, 1e-15) << n;  // orientation * (0, 0, -1)
    ASSERT_NEAR(got.axial_velocity_m_per_s, want.axial_velocity_m_per_s, 1e-15) << n;
  }
}

TEST(ScriptedDevice, RepeatAsksForFreshTissueAndHoldsUntilGranted) {
  const Scene scene = testing::short_insertion_scene();
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  ScriptedDevice device(scene.insertion, dt, /*repeat=*/true, /*rest_s=*/0.1);
  DeviceInput in;
  int n = 0, first_request = -1;
  for (; n < 5000; ++n) {
    device.read(n, n * dt, in);
    if (in.fresh_tissue) {
      first_request = n;
      break;
    }
  }
  ASSERT_GE(first_request, 0);
  EXPECT_NEAR(first_request * dt, device.cycle_duration_s(), 2 * dt);
  // Refused twice: the device keeps asking, resting at the start pose.
  ScriptedTrajectory trajectory(scene.insertion);
  for (int i = 0; i < 2; ++i) {
    device.fresh_tissue_result(false);
    device.read(++n, n * dt, in);
    EXPECT_TRUE(in.fresh_tissue);
    EXPECT_EQ(in.pose.position_m, trajectory.sample(0.0).tip_position_m);
  }
  device.fresh_tissue_result(true);
  EXPECT_EQ(device.cycles_started(), 2);
  device.read(++n, n * dt, in);  // the second tick of the new cycle
  EXPECT_FALSE(in.fresh_tissue);
  EXPECT_EQ(in.pose.position_m, trajectory.sample(dt).tip_position_m);
}

TEST(PointerDevice, FollowsWithoutOvershootWithinTheSpeedLimit) {
  const Scene scene = testing::default_scene();
  const double dt = 1e-3;
  PointerDeviceOptions o;
  o.follow_Hz = 6.0;
  o.max_speed_m_per_s = 0.05;
  PointerDevice device(scene, dt, o);
  const Eigen::Vector3d start = device.home();
  const Eigen::Vector3d target(0.0, 0.0, -0.005);  // 5 mm deep
  device.set_target(target);
  DeviceInput in;
  Eigen::Vector3d previous = start;
  double lowest = 1.0;
  for (int n = 0; n < 2000; ++n) {
    device.read(n, n * dt, in);
    const Eigen::Vector3d p = in.pose.position_m;
    ASSERT_LE((p - previous).norm() / dt, o.max_speed_m_per_s * (1 + 1e-12)) << n;
    ASSERT_LE(in.pose.velocity_m_per_s.norm(), o.max_speed_m_per_s * (1 + 1e-12));
    lowest = std::min(lowest, p.z());
    previous = p;
  }
  EXPECT_NEAR(previous.z(), target.z(), 1e-6);  // settled (about 12 time constants)
  EXPECT_GE(lowest, target.z() - 1e-9);         // critically damped: no overshoot
}

TEST(PointerDevice, TargetIsClampedToTheSample) {
  const Scene scene = testing::default_scene();
  PointerDevice device(scene, 1e-3);
  const Eigen::Vector3d t = device.set_target(Eigen::Vector3d(0.1, 0.0, -1.0));
  EXPECT_NEAR(t.x(), 0.5 * scene.sample.diameter_m, 1e-15);
  EXPECT_NEAR(t.z(), -(scene.total_thickness_m() - 0.5e-3), 1e-15);
  EXPECT_EQ(device.set_target(Eigen::Vector3d(0, 0, std::nan(""))), device.home());
}

TEST(PointerDevice, FreshTissueOnlyAboveTheSkin) {
  const Scene scene = testing::default_scene();
  PointerDevice device(scene, 1e-3);
  device.set_target(Eigen::Vector3d(0.0, 0.0, -0.003));
  DeviceInput in;
  int n = 0;
  for (; n < 1500; ++n) device.read(n, n * 1e-3, in);
  ASSERT_LT(in.pose.position_m.z(), 0.0);
  device.request_fresh_tissue();
  device.read(n++, n * 1e-3, in);
  EXPECT_FALSE(in.fresh_tissue);  // needle inside the tissue: not yet
  device.set_target(device.home());
  bool asked = false;
  for (int i = 0; i < 2000 && !asked; ++i) {
    device.read(n++, n * 1e-3, in);
    asked = in.fresh_tissue;
    if (asked) EXPECT_GE(in.pose.position_m.z(), 0.0);
  }
  EXPECT_TRUE(asked);
  device.fresh_tissue_result(true);
  device.read(n++, n * 1e-3, in);
  EXPECT_FALSE(in.fresh_tissue);  // served once
}

}  // namespace
}  // namespace puncture::realtime
