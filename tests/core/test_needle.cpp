// Scripted needle trajectory and device (needle.hpp).
#include <gtest/gtest.h>

#include <string>

#include "puncture/needle.hpp"

using namespace puncture;

TEST(ScriptedTrajectory, PhasesPositionsAndVelocities) {
  Insertion in;
  in.start_height_m = 2e-3;
  in.speed_m_per_s = 0.01;
  in.target_depth_m = 0.03;
  in.dwell_s = 0.5;
  in.withdrawal_speed_m_per_s = 0.02;
  const ScriptedTrajectory tr(in);
  EXPECT_NEAR(tr.insertion_end_s(), 0.032 / 0.01, 1e-12);
  EXPECT_NEAR(tr.withdrawal_start_s(), 3.2 + 0.5, 1e-12);
  EXPECT_NEAR(tr.duration(), 3.7 + 0.032 / 0.02, 1e-12);

  NeedleState s = tr.sample(0.0);
  EXPECT_DOUBLE_EQ(s.tip_position_m.z(), 2e-3);
  s = tr.sample(0.2);  // skin surface reached at 0.2 s
  EXPECT_NEAR(s.depth_m(), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(s.axial_velocity_m_per_s, 0.01);
  s = tr.sample(1.7);
  EXPECT_NEAR(s.depth_m(), 0.015, 1e-15);
  EXPECT_EQ(s.direction, -Eigen::Vector3d::UnitZ());
  EXPECT_EQ(s.tip_position_m.x(), 0.0);
  s = tr.sample(3.5);  // dwell
  EXPECT_NEAR(s.depth_m(), 0.03, 1e-15);
  EXPECT_EQ(s.axial_velocity_m_per_s, 0.0);
  s = tr.sample(4.2);  // withdrawing: 0.5 s at 0.02 m/s from 30 mm
  EXPECT_NEAR(s.depth_m(), 0.02, 1e-15);
  EXPECT_DOUBLE_EQ(s.axial_velocity_m_per_s, -0.02);
  EXPECT_DOUBLE_EQ(s.time_s, 4.2);
  s = tr.sample(100.0);
  EXPECT_NEAR(s.tip_position_m.z(), 2e-3, 1e-15);
  EXPECT_EQ(s.axial_velocity_m_per_s, 0.0);
}

TEST(ScriptedTrajectory, RejectsImpossibleMotions) {
  Insertion in;
  in.speed_m_per_s = 0.0;
  EXPECT_THROW(ScriptedTrajectory{in}, std::invalid_argument);
  in = Insertion{};
  in.withdrawal_speed_m_per_s = -1.0;
  EXPECT_THROW(ScriptedTrajectory{in}, std::invalid_argument);
  in = Insertion{};
  in.target_depth_m = -in.start_height_m;
  EXPECT_THROW(ScriptedTrajectory{in}, std::invalid_argument);
}

TEST(ScriptedNeedleDevice, ReadsTheTrajectory) {
  Insertion in;
  ScriptedNeedleDevice device(in);
  NeedleDevice& d = device;
  EXPECT_DOUBLE_EQ(d.read(0.7).tip_position_m.z(), device.trajectory().sample(0.7).tip_position_m.z());
}
