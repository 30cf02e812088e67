// jacobian_statistics (identifiability.hpp) against the closed-form
// ordinary-least-squares standard errors of a straight line, and on
// Jacobians with a known rank defect.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "puncture/validation/identifiability.hpp"

namespace pv = puncture::validation;

TEST(JacobianStatistics, StraightLineStandardErrorsMatchTheClosedForm) {
  // y = a + b t + noise; at the OLS optimum J = [1, t], r = fit - y.
  const int n = 40;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.3);
  Eigen::VectorXd t(n), y(n);
  for (int i = 0; i < n; ++i) t(i) = 0.25 * i, y(i) = 1.0 + 2.0 * t(i) + noise(rng);
  Eigen::MatrixXd J(n, 2);
  J.col(0).setOnes();
  J.col(1) = t;
  const Eigen::VectorXd beta = J.colPivHouseholderQr().solve(y);
  const Eigen::VectorXd r = J * beta - y;
  const pv::JacobianStatistics s = pv::jacobian_statistics(J, r);
  // Closed form: sigma^2 = SSR / (n - 2); se(b) = sigma / sqrt(Sxx); se(a) = sigma sqrt(1/n + tbar^2 / Sxx);
  // corr(a, b) = -tbar / sqrt(mean(t^2)).
  const double sigma2 = r.squaredNorm() / (n - 2);
  const double tbar = t.mean();
  const double sxx = (t.array() - tbar).square().sum();
  EXPECT_NEAR(s.residual_variance, sigma2, 1e-12);
  EXPECT_NEAR(s.standard_error(1), std::sqrt(sigma2 / sxx), 1e-10);
  EXPECT_NEAR(s.standard_error(0), std::sqrt(sigma2 * (1.0 / n + tbar * tbar / sxx)), 1e-10);
  EXPECT_NEAR(s.correlation(0, 1), -tbar / std::sqrt(t.array().square().mean()), 1e-10);
  EXPECT_NEAR(s.sensitivity(0), std::sqrt(static_cast<double>(n)), 1e-12);
  EXPECT_NEAR(s.sensitivity(1), t.norm(), 1e-12);
  // The mean is 4.9 of a span 0..9.75: corr(a, b) = -0.86, below 0.95: no pair named.
  EXPECT_TRUE(s.correlated.empty());
}

TEST(JacobianStatistics, AParameterTheResidualsDoNotDependOnIsNotDetermined) {
  Eigen::MatrixXd J(5, 3);
  J << 1, 0, 2, 2, 0, 1, 3, 0, 0, 4, 0, 1, 5, 0, 3;
  const Eigen::VectorXd r = Eigen::VectorXd::Constant(5, 0.1);
  const pv::JacobianStatistics s = pv::jacobian_statistics(J, r);
  EXPECT_EQ(s.sensitivity(1), 0.0);
  EXPECT_TRUE(std::isinf(s.standard_error(1)));
  EXPECT_TRUE(std::isfinite(s.standard_error(0)));
  EXPECT_TRUE(std::isfinite(s.standard_error(2)));
  EXPECT_TRUE(std::isnan(s.correlation(0, 1)));
}

TEST(JacobianStatistics, NamesNearlyCollinearPairsAndFlagsExactlyCollinearOnes) {
  Eigen::MatrixXd J(6, 3);
  for (int i = 0; i < 6; ++i) {
    J(i, 0) = 1.0 + i;
    J(i, 1) = (1.0 + i) * (1.0 + 0.02 * ((i % 2) ? 1.0 : -1.0));  // column 0 within 2 %
    J(i, 2) = (i % 3) - 1.0;
  }
  const Eigen::VectorXd r = Eigen::VectorXd::Constant(6, 0.05);
  const pv::JacobianStatistics s = pv::jacobian_statistics(J, r);
  ASSERT_EQ(s.correlated.size(), 1u);
  EXPECT_EQ(s.correlated[0].first, 0);
  EXPECT_EQ(s.correlated[0].second, 1);
  EXPECT_LT(s.correlated[0].correlation, -0.95);  // compensating parameters: negative correlation
  // Exactly collinear: neither is determined.
  J.col(1) = 2.0 * J.col(0);
  const pv::JacobianStatistics t = pv::jacobian_statistics(J, r);
  EXPECT_TRUE(std::isinf(t.standard_error(0)));
  EXPECT_TRUE(std::isinf(t.standard_error(1)));
  EXPECT_TRUE(std::isfinite(t.standard_error(2)));
}
