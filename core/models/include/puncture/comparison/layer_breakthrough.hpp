// layer_breakthrough.hpp: when a comparison model's layer breaks, by the rule
// the scene gives that layer for the real-time model
// (Layer::force_law.breakthrough, scene.hpp), so every model punctures by the
// same kind of criterion:
//   Rings          the paper's ring-w rule on the surface deflection at the
//                  force-mesh lattice points (ring_criterion.hpp);
//   CriticalForce  the model's contact force on the needle (N, positive
//                  resisting insertion) reaches critical_force_N;
//   CriticalEnergy the work the needle has done on the layer since its
//                  contact started, W = integral of F dz over the tip's
//                  advance (trapezoidal rule over the model's steps, J),
//                  reaches critical_energy_J (a continuum model's elastic
//                  energy and damping losses; the force mesh's is its stored
//                  energy).
// The critical force or energy scales with the layer's mean pressing speed
// as the real-time model's does (breakthrough_rate.hpp): the tip's advance
// since the contact started over the time since.
// The load the layer carried when it broke (the start of its rupture release,
// cutting.hpp) is the contact force at the break, but under the critical-force
// rule no more than the critical force: a model that finds the force above it
// on a step (a surface pressed onto the tip at once, after the layer above
// broke) crossed it between steps, where the layer broke; the layer cannot
// carry more than its strength.
// A depth prescribed for the layer (ComparisonSettings::
// prescribed_puncture_depths_m) overrides the rule: the layer breaks when the
// tip reaches it. Checked only while the needle advances (as the force mesh's
// rule).
// In: the layer, then per step the tip depth (m), the time (s) and the contact force (N);
// the ring deflections (m, into the tissue, from the contact) only for Rings.
#pragma once

#include <vector>

#include "puncture/comparison/ring_criterion.hpp"
#include "puncture/scene.hpp"

namespace puncture::comparison {

class LayerBreakthroughRule {
 public:
  /// prescribed_depth_m: the depth at which the layer breaks whatever its rule (<= 0: none).
  explicit LayerBreakthroughRule(const Layer& layer, double prescribed_depth_m = 0.0);
  /// The rule of layer k of the scene (with its prescribed depth, if any).
  static LayerBreakthroughRule of(const Scene& scene, std::size_t layer);

  BreakthroughCriterion::Kind kind() const { return criterion_.kind; }
  /// True for the ring rule, which needs the deflections at rings().points_m().
  bool needs_deflection() const { return criterion_.kind == BreakthroughCriterion::Kind::Rings && !(prescribed_depth_m_ > 0.0); }
  /// True when the rule reads the contact force (or its work) passed to advance().
  bool needs_force() const { return !needs_deflection() && !(prescribed_depth_m_ > 0.0); }
  const RingBreakthroughCriterion& rings() const { return rings_; }

  /// The needle's contact with the layer starts at this tip depth (m) at time_s (s).
  void start(double depth_m, double time_s);
  /// One model step (every step while the layer is pressed): the tip depth
  /// (m), the time (s) and the contact force (N; 0 when !needs_force()); books the work.
  void advance(double depth_m, double force_N, double time_s);
  /// Work done on the layer since start (J).
  double work_J() const { return work_J_; }
  /// Whether the layer breaks with this contact force (N) and, for Rings,
  /// ring deflections (m).
  bool broken(double force_N, const std::vector<double>& ring_deflection_m = {}) const;
  /// The load (N) the layer carried at its break with this contact force (N):
  /// the force, capped at the critical force at the pressing speed so far
  /// under the critical-force rule (not when a prescribed depth decides).
  double load_at_break_N(double force_N) const;

 private:
  BreakthroughCriterion criterion_;  ///< the layer's rule: kind, critical values, rate law
  double prescribed_depth_m_ = 0.0;
  RingBreakthroughCriterion rings_;
  double last_depth_m_ = 0.0;
  double last_force_N_ = 0.0;
  double work_J_ = 0.0;
  double start_depth_m_ = 0.0, start_time_s_ = 0.0, last_time_s_ = 0.0;
  /// s(v) of the criterion at the mean pressing speed since start().
  double rate_factor() const;
};

}  // namespace puncture::comparison
