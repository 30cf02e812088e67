// sh_surface.cpp: radial (Eq. 4) and parametric (Eq. 3) SH surfaces; see sh_surface.hpp.
#include "puncture/sh/sh_surface.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Geometry>

namespace puncture {

void sphere_tangent_frame(const Eigen::Vector3d& u, Eigen::Vector3d& e1, Eigen::Vector3d& e2) {
  // Helper axis: the coordinate axis least aligned with u.
  const Eigen::Vector3d a = u.cwiseAbs();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  if (a.y() <= a.x() && a.y() <= a.z()) axis = Eigen::Vector3d::UnitY();
  else if (a.z() <= a.x() && a.z() <= a.y()) axis = Eigen::Vector3d::UnitZ();
  e1 = (axis - u * u.dot(axis)).normalized();
  e2 = u.cross(e1);  // e1 x e2 = e1 x (u x e1) = u
}

bool normal_from_jacobian(const Eigen::Vector3d& u, const Eigen::Matrix3d& jacobian,
                          Eigen::Vector3d& normal) {
  Eigen::Vector3d e1, e2;
  sphere_tangent_frame(u, e1, e2);
  const Eigen::Vector3d n = (jacobian * e1).cross(jacobian * e2);
  const double scale = jacobian.squaredNorm();
  const double len = n.norm();
  if (!(len > 1e-14 * scale) || !std::isfinite(len)) return false;
  normal = n / len;
  return true;
}

int highest_order(const Eigen::MatrixXd& coefficients, int degree) {
  int order = 0;
  for (int l = 0; l <= degree; ++l)
    for (int m = -l; m <= l; ++m)
      if (std::abs(m) > order && !coefficients.row(sh_index(l, m)).isZero(0.0)) order = std::abs(m);
  return order;
}

namespace {
Eigen::Vector3d unit(const Eigen::Vector3d& u) {
  const double n = u.norm();
  if (!(n > 0.0) || !std::isfinite(n)) throw std::invalid_argument("SH surface: direction must be finite and non-zero");
  return u / n;
}
}  // namespace

// ----- RadialSHSurface -----------------------------------------------------------------

RadialSHSurface::RadialSHSurface(int degree, Eigen::VectorXd coefficients)
    : basis_(degree), coefficients_(std::move(coefficients)) {
  if (coefficients_.size() != basis_.count()) {
    throw std::invalid_argument("RadialSHSurface: need " + std::to_string(basis_.count()) +
                                " coefficients for degree " + std::to_string(degree) + ", got " +
                                std::to_string(coefficients_.size()));
  }
  max_order_ = highest_order(coefficients_, degree);
}

RadialSHSurface RadialSHSurface::fit(int degree, const Eigen::MatrixX3d& directions,
                                     const Eigen::VectorXd& radii, SHFitReport* report) {
  const RealSHBasis basis(degree);
  Eigen::MatrixXd c;
  const SHFitReport r = fit_sh_least_squares(basis, directions, radii, c);
  if (report) *report = r;
  return RadialSHSurface(degree, c.col(0));
}

double RadialSHSurface::radius(const Eigen::Vector3d& u, SHWorkspace& ws) const {
  basis_.evaluate(u, ws.values.data(), max_order_);
  double r = 0.0;
  for (int l = 0; l <= degree(); ++l)
    for (int m = -std::min(l, max_order_); m <= std::min(l, max_order_); ++m)
      r += coefficients_(sh_index(l, m)) * ws.values(sh_index(l, m));
  return r;
}

Eigen::Vector3d RadialSHSurface::position(const Eigen::Vector3d& u, SHWorkspace& ws) const {
  return radius(u, ws) * unit(u);
}

SurfacePoint RadialSHSurface::evaluate(const Eigen::Vector3d& u_in, SHWorkspace& ws) const {
  const Eigen::Vector3d u = unit(u_in);
  basis_.evaluate_with_gradient(u, ws.values.data(), ws.gradient.data(), max_order_);
  double r = 0.0;
  Eigen::Vector3d grad_r = Eigen::Vector3d::Zero();
  for (int l = 0; l <= degree(); ++l)
    for (int m = -std::min(l, max_order_); m <= std::min(l, max_order_); ++m) {
      const int k = sh_index(l, m);
      r += coefficients_(k) * ws.values(k);
      grad_r += coefficients_(k) * ws.gradient.col(k);
    }
  if (!(r > 0.0)) {
    throw std::domain_error("RadialSHSurface::evaluate: radius " + std::to_string(r) +
                            " <= 0; the expansion is not a star-shaped surface here");
  }
  SurfacePoint p;
  p.position = r * u;
  p.normal = (r * u - grad_r).normalized();
  return p;
}

Eigen::Vector3d RadialSHSurface::position(const Eigen::Vector3d& u) const {
  SHWorkspace ws = make_workspace();
  return position(u, ws);
}

SurfacePoint RadialSHSurface::evaluate(const Eigen::Vector3d& u) const {
  SHWorkspace ws = make_workspace();
  return evaluate(u, ws);
}

// ----- ParametricSHSurface ---------------------------------------------------------------

ParametricSHSurface::ParametricSHSurface(int degree, Eigen::MatrixX3d coefficients)
    : basis_(degree), coefficients_(std::move(coefficients)) {
  if (coefficients_.rows() != basis_.count()) {
    throw std::invalid_argument("ParametricSHSurface: need " + std::to_string(basis_.count()) +
                                " coefficient rows for degree " + std::to_string(degree) + ", got " +
                                std::to_string(coefficients_.rows()));
  }
  max_order_ = highest_order(coefficients_, degree);
}

ParametricSHSurface ParametricSHSurface::fit(int degree, const Eigen::MatrixX3d& directions,
                                             const Eigen::MatrixX3d& positions, SHFitReport* report) {
  const RealSHBasis basis(degree);
  Eigen::MatrixXd c;
  const SHFitReport r = fit_sh_least_squares(basis, directions, positions, c);
  if (report) *report = r;
  return ParametricSHSurface(degree, c);
}

Eigen::Vector3d ParametricSHSurface::position(const Eigen::Vector3d& u, SHWorkspace& ws) const {
  basis_.evaluate(u, ws.values.data(), max_order_);
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (int l = 0; l <= degree(); ++l)
    for (int m = -std::min(l, max_order_); m <= std::min(l, max_order_); ++m) {
      const int k = sh_index(l, m);
      x += ws.values(k) * coefficients_.row(k).transpose();
    }
  return x;
}

void ParametricSHSurface::position_and_jacobian(const Eigen::Vector3d& u, SHWorkspace& ws,
                                                Eigen::Vector3d& position,
                                                Eigen::Matrix3d& jacobian) const {
  basis_.evaluate_with_gradient(u, ws.values.data(), ws.gradient.data(), max_order_);
  // X = sum_k C_k Y_k and J(a, b) = sum_k C(k, a) grad_b Y_k over the present
  // orders, as fixed-size loops (Eigen's dynamic GEMM path costs ~10 us here).
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  Eigen::Matrix3d j = Eigen::Matrix3d::Zero();
  const double* y = ws.values.data();
  const double* g = ws.gradient.data();
  for (int l = 0; l <= degree(); ++l)
    for (int m = -std::min(l, max_order_); m <= std::min(l, max_order_); ++m) {
      const int k = sh_index(l, m);
      const Eigen::Vector3d c = coefficients_.row(k).transpose();
      const Eigen::Vector3d grad(g[3 * k], g[3 * k + 1], g[3 * k + 2]);
      x += y[k] * c;
      j += c * grad.transpose();
    }
  position = x;
  jacobian = j;
}

void ParametricSHSurface::tangent_derivatives(const Eigen::Vector3d& u, const Eigen::Vector3d& t1,
                                              const Eigen::Vector3d& t2, SHWorkspace& ws,
                                              Eigen::Vector3d& d1, Eigen::Vector3d& d2) const {
  Eigen::Vector3d x;
  Eigen::Matrix3d j;
  position_and_jacobian(u, ws, x, j);
  d1 = j * t1;  // J u = 0, so the normal component of t does not contribute
  d2 = j * t2;
}

SurfacePoint ParametricSHSurface::evaluate(const Eigen::Vector3d& u_in, SHWorkspace& ws) const {
  const Eigen::Vector3d u = unit(u_in);
  SurfacePoint p;
  Eigen::Matrix3d j;
  position_and_jacobian(u, ws, p.position, j);
  if (!normal_from_jacobian(u, j, p.normal)) {
    throw std::domain_error("ParametricSHSurface::evaluate: the map is singular at u = (" +
                            std::to_string(u.x()) + ", " + std::to_string(u.y()) + ", " +
                            std::to_string(u.z()) + "); no normal");
  }
  return p;
}

Eigen::Vector3d ParametricSHSurface::position(const Eigen::Vector3d& u) const {
  SHWorkspace ws = make_workspace();
  return position(u, ws);
}

SurfacePoint ParametricSHSurface::evaluate(const Eigen::Vector3d& u) const {
  SHWorkspace ws = make_workspace();
  return evaluate(u, ws);
}

}  // namespace puncture
