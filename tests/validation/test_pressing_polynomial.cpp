// fit_pressing_polynomial: the non-negative cubic through a pre-puncture rise.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "puncture/validation/pressing_polynomial.hpp"

using puncture::validation::fit_pressing_polynomial;

TEST(PressingPolynomial, RecoversTheCoefficientsOfAnExactCubic) {
  // F = 20 z + 300 z^2 + 4e6 z^3 (SI) sampled on 0..9 mm: recovered to round-off.
  std::vector<double> z, f;
  for (int i = 1; i <= 30; ++i) {
    const double x = 0.3e-3 * i;
    z.push_back(x);
    f.push_back(20 * x + 300 * x * x + 4e6 * x * x * x);
  }
  const auto p = fit_pressing_polynomial(z, f);
  EXPECT_NEAR(p.linear_N_per_m, 20, 1e-6 * 20);
  EXPECT_NEAR(p.quadratic_N_per_m2, 300, 1e-5 * 300);
  EXPECT_NEAR(p.cubic_N_per_m3, 4e6, 1e-6 * 4e6);
  EXPECT_LT(p.rms_residual_N, 1e-9);
}

TEST(PressingPolynomial, ANegativeUnconstrainedCoefficientGivesTheKktPointOfTheConstrainedProblem) {
  // F = z^3 - 0.3 z^2 on z in [0, 1] (scaled units): the unconstrained fit is
  // exactly (0, -0.3, 1), so a constraint is active. The non-negative optimum
  // satisfies the Karush-Kuhn-Tucker conditions, checked independently here:
  // with g = A^T (A c - F), g_j = 0 where c_j > 0 and g_j >= 0 where c_j = 0.
  std::vector<double> z, f;
  for (int i = 1; i <= 40; ++i) {
    const double x = i / 40.0;
    z.push_back(x);
    f.push_back(x * x * x - 0.3 * x * x);
  }
  const auto p = fit_pressing_polynomial(z, f);
  const double c[3] = {p.linear_N_per_m, p.quadratic_N_per_m2, p.cubic_N_per_m3};
  int active = 0;
  for (int j = 0; j < 3; ++j) {
    EXPECT_GE(c[j], 0.0);
    double g = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < z.size(); ++i) {
      const double a = std::pow(z[i], j + 1);
      g += a * (p(z[i]) - f[i]);
      scale += a * std::abs(f[i]);
    }
    if (c[j] > 0.0) {
      EXPECT_NEAR(g / scale, 0.0, 1e-10) << "coefficient " << j;
    } else {
      ++active;
      EXPECT_GE(g / scale, -1e-10) << "coefficient " << j;
    }
  }
  EXPECT_GE(active, 1);
}

TEST(PressingPolynomial, AFallingCurveFitsZeroAndBadInputIsRejected) {
  const auto p = fit_pressing_polynomial({1e-3, 2e-3, 3e-3}, {-0.1, -0.2, -0.3});
  EXPECT_EQ(p.linear_N_per_m + p.quadratic_N_per_m2 + p.cubic_N_per_m3, 0.0);
  EXPECT_NEAR(p.rms_residual_N, std::sqrt((0.01 + 0.04 + 0.09) / 3), 1e-12);
  EXPECT_THROW(fit_pressing_polynomial({1e-3, 2e-3}, {0.1, 0.2}), std::invalid_argument);
  EXPECT_THROW(fit_pressing_polynomial({1e-3, 2e-3, NAN}, {0.1, 0.2, 0.3}), std::invalid_argument);
  EXPECT_THROW(fit_pressing_polynomial({1e-3, 2e-3, 3e-3}, {0.1, 0.2}), std::invalid_argument);
}
