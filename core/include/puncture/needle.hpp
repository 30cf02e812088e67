// needle.hpp: the rigid straight needle, its scripted insertion and the
// device interface the haptic loop reads.
//
// Geometry convention (scene.hpp): the needle moves along -z on the sample
// axis; depth = -z_tip. Only insertion along the surface normal is
// supported (Insertion::angle_deg must be 0).
#pragma once

#include <Eigen/Core>

#include "puncture/scene.hpp"

namespace puncture {

struct NeedleState {
  Eigen::Vector3d tip_position_m = Eigen::Vector3d::Zero();  ///< m, scene frame
  Eigen::Vector3d direction = -Eigen::Vector3d::UnitZ();      ///< unit, pointing from the shaft to the tip (insertion direction)
  double axial_velocity_m_per_s = 0.0;  ///< tip velocity along `direction` (> 0 inserting, < 0 withdrawing)
  double time_s = 0.0;

  double depth_m() const { return -tip_position_m.z(); }
};

/// Approach from start_height above the skin at `speed`, go on at the same
/// speed to target_depth, dwell, withdraw at withdrawal_speed to the start
/// height. Piecewise linear in time; the tip stays on the z axis.
class ScriptedTrajectory {
 public:
  /// Throws std::invalid_argument for angle_deg != 0 (only insertion along the
  /// surface normal is supported), speed <= 0, withdrawal speed <= 0, or a
  /// target depth not below the start point.
  explicit ScriptedTrajectory(const Insertion& insertion);

  /// State at time t (s); t < 0 gives the start, t > duration() the end (at rest).
  NeedleState sample(double t) const;
  double duration() const { return insert_end_s_ + insertion_.dwell_s + withdraw_duration_s_; }
  double insertion_end_s() const { return insert_end_s_; }   ///< time the target depth is reached
  double withdrawal_start_s() const { return insert_end_s_ + insertion_.dwell_s; }

 private:
  Insertion insertion_;
  double insert_end_s_ = 0.0;
  double withdraw_duration_s_ = 0.0;
};

/// Where the haptic loop reads the needle from: a scripted trajectory here,
/// a mouse or haptic device in the interactive app.
class NeedleDevice {
 public:
  virtual ~NeedleDevice() = default;
  virtual NeedleState read(double t) = 0;
};

class ScriptedNeedleDevice final : public NeedleDevice {
 public:
  explicit ScriptedNeedleDevice(const Insertion& insertion) : trajectory_(insertion) {}
  NeedleState read(double t) override { return trajectory_.sample(t); }
  const ScriptedTrajectory& trajectory() const { return trajectory_; }

 private:
  ScriptedTrajectory trajectory_;
};

}  // namespace puncture
