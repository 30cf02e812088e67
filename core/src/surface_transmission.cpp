#include "puncture/surface_transmission.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace puncture {

namespace {
constexpr double kPi = 3.14159265358979323846;
// 4-point Gauss-Legendre on [-1, 1].
constexpr std::array<double, 4> kNodes{-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                       0.8611363115940526};
constexpr std::array<double, 4> kWeights{0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                         0.3478548451374538};
}  // namespace

double boussinesq_kernel_per_m2(double rho_m, double depth_m) {
  const double q = rho_m * rho_m + depth_m * depth_m;
  return 3.0 * depth_m * depth_m * depth_m / (2.0 * kPi * q * q * std::sqrt(q));
}

double boussinesq_ring_kernel_per_m(double rho_m, double s_m, double h) {
  const double A = rho_m * rho_m + s_m * s_m + h * h, B = 2.0 * rho_m * s_m;
  const double a = A + B, b = A - B;
  const double k = std::sqrt(std::clamp(2.0 * B / a, 0.0, 1.0));
  const double K = std::comp_ellint_1(k), E = std::comp_ellint_2(k);
  const double J = (4.0 / 3.0) / (std::sqrt(a) * b) * ((2.0 * E - K) / (2.0 * a) + E / b);
  return 3.0 * h * h * h / kPi * J;
}

Eigen::MatrixXd transmission_weights(const std::vector<double>& r, const std::vector<double>& targets, double h) {
  if (!(h > 0.0) || !std::isfinite(h)) throw std::invalid_argument("transmission_weights: depth must be > 0");
  if (r.empty() || r[0] != 0.0) throw std::invalid_argument("transmission_weights: the profile must start at r = 0");
  for (std::size_t j = 1; j < r.size(); ++j)
    if (!(r[j] > r[j - 1]) || !std::isfinite(r[j]))
      throw std::invalid_argument("transmission_weights: profile radii must increase");
  const auto n = static_cast<Eigen::Index>(r.size());
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(targets.size()), n);
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const double rho = targets[i];
    if (!(rho >= 0.0) || !std::isfinite(rho)) throw std::invalid_argument("transmission_weights: target radii must be >= 0");
    for (Eigen::Index j = 0; j + 1 < n; ++j) {
      const double lo = r[j], width = r[j + 1] - r[j];
      const int pieces = std::max(1, static_cast<int>(std::ceil(4.0 * width / h)));
      const double step = width / pieces;
      for (int p = 0; p < pieces; ++p)
        for (std::size_t g = 0; g < kNodes.size(); ++g) {
          const double s = lo + step * (p + 0.5 * (kNodes[g] + 1.0));
          const double f = 0.5 * step * kWeights[g] * boussinesq_ring_kernel_per_m(rho, s, h) * s;
          const double t = (s - lo) / width;
          W(static_cast<Eigen::Index>(i), j) += f * (1.0 - t);
          W(static_cast<Eigen::Index>(i), j + 1) += f * t;
        }
    }
  }
  return W;
}

double profile_value_at(const std::vector<double>& r, const double* u, double rho) {
  if (r.empty() || rho > r.back()) return 0.0;
  const auto it = std::upper_bound(r.begin(), r.end(), rho);
  if (it == r.end()) return u[r.size() - 1];
  const std::size_t j = static_cast<std::size_t>(it - r.begin());
  if (j == 0) return u[0];
  const double t = (rho - r[j - 1]) / (r[j] - r[j - 1]);
  return (1.0 - t) * u[j - 1] + t * u[j];
}

}  // namespace puncture
