#include "puncture/realtime/scripted_device.hpp"

#include <stdexcept>

namespace puncture::realtime {

ScriptedDevice::ScriptedDevice(const Insertion& insertion, double tick_period_s, bool repeat, double rest_s)
    : trajectory_(insertion), dt_(tick_period_s), rest_s_(rest_s), repeat_(repeat) {
  if (!(dt_ > 0.0)) throw std::invalid_argument("ScriptedDevice: tick period must be positive");
  if (!(rest_s_ >= 0.0)) throw std::invalid_argument("ScriptedDevice: rest must be >= 0");
}

void ScriptedDevice::read(std::int64_t, double time_s, DeviceInput& input) noexcept {
  const double local_t = static_cast<double>(cycle_ticks_) * dt_;
  if (repeat_ && local_t > cycle_duration_s()) waiting_ = true;
  // While waiting for a fresh tissue the needle rests at the trajectory's
  // start (= end) pose; the tick that gets the fresh tissue is the new t = 0.
  const NeedleState s = trajectory_.sample(waiting_ ? 0.0 : local_t);
  input.status = DeviceInput::Status::Pose;
  input.fresh_tissue = waiting_;
  input.pose.position_m = s.tip_position_m;
  // The needle axis orientation * (0, 0, -1) is the trajectory's direction (the identity along the sample axis).
  input.pose.orientation = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d(0.0, 0.0, -1.0), s.direction);
  input.pose.velocity_m_per_s = s.direction * s.axial_velocity_m_per_s;
  input.pose.has_velocity = true;
  input.has_exact_needle = false;
  input.has_expected = false;
  (void)time_s;
  if (!waiting_) ++cycle_ticks_;
}

void ScriptedDevice::fresh_tissue_result(bool done) noexcept {
  if (!done) return;
  waiting_ = false;
  cycle_ticks_ = 1;  // this tick ran at local t = 0
  ++cycles_;
}

}  // namespace puncture::realtime
