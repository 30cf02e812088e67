// Standard errors and correlations from a least-squares Jacobian (identifiability.hpp).
#include <cmath>
#include <limits>

#include "puncture/validation/identifiability.hpp"

namespace puncture::validation {

JacobianStatistics jacobian_statistics(const Eigen::MatrixXd& J, const Eigen::VectorXd& r, double threshold) {
  JacobianStatistics s;
  const Eigen::Index m = J.rows(), n = J.cols();
  s.residuals = static_cast<int>(m);
  s.parameters = static_cast<int>(n);
  s.sensitivity = J.colwise().norm().transpose();
  s.residual_variance = r.squaredNorm() / static_cast<double>(std::max<Eigen::Index>(m - n, 1));
  const double inf = std::numeric_limits<double>::infinity();
  s.standard_error = Eigen::VectorXd::Constant(n, inf);
  s.correlation = Eigen::MatrixXd::Constant(n, n, std::numeric_limits<double>::quiet_NaN());
  if (n == 0 || m == 0) return s;
  // J = U S V^T: (J^T J)^-1 = V S^-2 V^T over the determined directions.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  const Eigen::MatrixXd V = svd.matrixV();
  const double smax = sv.size() ? sv(0) : 0.0;
  std::vector<bool> determined(static_cast<std::size_t>(n), smax > 0.0);
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index k = 0; k < sv.size(); ++k) {
    if (sv(k) > 1e-8 * smax) {
      cov += V.col(k) * V.col(k).transpose() / (sv(k) * sv(k));
      continue;
    }
    for (Eigen::Index j = 0; j < n; ++j)
      if (std::abs(V(j, k)) > 0.05) determined[static_cast<std::size_t>(j)] = false;
  }
  cov *= s.residual_variance;
  for (Eigen::Index j = 0; j < n; ++j)
    if (determined[static_cast<std::size_t>(j)]) s.standard_error(j) = std::sqrt(std::max(cov(j, j), 0.0));
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      if (!determined[static_cast<std::size_t>(i)] || !determined[static_cast<std::size_t>(j)]) continue;
      const double d = std::sqrt(cov(i, i) * cov(j, j));
      s.correlation(i, j) = d > 0.0 ? cov(i, j) / d : (i == j ? 1.0 : 0.0);
    }
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = i + 1; j < n; ++j)
      if (std::abs(s.correlation(i, j)) > threshold)
        s.correlated.push_back({static_cast<int>(i), static_cast<int>(j), s.correlation(i, j)});
  return s;
}

}  // namespace puncture::validation
