#include "puncture/realtime/device.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>


namespace puncture::realtime {

NeedleFromPose::NeedleFromPose(double tick_period_s, double velocity_cutoff_Hz) : dt_(tick_period_s) {
  if (!(dt_ > 0.0)) throw std::invalid_argument("NeedleFromPose: tick period must be positive");
  if (!(velocity_cutoff_Hz >= 0.0)) throw std::invalid_argument("NeedleFromPose: cut-off must be >= 0");
  // Backward-Euler discretisation of the first-order low-pass 1 / (1 + s / (2 pi fc)).
  alpha_ = velocity_cutoff_Hz > 0.0 ? dt_ / (dt_ + 1.0 / (2.0 * M_PI * velocity_cutoff_Hz)) : 1.0;
}

NeedleState NeedleFromPose::convert(const DevicePose& pose, double time_s) noexcept {
  NeedleState s;
  s.time_s = time_s;
  s.tip_position_m = pose.position_m;
  Eigen::Vector3d axis = pose.orientation * Eigen::Vector3d(0.0, 0.0, -1.0);
  const double n = axis.norm();
  s.direction = n > 0.0 && std::isfinite(n) ? Eigen::Vector3d(axis / n) : Eigen::Vector3d(0.0, 0.0, -1.0);
  if (pose.has_velocity) {
    s.axial_velocity_m_per_s = s.direction.dot(pose.velocity_m_per_s);
  } else {
    const double raw = has_previous_ ? s.direction.dot(pose.position_m - previous_) / dt_ : 0.0;
    filtered_velocity_ = has_previous_ ? filtered_velocity_ + alpha_ * (raw - filtered_velocity_) : 0.0;
    s.axial_velocity_m_per_s = filtered_velocity_;
  }
  previous_ = pose.position_m;
  has_previous_ = true;
  return s;
}

std::uint32_t pack_layer_states(const TickResult& result) noexcept {
  std::uint32_t packed = 0;
  const std::size_t n = std::min<std::size_t>(result.layers.size(), 16);
  for (std::size_t k = 0; k < n; ++k) {
    std::uint32_t code = 0;
    if (result.layers[k].state == LayerState::Pressed) code = 1;
    if (result.layers[k].state == LayerState::Punctured) code = 2;
    packed |= code << (2 * k);
  }
  return packed;
}

LayerState unpack_layer_state(std::uint32_t packed, std::size_t layer) noexcept {
  const std::uint32_t code = (packed >> (2 * layer)) & 0x3u;
  return code == 1 ? LayerState::Pressed : code == 2 ? LayerState::Punctured : LayerState::Untouched;
}

}  // namespace puncture::realtime
