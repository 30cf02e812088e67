#include "puncture/stiffening.hpp"

#include <cmath>

namespace puncture {

double stiffening_force_N(const StiffeningLaw& law, double z) {
  if (!(z > 0.0)) return 0.0;
  if (law.kind == StiffeningLaw::Kind::Polynomial) return z * z * (law.quadratic_N_per_m2 + law.cubic_N_per_m3 * z);
  const double x = z / law.strain_scale_m;
  return law.exponential_stiffness_N_per_m * law.strain_scale_m * (std::expm1(x) - x);
}

double stiffening_stiffness_N_per_m(const StiffeningLaw& law, double z) {
  if (!(z > 0.0)) return 0.0;
  if (law.kind == StiffeningLaw::Kind::Polynomial) return z * (2.0 * law.quadratic_N_per_m2 + 3.0 * law.cubic_N_per_m3 * z);
  return law.exponential_stiffness_N_per_m * std::expm1(z / law.strain_scale_m);
}

double stiffening_energy_J(const StiffeningLaw& law, double z) {
  if (!(z > 0.0)) return 0.0;
  if (law.kind == StiffeningLaw::Kind::Polynomial)
    return z * z * z * (law.quadratic_N_per_m2 / 3.0 + law.cubic_N_per_m3 * z / 4.0);
  const double zs = law.strain_scale_m, x = z / zs;
  // integral of k_e zs (e^(s/zs) - 1 - s/zs) ds from 0 to z
  return law.exponential_stiffness_N_per_m * zs * zs * (std::expm1(x) - x - 0.5 * x * x);
}

}  // namespace puncture
