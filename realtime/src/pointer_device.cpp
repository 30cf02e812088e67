#include "puncture/realtime/pointer_device.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace puncture::realtime {

PointerDevice::PointerDevice(const Scene& scene, double tick_period_s, PointerDeviceOptions o)
    : dt_(tick_period_s),
      omega_(2.0 * M_PI * o.follow_Hz),
      max_speed_(o.max_speed_m_per_s),
      radius_m_(0.5 * scene.sample.diameter_m),
      min_z_m_(-(scene.total_thickness_m() - 0.5e-3)),
      max_z_m_(o.max_height_m),
      home_(0.0, 0.0, std::min(scene.insertion.start_height_m, o.max_height_m)),
      target_(home_),
      shared_target_([this](Eigen::Vector3d& v) { v = home_; }),
      position_(home_),
      haptic_target_(home_) {
  if (!(dt_ > 0.0) || !(o.follow_Hz > 0.0) || !(max_speed_ > 0.0))
    throw std::invalid_argument("PointerDevice: tick period, follow frequency and speed must be positive");
  if (omega_ * dt_ > 0.5)
    throw std::invalid_argument("PointerDevice: follow frequency too high for the haptic rate");
}

Eigen::Vector3d PointerDevice::clamp(const Eigen::Vector3d& p) const noexcept {
  Eigen::Vector3d q = p.allFinite() ? p : home_;
  const double r = std::hypot(q.x(), q.y());
  if (r > radius_m_) {
    q.x() *= radius_m_ / r;
    q.y() *= radius_m_ / r;
  }
  q.z() = std::clamp(q.z(), min_z_m_, max_z_m_);
  return q;
}

Eigen::Vector3d PointerDevice::set_target(const Eigen::Vector3d& tip_m) noexcept {
  target_ = clamp(tip_m);
  shared_target_.back() = target_;
  shared_target_.publish();
  return target_;
}

void PointerDevice::read(std::int64_t, double, DeviceInput& input) noexcept {
  if (shared_target_.update()) haptic_target_ = shared_target_.front();
  const unsigned requests = fresh_requests_.load(std::memory_order_acquire);
  if (requests != fresh_served_) fresh_pending_ = true;
  // Critically damped follower, semi-implicit Euler at the haptic step.
  const Eigen::Vector3d a = omega_ * omega_ * (haptic_target_ - position_) - 2.0 * omega_ * velocity_;
  velocity_ += dt_ * a;
  const double speed = velocity_.norm();
  if (speed > max_speed_) velocity_ *= max_speed_ / speed;
  position_ += dt_ * velocity_;
  input.status = DeviceInput::Status::Pose;
  input.pose.position_m = position_;
  input.pose.orientation.setIdentity();
  input.pose.velocity_m_per_s = velocity_;
  input.pose.has_velocity = true;
  // A fresh tissue only with the tip above the skin: a new tissue must not
  // start with the needle already inside it.
  input.fresh_tissue = fresh_pending_ && position_.z() >= 0.0;
  input.has_exact_needle = false;
  input.has_expected = false;
}

void PointerDevice::fresh_tissue_result(bool done) noexcept {
  if (!done) return;
  fresh_pending_ = false;
  fresh_served_ = fresh_requests_.load(std::memory_order_acquire);
}

}  // namespace puncture::realtime
