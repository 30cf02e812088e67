// force_guard.hpp: the haptic stability guard.
//
// ForceGuard limits the force vector sent to a device, every haptic tick:
//   1. magnitude: |F| <= haptics.max_force_N (the vector is scaled down);
//   2. rate:      |F_n - F_{n-1}| <= haptics.max_force_rate_N_per_s * T
//                 (the step is shortened along its own direction).
// Both limits hold at once: F_{n-1} and the clipped target lie in the ball
// |F| <= max_force_N, so the shortened step does too. A non-finite request is
// treated as zero (and flagged). The model's own force is never changed; only
// what goes to the device.
//
// Stability criterion (assess_stability). A sampled-data haptic display that
// renders a virtual stiffness K and damping B at sample period T through a
// device with physical damping b is passive when
//        b > K T / 2 + |B|                        (Colgate and Brown 1994)
// (necessary and sufficient for a spring-damper wall with a backward-difference
// velocity and zero-order hold). We take K = the steepest force-depth slope the
// model renders (probed along the scene's scripted insertion, puncture drops
// excluded) and B = the viscous puncture damping of the whole shaft with every
// layer punctured, sum_k d_k t_k (Table 1's F = d h v). The app also warns when
// K exceeds the device's data-sheet stiffness and when the scripted insertion's
// peak force exceeds max_force_N (the guard will clip it).
// Units: N, N/s, N/m, N s/m, s.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "puncture/scene.hpp"

namespace puncture::realtime {

enum GuardFlags : unsigned {
  kMagnitudeClamped = 1u << 0,
  kRateClamped = 1u << 1,
  kNonFiniteRequest = 1u << 2,
};

class ForceGuard {
 public:
  ForceGuard(const Haptics& limits, double tick_period_s);

  /// One tick: returns the force to send; `flags` gets GuardFlags bits.
  Eigen::Vector3d apply(const Eigen::Vector3d& requested_N, unsigned& flags) noexcept;
  /// The next output starts from zero again (a new device or a fresh tissue).
  void reset() noexcept { last_.setZero(); }

  const Eigen::Vector3d& last_output_N() const { return last_; }
  double max_force_N() const { return max_force_N_; }
  double max_step_N() const { return max_step_N_; }

 private:
  double max_force_N_, max_step_N_;
  Eigen::Vector3d last_ = Eigen::Vector3d::Zero();
};

/// What the model renders, as seen by a device.
struct RenderedImpedance {
  double stiffness_N_per_m = 0.0;       ///< K: steepest force-depth slope without a puncture in between
  double stiffness_depth_m = 0.0;       ///< depth where it occurs
  std::string stiffness_layer;          ///< layer being pressed there ("" if none)
  double damping_N_s_per_m = 0.0;       ///< B: sum_k d_k t_k (0 when the damping effect is off)
  double peak_force_N = 0.0;            ///< largest |force| along the scripted insertion
};

/// Builds a fresh model from `scene` and drives it along the scene's scripted
/// insertion (about as long as `puncture run`, typically well under a second).
RenderedImpedance probe_rendered_impedance(const Scene& scene);

struct StabilityAssessment {
  double tick_period_s = 0.0;
  double stiffness_N_per_m = 0.0;       ///< K
  double damping_N_s_per_m = 0.0;       ///< B
  double device_damping_N_s_per_m = 0.0;  ///< b
  double passivity_demand_N_s_per_m = 0.0;  ///< K T / 2 + B
  double max_passive_stiffness_N_per_m = 0.0;  ///< 2 (b - B) / T (<= 0: no stiffness is passive)
  bool passive = true;                  ///< K T / 2 + B <= b
  bool within_device_stiffness = true;  ///< K <= device_max_stiffness
  bool within_force_limit = true;       ///< peak force <= max_force_N
  std::vector<std::string> warnings;    ///< one sentence each, empty when all hold
};

StabilityAssessment assess_stability(const Haptics& haptics, double tick_period_s, const RenderedImpedance& impedance);

}  // namespace puncture::realtime
