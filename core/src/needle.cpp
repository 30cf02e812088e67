#include "puncture/needle.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace puncture {

ScriptedTrajectory::ScriptedTrajectory(const Insertion& insertion) : insertion_(insertion) {
  if (insertion.angle_deg != 0.0)
    throw std::invalid_argument("insertion.angle_deg = " + std::to_string(insertion.angle_deg) +
                                ": only insertion along the surface normal is supported (angle 0)");
  if (!(insertion.speed_m_per_s > 0.0) || !std::isfinite(insertion.speed_m_per_s))
    throw std::invalid_argument("insertion.speed_m_per_s must be positive for a scripted trajectory");
  if (!(insertion.withdrawal_speed_m_per_s > 0.0) || !std::isfinite(insertion.withdrawal_speed_m_per_s))
    throw std::invalid_argument("insertion.withdrawal_speed_m_per_s must be positive");
  if (!(insertion.dwell_s >= 0.0)) throw std::invalid_argument("insertion.dwell_s must be >= 0");
  const double travel = insertion.start_height_m + insertion.target_depth_m;
  if (!(travel > 0.0)) throw std::invalid_argument("insertion.target_depth_m must lie below the start height");
  insert_end_s_ = travel / insertion.speed_m_per_s;
  withdraw_duration_s_ = travel / insertion.withdrawal_speed_m_per_s;
}

NeedleState ScriptedTrajectory::sample(double t) const {
  NeedleState s;
  s.time_s = t;
  const double z_start = insertion_.start_height_m;
  const double z_target = -insertion_.target_depth_m;
  double z = z_start, v = 0.0;
  if (t <= 0.0) {
    z = z_start;
  } else if (t < insert_end_s_) {
    z = z_start - insertion_.speed_m_per_s * t;
    v = insertion_.speed_m_per_s;
  } else if (t < withdrawal_start_s()) {
    z = z_target;
  } else if (t < duration()) {
    z = z_target + insertion_.withdrawal_speed_m_per_s * (t - withdrawal_start_s());
    v = -insertion_.withdrawal_speed_m_per_s;
  }
  s.tip_position_m = Eigen::Vector3d(0.0, 0.0, z);
  s.axial_velocity_m_per_s = v;
  return s;
}

}  // namespace puncture
