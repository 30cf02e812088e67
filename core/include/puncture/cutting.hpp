// cutting.hpp: the cutting force of a punctured layer (Effects::cutting,
// ForceLaw::cutting_force_N, cutting_rate and cutting_release_m in scene.hpp).
//
// After a layer breaks, the needle tip advances a crack through it until it
// reaches the next layer's surface. Advancing the crack by ds costs the
// fracture energy G_c w ds (w: cut width, about the needle diameter 2R), so
// the needle feels the constant cutting force
//     C = G_c w                         (N; e.g. 1.1 kJ/m^2 x 1.27 mm = 1.4 N)
// while the tip is at the crack front. The front is the deepest point the
// tip has reached in the layer (s_front, measured along the needle axis);
// when the tip backs off by r = s_front - s_tip >= 0 the force falls
// linearly to 0 over the release distance r_c (the crack tip region unloads
// elastically; this keeps the force continuous when a device jitters):
//     F_cut = C max(0, 1 - r / r_c)
// Re-inserting into an existing crack costs nothing until the tip is back
// within r_c of the front. Withdrawal: F_cut = 0 once r >= r_c.
//
// Rate (ForceLaw::cutting_rate, b > 0). The bevel also wedges the tissue
// apart ahead of the crack, and a viscoelastic tissue resists that the more
// the faster it is done. With C the force at the reference speed v_ref:
//     C(v) = C [(1 - b) + b v / v_ref],   v clamped to [0, 100 v_ref],
// v the needle's axial speed now. C (1 - b) is the fracture part, b C v / v_ref
// the viscous part (reported with the tip force). The FEM reference shows this
// split in the default slab's muscle after its puncture (16-29 mm): its cutting
// column (the cohesive energy per unit advance) is 0.72-0.74 N at 1, 3, 10 and
// 20 mm/s (G_c w = 550 J/m^2 x 1.27 mm = 0.70 N), its tip column 0.25 / 0.28 /
// 0.55 / 1.00 N: a line through 1 and 10 mm/s gives 0.31 N at 3 and 0.89 N at
// 20 mm/s, a power law through them 0.36 N and 0.71 N. b = 0: C at every
// speed (the paper).
//
// Fracture limit. Advancing the crack costs G_c w whatever else the tip does,
// so of a fitted C (1 - b) only up to G_c w (the layer's measured toughness
// times the cut width 2a, when the scene gives it: PunctureCriterion) is
// fracture; the rest is the bevel's static resistance, reported with the
// viscous part as tip force (shaft_forces.hpp). The FEM's cutting column is
// exactly its cohesive energy per unit advance (reference_fem/README.md), so the
// parts are compared like for like; for the same reason nothing is fracture
// while the crack does not grow (the needle dwells or backs off): the force
// the tip still feels is the bevel's pressure on uncut tissue. The total
// force does not change.
//
// Rupture release (ForceLaw::rupture_release_m, l > 0). A layer does not let
// go of its load at once when it breaks: the crack opens through a cohesive
// process zone whose traction softens with the opening (a bilinear law of
// strength sigma_c and toughness G_c opens fully at delta_c = 2 G_c / sigma_c,
// about 1.1 mm for skin; a published skin law opens over 1.6 mm, Mohammadi et
// al. 2021). The needle feels the part of the load at its tip at the break
// F_b that exceeds the cutting force, R = max(0, F_b - C), released as the
// tip goes on by s past the break depth. F_b is the layer's surface force
// plus, when the layer was met at the tip with the layer above broken and
// squeezed between them, the crack force of that layer still cut at the
// break: its crack stops with the break, and the load it carried passes to
// this layer's crack (the FEM's fat, pressed through the cut skin, keeps
// cutting after its own break under the force the skin's crack carried):
//     F_rel = R exp(-s / l) max(0, 1 - r / r_c),
// s the deepest tip position since the break minus the break position (a
// crack does not close again), r the retraction from that deepest position
// as above. With l = 0 the force drops to C at the break (the paper's model).
//
// Release rate (ForceLaw::rupture_release_rate, m > 0). The process zone of a
// crack in a viscoelastic solid opens the slower, in tip travel, the faster it
// is loaded: the length is l(v_b) = l (v_b / v_ref)^m, v_b the needle's axial
// speed at the break (clamped to [v_ref / 100, 100 v_ref]). The FEM reference
// shows it after the default slab's skin breaks: its force falls to 1/e of the
// way to its trough over 0.4 / 0.6 / 0.9 / 1.2 mm at 1 / 3 / 10 / 20 mm/s
// (0.40 / 0.20 / 0.09 / 0.06 s: neither a fixed travel, m = 0, nor a fixed
// time, m = 1); a power through 1 and 10 mm/s (m = 0.35) gives 0.59 mm at 3 and
// 1.15 mm at 20 mm/s.
// The force at the break stays continuous: C + R = F_b. The energy released,
// R l, is the area between the curve and C.
#pragma once

#include <algorithm>
#include <cmath>

#include "puncture/breakthrough_rate.hpp"
#include "puncture/scene.hpp"

namespace puncture {

/// v clamp of the cutting rate law: 0 .. kCuttingRateClamp v_ref.
constexpr double kCuttingRateClamp = 100.0;

/// A cutting force split into its fracture part and the bevel's part (N).
struct CuttingForceParts {
  double fracture_N = 0.0;  ///< C (1 - b) (the whole C with b = 0), at most the fracture limit
  double bevel_N = 0.0;     ///< b C v / v_ref, plus any of C (1 - b) beyond the fracture limit
  double total_N() const { return fracture_N + bevel_N; }
};

/// C(v) of force law `law` at axial speed axial_speed_m_per_s (m/s, > 0
/// inserting), by part, before the release factor.
inline CuttingForceParts rate_cutting_force(const ForceLaw& law, double axial_speed_m_per_s) {
  const double b = law.cutting_rate.viscous_fraction;
  if (b == 0.0) return {law.cutting_force_N, 0.0};
  const double v_ref = law.cutting_rate.reference_speed_m_per_s;
  const double v = std::clamp(axial_speed_m_per_s, 0.0, kCuttingRateClamp * v_ref);
  return {law.cutting_force_N * (1.0 - b), law.cutting_force_N * b * v / v_ref};
}

/// l(v_b) (m) of force law `law` for a break at axial speed break_speed_m_per_s (m/s).
inline double rupture_release_length_m(const ForceLaw& law, double break_speed_m_per_s) {
  const ReleaseRate& r = law.rupture_release_rate;
  return law.rupture_release_m * clamped_rate_power(break_speed_m_per_s, r.reference_speed_m_per_s, r.exponent);
}

/// F_cut (N) for cutting force C (N), release distance r_c (m > 0), front and
/// tip positions along the needle axis (m, larger = deeper).
inline double cutting_force_N(double cutting_force_N, double release_m, double front_m, double tip_m) {
  const double r = std::max(0.0, front_m - tip_m);
  return cutting_force_N * std::max(0.0, 1.0 - r / release_m);
}

/// R (N): what a layer with force law `law` that broke under the load
/// force_at_break_N (N) at the tip (its surface force + the crack above still
/// cut) at axial speed axial_speed_m_per_s (m/s) releases beyond its cutting
/// force C(v) (0 without a rupture release length).
inline double rupture_release_N(const ForceLaw& law, double force_at_break_N, double axial_speed_m_per_s) {
  if (!(law.rupture_release_m > 0.0)) return 0.0;
  return std::max(0.0, force_at_break_N - rate_cutting_force(law, axial_speed_m_per_s).total_N());
}

/// F_rel (N) of a layer that broke with release R = release_N (N, >= 0) at
/// break_m, rupture release length l = length_m (m; <= 0: none), retraction
/// distance r_c = retraction_m (m > 0), the deepest tip position since the
/// break deepest_m and the tip at tip_m (m along the needle axis).
inline double rupture_release_force_N(double release_N, double length_m, double retraction_m, double break_m,
                                      double deepest_m, double tip_m) {
  if (!(length_m > 0.0) || !(release_N > 0.0)) return 0.0;
  const double s = std::max(0.0, deepest_m - break_m);
  const double r = std::max(0.0, deepest_m - tip_m);
  return release_N * std::exp(-s / length_m) * std::max(0.0, 1.0 - r / retraction_m);
}

}  // namespace puncture
