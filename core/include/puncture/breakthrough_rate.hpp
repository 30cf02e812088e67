// breakthrough_rate.hpp: the rate dependence of a layer's breakthrough
// threshold (BreakthroughCriterion::rate_exponent, reference_speed_m_per_s
// in scene.hpp).
//
// A viscoelastic solid is harder to tear the faster it is loaded: the energy
// a crack needs grows with its loading rate, as a power of the rate over the
// range a test covers (Gent 1996, Langmuir 12:4492; Persson & Brener 2005,
// Phys. Rev. E 71:036123). The FEM reference shows it for the default slab:
// its force before the skin breaks rises by 10 % from 1 to 20 mm/s (8.0 mm:
// 1.74 / 1.84 / 1.89 / 1.92 N at 1 / 3 / 10 / 20 mm/s), while the skin's
// peak rises by 27 %, from 2.53 N at 9.0 mm to 3.22 N at 9.6 mm: the skin
// tears later and under more force when pressed faster (results/fem_rate and
// the cached references). The real-time criterion reads this as a critical
// force (or energy) that grows with the speed the layer is pressed at:
//     F_c(v) = F_c,ref s(v),   s(v) = (v / v_ref)^n,
// v the layer's mean pressing speed: the tip's advance along the needle axis
// since the layer's contact over the time since (m/s; a mean, so a jittering
// device or a pause does not make the threshold jump), clamped to
// [v_ref / 100, 100 v_ref] (a pause or a retraction does not make the layer
// break at once). n = 0: s = 1 (the paper's rate-independent threshold).
// n is identified from references at two or more speeds (the calibration's
// rate stage, with d); F_c,ref from the reference at v_ref.
#pragma once

#include <algorithm>
#include <cmath>

#include "puncture/scene.hpp"

namespace puncture {

/// v clamp of the rate law: v_ref / kRateClamp .. kRateClamp v_ref.
constexpr double kBreakthroughRateClamp = 100.0;

/// Mean pressing speed (m/s) of a layer whose contact started at
/// contact_axial_m (m along the needle axis) at contact_time_s (s), with the
/// tip now at tip_axial_m at time_s; v_ref (m/s) while no time has passed.
inline double mean_pressing_speed_m_per_s(double contact_axial_m, double contact_time_s, double tip_axial_m,
                                          double time_s, double reference_speed_m_per_s) {
  const double dt = time_s - contact_time_s;
  if (!(dt > 0.0)) return reference_speed_m_per_s;
  return (tip_axial_m - contact_axial_m) / dt;
}

/// (v / v_ref)^n with v (m/s) clamped to [v_ref / kBreakthroughRateClamp,
/// kBreakthroughRateClamp v_ref]; 1 for n = 0. The power rate law of the
/// breakthrough threshold and of the rupture release length (cutting.hpp).
inline double clamped_rate_power(double speed_m_per_s, double reference_speed_m_per_s, double exponent) {
  if (exponent == 0.0) return 1.0;
  const double v_ref = reference_speed_m_per_s;
  const double v = std::clamp(speed_m_per_s, v_ref / kBreakthroughRateClamp, v_ref * kBreakthroughRateClamp);
  return std::pow(v / v_ref, exponent);
}

/// s(v) (dimensionless, > 0) of criterion c at the mean pressing speed v (m/s).
inline double breakthrough_rate_factor(const BreakthroughCriterion& c, double speed_m_per_s) {
  return clamped_rate_power(speed_m_per_s, c.reference_speed_m_per_s, c.rate_exponent);
}

}  // namespace puncture
