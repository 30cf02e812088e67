// sh_fit.hpp: least-squares fitting of SH coefficients (seed paper Sec. 2.1,
// "c_l^m can be calculated by the least-square fitting approach").
//
// In:  a basis of degree L, sample directions u_i on the sphere (need not be
//      unit) and sampled values f_i (one column per fitted function, e.g. the
//      x, y, z of Eq. 3 or the radius of Eq. 4).
// Out: coefficients (count x columns), minimising sum_i |A c - f|^2 with
//      A_ik = Y_k(u_i), and an SHFitReport.
// Errors: std::invalid_argument if samples < unknowns (under-determined) or
//      the design matrix is numerically rank deficient (condition number above
//      kMaxFitConditionNumber).
#pragma once

#include <Eigen/Core>

#include "puncture/sh/gauss_legendre.hpp"
#include "puncture/sh/real_sh.hpp"

namespace puncture {

struct SHFitReport {
  int samples = 0;                ///< number of sample points
  int unknowns = 0;               ///< coefficients per fitted function = (L + 1)^2
  double rms_residual = 0.0;      ///< sqrt(mean_i |r_i|^2), r_i = residual row of sample i (units of the values)
  double max_residual = 0.0;      ///< max_i |r_i|
  double condition_number = 0.0;  ///< sigma_max / sigma_min of the design matrix A (exact, from an SVD)
};

/// A design matrix whose condition number exceeds this is treated as rank deficient.
constexpr double kMaxFitConditionNumber = 1e10;

/// Scattered fit. directions: n x 3; values: n x k. Solves with a thin
/// BDCSVD (rank revealing; gives the exact condition number). Cost O(n L^4).
SHFitReport fit_sh_least_squares(const RealSHBasis& basis, const Eigen::MatrixX3d& directions,
                                 const Eigen::MatrixXd& values, Eigen::MatrixXd& coefficients);

/// Tensor sample grid: cos(theta) at Gauss-Legendre nodes x uniform phi.
/// Sample (i, j) has flat index i * n_phi + j.
struct SHGrid {
  Eigen::VectorXd cos_theta;  ///< n_theta Gauss-Legendre nodes in (-1, 1)
  Eigen::VectorXd weights;    ///< the matching Gauss-Legendre weights
  Eigen::VectorXd phi;        ///< n_phi azimuths 2 pi j / n_phi, rad
  int n_theta() const { return int(cos_theta.size()); }
  int n_phi() const { return int(phi.size()); }
  int size() const { return n_theta() * n_phi(); }
  Eigen::Vector3d direction(int i, int j) const;
  Eigen::MatrixX3d directions() const;  ///< size() x 3, flat order
};
SHGrid make_sh_grid(int n_theta, int n_phi);

/// Least-squares fit on an SHGrid; the same minimiser as fit_sh_least_squares
/// on those samples, but fast: with n_phi >= 2L + 1 the discrete Fourier sums
/// in phi are exactly orthogonal, so the normal equations split into one
/// small problem per order m (n_theta x (L + 1 - |m|), solved by JacobiSVD).
/// Cost O(n_theta n_phi L + L n_theta L^2). values: grid.size() x k.
/// Throws std::invalid_argument if n_phi < 2L + 1, n_theta < L + 1
/// (under-determined) or rank deficiency.
SHFitReport fit_sh_on_grid(const RealSHBasis& basis, const SHGrid& grid,
                           const Eigen::MatrixXd& values, Eigen::MatrixXd& coefficients);

}  // namespace puncture
