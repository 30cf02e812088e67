// pressing_polynomial.hpp: the pre-puncture rise of a force-depth curve as a
// non-negative cubic, F = s z + a2 z^2 + a3 z^3 (the real-time model's tip
// spring with a linear force mesh and the polynomial stiffening law,
// core/include/puncture/stiffening.hpp).
//
// In:  deflections z (m, >= 0: depth below where the layer was first
//      pressed) and force rises F (N, force minus the force at z = 0), one
//      pair per sample, at least 3 samples.
// Out: PressingPolynomial with s (N/m), a2 (N/m^2), a3 (N/m^3), all >= 0,
//      minimising sum (F_i - F(z_i))^2 (non-negative least squares: the best
//      of the unconstrained fits on every subset of {z, z^2, z^3} whose
//      coefficients are all >= 0, which is the constrained optimum for three
//      unknowns), and the RMS residual (N). Throws std::invalid_argument for
//      fewer than 3 samples, mismatched sizes or non-finite values.
#pragma once

#include <vector>

namespace puncture::validation {

struct PressingPolynomial {
  double linear_N_per_m = 0.0;     ///< s
  double quadratic_N_per_m2 = 0.0; ///< a2
  double cubic_N_per_m3 = 0.0;     ///< a3
  double rms_residual_N = 0.0;
  double operator()(double z_m) const {
    return z_m * (linear_N_per_m + z_m * (quadratic_N_per_m2 + z_m * cubic_N_per_m3));
  }
};

PressingPolynomial fit_pressing_polynomial(const std::vector<double>& deflection_m, const std::vector<double>& force_rise_N);

}  // namespace puncture::validation
