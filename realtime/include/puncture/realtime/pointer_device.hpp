// pointer_device.hpp: the mouse-and-keyboard needle.
//
// The view thread (VTK interactor) sets a target tip position; the haptic
// thread moves the needle tip towards it with a critically damped second-order
// follower (natural frequency `follow_Hz`, speed limited to `max_speed`),
// integrated at the haptic rate:
//     a = w^2 (target - x) - 2 w v,   v += T a,  |v| <= v_max,   x += T v,
// so the coarse, 60-100 Hz mouse steps reach the model as a smooth motion
// with a finite velocity (which drives the damping force d h v). The target is
// clamped to the sample (lateral radius) and to [below the skin by
// total thickness - 0.5 mm, `max_height_m` above it]. The needle points
// straight down (-z); the view requests a fresh tissue with request_fresh_tissue(),
// served once the tip is above the skin (z >= 0).
// Thread use: set_target/request_fresh_tissue from ONE thread (the view),
// read/write from the haptic thread; exchange through a triple buffer and an
// atomic counter (no locks).
#pragma once

#include <atomic>

#include "puncture/realtime/device.hpp"
#include "puncture/realtime/triple_buffer.hpp"

namespace puncture::realtime {

struct PointerDeviceOptions {
  double follow_Hz = 6.0;            ///< natural frequency of the follower
  double max_speed_m_per_s = 0.05;   ///< speed limit of the needle tip
  double max_height_m = 0.02;        ///< highest tip position above the skin
};

class PointerDevice final : public HapticDevice {
 public:
  PointerDevice(const Scene& scene, double tick_period_s, PointerDeviceOptions options = {});
  std::string name() const override { return "mouse"; }

  // --- view thread ---
  /// Clamped and stored; returns the clamped target.
  Eigen::Vector3d set_target(const Eigen::Vector3d& tip_m) noexcept;
  const Eigen::Vector3d& target() const { return target_; }
  void request_fresh_tissue() noexcept { fresh_requests_.fetch_add(1, std::memory_order_release); }
  /// Start position: on the axis at the scene's start height.
  Eigen::Vector3d home() const { return home_; }

  // --- haptic thread ---
  void read(std::int64_t tick, double time_s, DeviceInput& input) noexcept override;
  void fresh_tissue_result(bool done) noexcept override;
  void write(const ForceOutput&) noexcept override {}

 private:
  Eigen::Vector3d clamp(const Eigen::Vector3d& p) const noexcept;

  double dt_, omega_, max_speed_;
  double radius_m_, min_z_m_, max_z_m_;
  Eigen::Vector3d home_;
  Eigen::Vector3d target_;               ///< view thread's copy
  TripleBuffer<Eigen::Vector3d> shared_target_;
  std::atomic<unsigned> fresh_requests_{0};
  // haptic thread state
  Eigen::Vector3d position_, velocity_ = Eigen::Vector3d::Zero(), haptic_target_;
  unsigned fresh_served_ = 0;
  bool fresh_pending_ = false;
};

}  // namespace puncture::realtime
