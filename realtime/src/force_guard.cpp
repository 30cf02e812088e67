#include "puncture/realtime/force_guard.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "puncture/model/realtime_model.hpp"

namespace puncture::realtime {

ForceGuard::ForceGuard(const Haptics& limits, double tick_period_s)
    : max_force_N_(limits.max_force_N), max_step_N_(limits.max_force_rate_N_per_s * tick_period_s) {
  if (!(max_force_N_ > 0.0) || !(max_step_N_ > 0.0))
    throw std::invalid_argument("ForceGuard: force and rate limits must be positive");
}

Eigen::Vector3d ForceGuard::apply(const Eigen::Vector3d& requested_N, unsigned& flags) noexcept {
  flags = 0;
  Eigen::Vector3d target = requested_N;
  if (!target.allFinite()) {
    target.setZero();
    flags |= kNonFiniteRequest;
  }
  const double magnitude = target.norm();
  if (magnitude > max_force_N_) {
    target *= max_force_N_ / magnitude;
    flags |= kMagnitudeClamped;
  }
  const Eigen::Vector3d step = target - last_;
  const double step_norm = step.norm();
  if (step_norm > max_step_N_) {
    last_ += step * (max_step_N_ / step_norm);
    flags |= kRateClamped;
  } else {
    last_ = target;
  }
  return last_;
}

RenderedImpedance probe_rendered_impedance(const Scene& scene) {
  RenderedImpedance out;
  if (scene.effects.damping)
    for (const Layer& l : scene.layers) out.damping_N_s_per_m += l.damping_N_s_per_m2 * l.thickness_m;

  RealtimeModel model = build_realtime_model(scene);
  const ScriptedRunResult run = run_scripted_insertion(model, scene);
  for (std::size_t i = 0; i < run.ticks.size(); ++i) {
    const TickResult& b = run.ticks[i];
    out.peak_force_N = std::max(out.peak_force_N, std::abs(b.total_force_N));
    if (i == 0) continue;
    const TickResult& a = run.ticks[i - 1];
    const double dx = b.depth_m - a.depth_m;
    if (!(dx > 1e-9)) continue;  // inserting only: the slope of the force-depth curve
    bool same_states = true;
    for (std::size_t k = 0; k < b.layers.size(); ++k) same_states &= a.layers[k].state == b.layers[k].state;
    if (!same_states) continue;  // a puncture (force drop) is not a stiffness
    const double slope = (b.total_force_N - a.total_force_N) / dx;
    if (slope > out.stiffness_N_per_m) {
      out.stiffness_N_per_m = slope;
      out.stiffness_depth_m = b.depth_m;
      out.stiffness_layer.clear();
      for (std::size_t k = 0; k < b.layers.size(); ++k)
        if (b.layers[k].state == LayerState::Pressed) out.stiffness_layer = scene.layers[k].name;
    }
  }
  return out;
}

StabilityAssessment assess_stability(const Haptics& h, double T, const RenderedImpedance& imp) {
  StabilityAssessment a;
  a.tick_period_s = T;
  a.stiffness_N_per_m = imp.stiffness_N_per_m;
  a.damping_N_s_per_m = imp.damping_N_s_per_m;
  a.device_damping_N_s_per_m = h.device_damping_N_s_per_m;
  a.passivity_demand_N_s_per_m = imp.stiffness_N_per_m * T / 2.0 + std::abs(imp.damping_N_s_per_m);
  a.max_passive_stiffness_N_per_m = 2.0 * (h.device_damping_N_s_per_m - std::abs(imp.damping_N_s_per_m)) / T;
  a.passive = a.passivity_demand_N_s_per_m <= h.device_damping_N_s_per_m;
  a.within_device_stiffness = imp.stiffness_N_per_m <= h.device_max_stiffness_N_per_m;
  a.within_force_limit = imp.peak_force_N <= h.max_force_N;
  std::ostringstream w;
  w << std::setprecision(3);
  if (!a.passive) {
    w << "not passive on this device: K T/2 + B = " << a.passivity_demand_N_s_per_m << " N s/m > b = "
      << h.device_damping_N_s_per_m << " N s/m (Colgate-Brown; K = " << imp.stiffness_N_per_m * 1e-3
      << " N/mm" << (imp.stiffness_layer.empty() ? "" : " in " + imp.stiffness_layer) << ", T = " << T * 1e3
      << " ms, B = " << imp.damping_N_s_per_m << " N s/m from the puncture damping d h): the device may buzz or "
      << "oscillate; lower K or d, raise the haptic rate or add device damping";
    a.warnings.push_back(w.str());
    w.str("");
  }
  if (!a.within_device_stiffness) {
    w << "stiffness K = " << imp.stiffness_N_per_m * 1e-3 << " N/mm exceeds the device's "
      << h.device_max_stiffness_N_per_m * 1e-3 << " N/mm";
    a.warnings.push_back(w.str());
    w.str("");
  }
  if (!a.within_force_limit) {
    w << "the scripted insertion peaks at " << imp.peak_force_N << " N, above haptics.max_force_N = " << h.max_force_N
      << " N: the guard clips the force sent to the device";
    a.warnings.push_back(w.str());
  }
  return a;
}

}  // namespace puncture::realtime
