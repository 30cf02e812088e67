// sh_fit.cpp: least-squares SH fitting (scattered and on a tensor grid); see sh_fit.hpp.
#include "puncture/sh/sh_fit.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/SVD>

namespace puncture {

namespace {
constexpr double kPi = 3.14159265358979323846;

void check_values(const char* who, int samples, const Eigen::MatrixXd& values) {
  if (values.rows() != samples) {
    throw std::invalid_argument(std::string(who) + ": values has " + std::to_string(values.rows()) +
                                " rows but there are " + std::to_string(samples) + " samples");
  }
  if (values.cols() < 1) throw std::invalid_argument(std::string(who) + ": values has no column");
  if (!values.allFinite()) throw std::invalid_argument(std::string(who) + ": values contain NaN or Inf");
}

void check_condition(const char* who, double sigma_max, double sigma_min, int unknowns) {
  if (!(sigma_min > 0.0) || sigma_max / sigma_min > kMaxFitConditionNumber) {
    throw std::invalid_argument(
        std::string(who) + ": the design matrix is rank deficient (condition number " +
        (sigma_min > 0.0 ? std::to_string(sigma_max / sigma_min) : std::string("inf")) + " > " +
        std::to_string(kMaxFitConditionNumber) + ") for " + std::to_string(unknowns) +
        " unknowns; the samples do not determine every SH coefficient (spread them over the "
        "sphere or lower the degree)");
  }
}

void fill_residuals(const Eigen::MatrixXd& residual, SHFitReport& report) {
  const Eigen::VectorXd row_norm = residual.rowwise().norm();
  report.rms_residual = std::sqrt(row_norm.squaredNorm() / double(row_norm.size()));
  report.max_residual = row_norm.maxCoeff();
}
}  // namespace

SHFitReport fit_sh_least_squares(const RealSHBasis& basis, const Eigen::MatrixX3d& directions,
                                 const Eigen::MatrixXd& values, Eigen::MatrixXd& coefficients) {
  const int n = int(directions.rows());
  const int unknowns = basis.count();
  check_values("fit_sh_least_squares", n, values);
  if (n < unknowns) {
    throw std::invalid_argument("fit_sh_least_squares: under-determined: " + std::to_string(n) +
                                " samples for " + std::to_string(unknowns) +
                                " unknowns at degree " + std::to_string(basis.degree()));
  }
  Eigen::MatrixXd design(n, unknowns);
  Eigen::VectorXd row(unknowns);
  for (int i = 0; i < n; ++i) {
    basis.evaluate(directions.row(i).transpose(), row.data());
    design.row(i) = row.transpose();
  }
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(design, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& sigma = svd.singularValues();
  check_condition("fit_sh_least_squares", sigma(0), sigma(sigma.size() - 1), unknowns);
  coefficients = svd.solve(values);

  SHFitReport report;
  report.samples = n;
  report.unknowns = unknowns;
  report.condition_number = sigma(0) / sigma(sigma.size() - 1);
  fill_residuals(design * coefficients - values, report);
  return report;
}

Eigen::Vector3d SHGrid::direction(int i, int j) const {
  const double z = cos_theta(i);
  const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {s * std::cos(phi(j)), s * std::sin(phi(j)), z};
}

Eigen::MatrixX3d SHGrid::directions() const {
  Eigen::MatrixX3d d(size(), 3);
  for (int i = 0; i < n_theta(); ++i)
    for (int j = 0; j < n_phi(); ++j) d.row(i * n_phi() + j) = direction(i, j).transpose();
  return d;
}

SHGrid make_sh_grid(int n_theta, int n_phi) {
  if (n_theta < 1 || n_phi < 1) throw std::invalid_argument("make_sh_grid: need n_theta, n_phi >= 1");
  SHGrid grid;
  gauss_legendre(n_theta, grid.cos_theta, grid.weights);
  grid.phi.resize(n_phi);
  for (int j = 0; j < n_phi; ++j) grid.phi(j) = 2.0 * kPi * j / n_phi;
  return grid;
}

namespace {

/// Associated Legendre factors B(i, index(l, m)) = Y_lm(theta_i, phi = 0) (nt x (L + 1)^2).
Eigen::MatrixXd legendre_factors(const RealSHBasis& basis, const SHGrid& grid) {
  const int nt = grid.n_theta(), unknowns = basis.count();
  Eigen::MatrixXd legendre(nt, unknowns);
  Eigen::VectorXd row(unknowns);
  for (int i = 0; i < nt; ++i) {
    basis.evaluate(grid.direction(i, 0), row.data());  // phi_0 = 0
    legendre.row(i) = row.transpose();
  }
  return legendre;
}

/// Fourier projections per polar node i: a_cos[m](i, :) = (cos_mj * F_i)(m, :) / sum_j cos^2
/// (likewise a_sin), F_i the np x k block of node i's samples.
void fourier_projections(const Eigen::MatrixXd& values, const Eigen::MatrixXd& cos_mj, const Eigen::MatrixXd& sin_mj,
                         int nt, std::vector<Eigen::MatrixXd>& a_cos, std::vector<Eigen::MatrixXd>& a_sin) {
  const int L = int(cos_mj.rows()) - 1, np = int(cos_mj.cols()), k = int(values.cols());
  a_cos.assign(L + 1, Eigen::MatrixXd(nt, k));
  a_sin.assign(L + 1, Eigen::MatrixXd(nt, k));
  for (int i = 0; i < nt; ++i) {
    const Eigen::MatrixXd block = values.middleRows(i * np, np);
    const Eigen::MatrixXd pc = cos_mj * block, ps = sin_mj * block;
    for (int m = 0; m <= L; ++m) {
      const double w = (m == 0) ? np : 0.5 * np;  // sum_j trig^2
      a_cos[m].row(i) = pc.row(m) / w;
      a_sin[m].row(i) = ps.row(m) / w;
    }
  }
}

/// The fit minus the samples at every grid sample (size x k).
Eigen::MatrixXd grid_residual(const Eigen::MatrixXd& values, const Eigen::MatrixXd& cos_mj,
                              const Eigen::MatrixXd& sin_mj, const std::vector<Eigen::MatrixXd>& fit_cos,
                              const std::vector<Eigen::MatrixXd>& fit_sin, int nt) {
  const int L = int(cos_mj.rows()) - 1, np = int(cos_mj.cols()), k = int(values.cols());
  Eigen::MatrixXd residual(values.rows(), k);
  Eigen::MatrixXd gc(L + 1, k), gs(L + 1, k);
  for (int i = 0; i < nt; ++i) {
    for (int m = 0; m <= L; ++m) {
      gc.row(m) = fit_cos[m].row(i);
      gs.row(m) = fit_sin[m].row(i);
    }
    residual.middleRows(i * np, np) =
        cos_mj.transpose() * gc + sin_mj.transpose() * gs - values.middleRows(i * np, np);
  }
  return residual;
}

}  // namespace

SHFitReport fit_sh_on_grid(const RealSHBasis& basis, const SHGrid& grid,
                           const Eigen::MatrixXd& values, Eigen::MatrixXd& coefficients) {
  const int L = basis.degree(), nt = grid.n_theta(), np = grid.n_phi();
  const int k = int(values.cols()), unknowns = basis.count();
  check_values("fit_sh_on_grid", grid.size(), values);
  if (np < 2 * L + 1) {
    throw std::invalid_argument("fit_sh_on_grid: need n_phi >= 2L + 1 = " + std::to_string(2 * L + 1) +
                                " azimuths, got " + std::to_string(np));
  }
  if (nt < L + 1) {
    throw std::invalid_argument("fit_sh_on_grid: under-determined: " + std::to_string(nt) +
                                " polar nodes for degree " + std::to_string(L) + " (need >= " +
                                std::to_string(L + 1) + ")");
  }

  const Eigen::MatrixXd legendre = legendre_factors(basis, grid);
  // Discrete Fourier factors: trig(m, j).
  Eigen::MatrixXd cos_mj(L + 1, np), sin_mj(L + 1, np);
  for (int m = 0; m <= L; ++m)
    for (int j = 0; j < np; ++j) {
      cos_mj(m, j) = std::cos(m * grid.phi(j));
      sin_mj(m, j) = std::sin(m * grid.phi(j));
    }
  std::vector<Eigen::MatrixXd> a_cos, a_sin;
  fourier_projections(values, cos_mj, sin_mj, nt, a_cos, a_sin);

  coefficients.setZero(unknowns, k);
  double sigma_max = 0.0, sigma_min = std::numeric_limits<double>::infinity();
  std::vector<Eigen::MatrixXd> fit_cos(L + 1), fit_sin(L + 1);  // B_m c_m, nt x k
  for (int m = 0; m <= L; ++m) {
    Eigen::MatrixXd b(nt, L + 1 - m);
    for (int l = m; l <= L; ++l) b.col(l - m) = legendre.col(sh_index(l, m));
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(b, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const double scale = std::sqrt((m == 0) ? double(np) : 0.5 * np);
    sigma_max = std::max(sigma_max, scale * svd.singularValues()(0));
    sigma_min = std::min(sigma_min, scale * svd.singularValues()(L - m));
    check_condition("fit_sh_on_grid", sigma_max, sigma_min, unknowns);
    const Eigen::MatrixXd c_cos = svd.solve(a_cos[m]);
    fit_cos[m] = b * c_cos;
    for (int l = m; l <= L; ++l) coefficients.row(sh_index(l, m)) = c_cos.row(l - m);
    if (m > 0) {
      const Eigen::MatrixXd c_sin = svd.solve(a_sin[m]);
      fit_sin[m] = b * c_sin;
      for (int l = m; l <= L; ++l) coefficients.row(sh_index(l, -m)) = c_sin.row(l - m);
    } else {
      fit_sin[m].setZero(nt, k);
    }
  }

  const Eigen::MatrixXd residual = grid_residual(values, cos_mj, sin_mj, fit_cos, fit_sin, nt);
  SHFitReport report;
  report.samples = grid.size();
  report.unknowns = unknowns;
  report.condition_number = sigma_max / sigma_min;
  fill_residuals(residual, report);
  return report;
}

}  // namespace puncture
