// needle.hpp: the rigid straight needle, its scripted insertion and the
// device interface the haptic loop reads.
//
// Geometry convention (scene.hpp): the undeformed skin surface is the plane
// z = 0, tissue below; depth = -z_tip. A scripted insertion enters the skin
// at the origin along the unit direction
//   d = (sin a cos b, sin a sin b, -cos a),  a = Insertion::angle_deg (0: along
// the sample axis, the surface normal), b = Insertion::azimuth_deg (the
// needle tilts towards +x at b = 0, towards +y at b = 90). The tip's path
// coordinate s (m, along d, 0 at the entry point, < 0 above the skin) runs
// from -start_height / cos a to target_depth / cos a: start height and target
// depth are vertical, the speeds are along the needle.
#pragma once

#include <Eigen/Core>

#include "puncture/insertion_angle.hpp"
#include "puncture/scene.hpp"

namespace puncture {

/// Smallest axis cosine (needle to the vertical) at which depths along the
/// needle and vertical depths convert into each other; a needle closer to
/// horizontal counts as horizontal (path depth and shaft lengths use this).
constexpr double kMinAxisCosine = 1e-3;

struct NeedleState {
  Eigen::Vector3d tip_position_m = Eigen::Vector3d::Zero();  ///< m, scene frame
  Eigen::Vector3d direction = -Eigen::Vector3d::UnitZ();      ///< unit, pointing from the shaft to the tip (insertion direction)
  double axial_velocity_m_per_s = 0.0;  ///< tip velocity along `direction` (> 0 inserting, < 0 withdrawing)
  double time_s = 0.0;

  double depth_m() const { return -tip_position_m.z(); }
  /// Tip position along the needle axis (m): tip . direction (= depth_m() for the axial needle).
  double axial_position_m() const { return tip_position_m.dot(direction); }
  /// Cosine of the needle axis to the vertical, -direction.z (1 along the sample axis).
  double axis_cosine() const { return -direction.z(); }
  /// A vertical extent (m) as a length along the needle: vertical / cos a, the
  /// cosine at least kMinAxisCosine.
  double along_axis_m(double vertical_m) const;
};

/// The unit insertion direction d of a scripted insertion at insertion.angle_deg (see the header).
Eigen::Vector3d insertion_direction(const Insertion& insertion);

/// The point path_m (m) along the unit direction d from the origin (the entry
/// point); a component d has none of is exactly 0 (not -0).
Eigen::Vector3d point_on_insertion_line(const Eigen::Vector3d& direction, double path_m);

/// Approach from start_height above the skin at `speed`, go on at the same
/// speed to target_depth, dwell, withdraw at withdrawal_speed to the start
/// height, all along the straight line through the origin at the insertion
/// angle (see the header). Piecewise linear in time.
class ScriptedTrajectory {
 public:
  /// Throws std::invalid_argument for an angle outside [0, kMaxInsertionAngleDeg],
  /// speed <= 0, withdrawal speed <= 0, or a target depth not below the start point.
  explicit ScriptedTrajectory(const Insertion& insertion);

  /// State at time t (s); t < 0 gives the start, t > duration() the end (at rest).
  NeedleState sample(double t) const;
  double duration() const { return insert_end_s_ + insertion_.dwell_s + withdraw_duration_s_; }
  double insertion_end_s() const { return insert_end_s_; }   ///< time the target depth is reached
  double withdrawal_start_s() const { return insert_end_s_ + insertion_.dwell_s; }
  /// Unit insertion direction d (see the header).
  const Eigen::Vector3d& direction() const { return direction_; }

 private:
  Insertion insertion_;
  Eigen::Vector3d direction_ = -Eigen::Vector3d::UnitZ();
  double start_path_m_ = 0.0;   ///< path coordinate of the start (m, <= 0)
  double target_path_m_ = 0.0;  ///< path coordinate of the target (m)
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
