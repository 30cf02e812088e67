#include "puncture/needle.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace puncture {

double NeedleState::along_axis_m(double vertical_m) const {
  return vertical_m / std::max(axis_cosine(), kMinAxisCosine);
}

Eigen::Vector3d point_on_insertion_line(const Eigen::Vector3d& d, double path_m) {
  auto along = [path_m](double component) { return component == 0.0 ? 0.0 : component * path_m; };
  return Eigen::Vector3d(along(d.x()), along(d.y()), along(d.z()));
}

Eigen::Vector3d insertion_direction(const Insertion& insertion) {
  const double angle_rad = insertion.angle_deg * (M_PI / 180.0);
  const double azimuth_rad = insertion.azimuth_deg * (M_PI / 180.0);
  return Eigen::Vector3d(std::sin(angle_rad) * std::cos(azimuth_rad), std::sin(angle_rad) * std::sin(azimuth_rad),
                         -std::cos(angle_rad));
}

ScriptedTrajectory::ScriptedTrajectory(const Insertion& insertion) : insertion_(insertion) {
  if (!(insertion.angle_deg >= 0.0 && insertion.angle_deg <= kMaxInsertionAngleDeg))
    throw std::invalid_argument("insertion.angle_deg = " + std::to_string(insertion.angle_deg) + ": must lie in [0, " +
                                std::to_string(kMaxInsertionAngleDeg) + "] deg");
  if (!(insertion.azimuth_deg >= 0.0 && insertion.azimuth_deg < 360.0))
    throw std::invalid_argument("insertion.azimuth_deg = " + std::to_string(insertion.azimuth_deg) +
                                ": must lie in [0, 360) deg");
  if (!(insertion.speed_m_per_s > 0.0) || !std::isfinite(insertion.speed_m_per_s))
    throw std::invalid_argument("insertion.speed_m_per_s must be positive for a scripted trajectory");
  if (!(insertion.withdrawal_speed_m_per_s > 0.0) || !std::isfinite(insertion.withdrawal_speed_m_per_s))
    throw std::invalid_argument("insertion.withdrawal_speed_m_per_s must be positive");
  if (!(insertion.dwell_s >= 0.0)) throw std::invalid_argument("insertion.dwell_s must be >= 0");
  if (!(insertion.start_height_m + insertion.target_depth_m > 0.0))
    throw std::invalid_argument("insertion.target_depth_m must lie below the start height");
  direction_ = insertion_direction(insertion);
  const double cos_a = -direction_.z();
  start_path_m_ = -insertion.start_height_m / cos_a;
  target_path_m_ = insertion.target_depth_m / cos_a;
  const double travel = target_path_m_ - start_path_m_;
  insert_end_s_ = travel / insertion.speed_m_per_s;
  withdraw_duration_s_ = travel / insertion.withdrawal_speed_m_per_s;
}

NeedleState ScriptedTrajectory::sample(double t) const {
  NeedleState s;
  s.time_s = t;
  // Path coordinate along direction_ (0 at the entry point, the origin).
  double path = start_path_m_, v = 0.0;
  if (t <= 0.0) {
    path = start_path_m_;
  } else if (t < insert_end_s_) {
    path = start_path_m_ + insertion_.speed_m_per_s * t;
    v = insertion_.speed_m_per_s;
  } else if (t < withdrawal_start_s()) {
    path = target_path_m_;
  } else if (t < duration()) {
    path = target_path_m_ - insertion_.withdrawal_speed_m_per_s * (t - withdrawal_start_s());
    v = -insertion_.withdrawal_speed_m_per_s;
  }
  s.tip_position_m = point_on_insertion_line(direction_, path);
  s.direction = direction_;
  s.axial_velocity_m_per_s = v;
  return s;
}

}  // namespace puncture
