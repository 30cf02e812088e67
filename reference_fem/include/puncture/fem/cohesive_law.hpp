// cohesive_law.hpp: the traction-separation law of the crack that the needle
// cuts along its path (header-only, no deal.II).
//
// Bilinear mixed-mode law with scalar damage D (Camanho & Davila 2002 with a
// mode-independent toughness; the cohesive-zone form used for needle
// insertion by Oldfield et al. 2013, Mohammadi et al. 2021, Terzano et al. 2020):
//   separation  delta = (delta_n, delta_t) (m): opening normal to the crack
//               and sliding along it;
//   effective   lambda = sqrt(<delta_n>^2 + delta_t^2)  (<x> = max(x, 0));
//   energy/area phi = (1 - D) K0/2 (<delta_n>^2 + delta_t^2) + K0/2 <-delta_n>^2
//               (closing is resisted by the undamaged penalty K0: the faces
//               do not interpenetrate);
//   damage      D(lambda_max) = delta_f (lambda_max - delta_0) / (lambda_max (delta_f - delta_0))
//               between delta_0 = sigma_c / K0 and delta_f = 2 G_c / sigma_c,
//               0 before, 1 after; lambda_max = largest lambda so far
//               (irreversible).
// Energy: the work to open a unit area to full separation is G_c, on any
// loading path (the law is one of lambda); the dissipated energy per area is
// accumulated as int Y dD with Y = K0/2 lambda^2 (exactly G_c at D = 1).
//
// Viscous regularisation (Gao & Bower 2004): the damage follows its
// rate-independent value D_inf(lambda_max) with delay eta (s),
//   dD/dt = (D_inf - D) / eta, integrated implicitly over a step dt:
//   D = (D_old + (dt/eta) D_inf) / (1 + dt/eta);  eta = 0: D = D_inf.
// It lets Newton trace an unstable crack jump (a puncture) over a few steps.
//
// Units: tractions Pa, separations m, stiffness Pa/m, toughness J/m^2.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace puncture::fem {

/// Parameters of one layer's cohesive law.
struct CohesiveLawParameters {
  double strength_Pa = 1e6;            ///< sigma_c: peak traction
  double toughness_J_per_m2 = 1e3;     ///< G_c: area under the law
  /// delta_0 / delta_f: the elastic part of the law, small so that the intact
  /// crack adds little compliance (K0 = sigma_c / (elastic_fraction delta_f)).
  double elastic_fraction = 0.01;
  double viscosity_s = 0.0;            ///< eta of the viscous regularisation

  double failure_separation_m() const { return 2.0 * toughness_J_per_m2 / strength_Pa; }
  double onset_separation_m() const { return elastic_fraction * failure_separation_m(); }
  double initial_stiffness_Pa_per_m() const { return strength_Pa / onset_separation_m(); }
  void check() const {
    if (!(strength_Pa > 0.0) || !(toughness_J_per_m2 > 0.0) || !std::isfinite(strength_Pa) ||
        !std::isfinite(toughness_J_per_m2))
      throw std::invalid_argument("cohesive law: strength and toughness must be positive and finite");
    if (!(elastic_fraction > 0.0 && elastic_fraction < 1.0))
      throw std::invalid_argument("cohesive law: elastic fraction must lie in (0, 1)");
    if (!(viscosity_s >= 0.0) || !std::isfinite(viscosity_s))
      throw std::invalid_argument("cohesive law: viscosity must be >= 0");
  }
};

/// History of one cohesive point (committed at converged steps).
struct CohesiveHistory {
  double max_separation_m = 0.0;  ///< lambda_max
  double damage = 0.0;            ///< D
  double dissipated_J_per_m2 = 0.0;
};

/// Traction (Pa) on the outer face, its tangent (Pa/m) with respect to the
/// separation, and the updated history, at a trial separation.
struct CohesiveResponse {
  std::array<double, 2> traction{0.0, 0.0};  ///< d phi / d delta (n, t)
  std::array<std::array<double, 2>, 2> tangent{};  ///< d traction / d delta (symmetric)
  CohesiveHistory history;                   ///< trial history at this separation
};

/// Rate-independent damage of the bilinear law and its derivative.
inline double bilinear_damage(const CohesiveLawParameters& p, double lambda_max, double* dD = nullptr) {
  const double d0 = p.onset_separation_m(), df = p.failure_separation_m();
  if (dD != nullptr) *dD = 0.0;
  if (lambda_max <= d0) return 0.0;
  if (lambda_max >= df) return 1.0;
  if (dD != nullptr) *dD = df * d0 / (lambda_max * lambda_max * (df - d0));
  return df * (lambda_max - d0) / (lambda_max * (df - d0));
}

/// Energy per unit area the rate-independent bilinear law has dissipated when
/// its damage is D (J/m^2): the area under the law up to the separation
/// lambda(D) at which it reaches D, less the energy still stored,
/// 0.5 (1 - D) K0 lambda^2. Phi(0) = 0, Phi(1) = G_c, increasing. A state
/// function of D, so the crack's dissipation never exceeds G_c per unit area
/// whatever the step (the viscous regularisation's own dissipation is not
/// fracture energy and is not counted).
inline double bilinear_dissipation_J_per_m2(const CohesiveLawParameters& p, double D) {
  D = std::clamp(D, 0.0, 1.0);
  if (D <= 0.0) return 0.0;
  const double d0 = p.onset_separation_m(), df = p.failure_separation_m(), sc = p.strength_Pa;
  const double lambda = df * d0 / (df - D * (df - d0));  // inverse of bilinear_damage
  const double x = (df - lambda) / (df - d0);
  const double area = 0.5 * sc * d0 + 0.5 * sc * (df - d0) * (1.0 - x * x);
  return area - 0.5 * (1.0 - D) * p.initial_stiffness_Pa_per_m() * lambda * lambda;
}

/// Evaluates the law at separation (delta_n, delta_t) from the committed
/// history over a step of dt seconds.
inline CohesiveResponse cohesive_response(const CohesiveLawParameters& p, const CohesiveHistory& committed,
                                          double delta_n, double delta_t, double dt_s) {
  CohesiveResponse r;
  const double K0 = p.initial_stiffness_Pa_per_m();
  const double dn_pos = std::max(delta_n, 0.0);
  const double lambda = std::sqrt(dn_pos * dn_pos + delta_t * delta_t);
  const bool loading = lambda > committed.max_separation_m;
  r.history.max_separation_m = std::max(lambda, committed.max_separation_m);
  double dDinf = 0.0;
  const double D_inf = bilinear_damage(p, r.history.max_separation_m, loading ? &dDinf : nullptr);
  double weight = 1.0;  // dD / dD_inf of the implicit viscous update
  double D = D_inf;
  if (p.viscosity_s > 0.0) {
    const double q = std::max(dt_s, 0.0) / p.viscosity_s;
    weight = q / (1.0 + q);
    D = (committed.damage + q * D_inf) / (1.0 + q);
  }
  D = std::clamp(std::max(D, committed.damage), 0.0, 1.0);
  r.history.damage = D;
  r.history.dissipated_J_per_m2 = bilinear_dissipation_J_per_m2(p, D);
  const double s = (1.0 - D) * K0;
  r.traction[0] = delta_n > 0.0 ? s * delta_n : K0 * delta_n;
  r.traction[1] = s * delta_t;
  r.tangent[0][0] = delta_n > 0.0 ? s : K0;
  r.tangent[1][1] = s;
  r.tangent[0][1] = r.tangent[1][0] = 0.0;
  // Softening: d traction / d delta gains -K0 dD/dlambda (delta' x delta') / lambda.
  const double dD_dlambda = weight * dDinf;
  if (loading && dD_dlambda > 0.0 && lambda > 0.0 && D < 1.0) {
    const double v[2] = {dn_pos, delta_t};
    const double c = K0 * dD_dlambda / lambda;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) r.tangent[i][j] -= c * v[i] * v[j];
  }
  return r;
}

}  // namespace puncture::fem
