#include "puncture/validation/pressing_polynomial.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

namespace puncture::validation {

PressingPolynomial fit_pressing_polynomial(const std::vector<double>& z, const std::vector<double>& f) {
  if (z.size() != f.size()) throw std::invalid_argument("fit_pressing_polynomial: deflection and force sizes differ");
  if (z.size() < 3) throw std::invalid_argument("fit_pressing_polynomial: needs at least 3 samples");
  const auto n = static_cast<Eigen::Index>(z.size());
  // Columns z, z^2, z^3 scaled by the largest deflection (conditioning).
  double z_max = 0.0;
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (!std::isfinite(z[i]) || !std::isfinite(f[i])) throw std::invalid_argument("fit_pressing_polynomial: non-finite sample");
    z_max = std::max(z_max, std::abs(z[i]));
  }
  if (!(z_max > 0.0)) throw std::invalid_argument("fit_pressing_polynomial: every deflection is 0");
  Eigen::MatrixXd basis(n, 3);
  Eigen::VectorXd rhs(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double x = z[static_cast<std::size_t>(i)] / z_max;
    basis(i, 0) = x, basis(i, 1) = x * x, basis(i, 2) = x * x * x;
    rhs(i) = f[static_cast<std::size_t>(i)];
  }
  // Candidates: F = 0 and every subset fit with non-negative coefficients.
  double best = rhs.squaredNorm();
  Eigen::Vector3d best_c = Eigen::Vector3d::Zero();
  for (int mask = 1; mask < 8; ++mask) {
    std::vector<int> cols;
    for (int j = 0; j < 3; ++j)
      if (mask & (1 << j)) cols.push_back(j);
    Eigen::MatrixXd a(n, static_cast<Eigen::Index>(cols.size()));
    for (std::size_t j = 0; j < cols.size(); ++j) a.col(static_cast<Eigen::Index>(j)) = basis.col(cols[j]);
    const Eigen::VectorXd c = a.colPivHouseholderQr().solve(rhs);
    if ((c.array() < 0.0).any() || !c.allFinite()) continue;
    const double r = (a * c - rhs).squaredNorm();
    if (r < best) {
      best = r;
      best_c.setZero();
      for (std::size_t j = 0; j < cols.size(); ++j) best_c(cols[j]) = c(static_cast<Eigen::Index>(j));
    }
  }
  PressingPolynomial p;
  p.linear_N_per_m = best_c(0) / z_max;
  p.quadratic_N_per_m2 = best_c(1) / (z_max * z_max);
  p.cubic_N_per_m3 = best_c(2) / (z_max * z_max * z_max);
  p.rms_residual_N = std::sqrt(best / static_cast<double>(n));
  return p;
}

}  // namespace puncture::validation
