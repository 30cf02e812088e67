// layer_surface.cpp: SH surface of a cylindrical tissue layer; see layer_surface.hpp.
#include "puncture/sh/layer_surface.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Geometry>
#include <Eigen/LU>

namespace puncture {

namespace {
constexpr double kPi = 3.14159265358979323846;

/// Smooth step I_sigma(k, k) on [0, 1]; first k - 1 derivatives vanish at 0 and 1.
double smooth_step(double sigma, int k) {
  sigma = std::clamp(sigma, 0.0, 1.0);
  const int n = 2 * k - 1;
  double sum = 0.0, binom = 1.0;  // binom = C(n, j)
  for (int j = 0; j <= n; ++j) {
    if (j > 0) binom = binom * (n - j + 1) / j;
    if (j >= k) sum += binom * std::pow(sigma, j) * std::pow(1.0 - sigma, n - j);
  }
  return sum;
}

void check_options(const LayerFitOptions& o) {
  if (!(o.top_rim_cos_theta > 0.0 && o.top_rim_cos_theta < 1.0) ||
      !(o.bottom_rim_cos_theta > -1.0 && o.bottom_rim_cos_theta < o.top_rim_cos_theta) ||
      o.corner_order < 1 || !(o.oversampling >= 1.0)) {
    throw std::invalid_argument(
        "LayerFitOptions: need 0 < top_rim_cos_theta < 1, -1 < bottom_rim_cos_theta < "
        "top_rim_cos_theta, corner_order >= 1, oversampling >= 1");
  }
}
}  // namespace

// ----- LayerProfile --------------------------------------------------------------------

namespace {
/// The profile from zeta and the accurately known 1 - zeta, 1 + zeta (near the
/// poles these come from sin^2(theta), not from the rounded zeta).
void profile_at(const LayerProfile& p, double zeta, double one_minus_zeta, double one_plus_zeta,
                double& rho_m, double& z_m) {
  const double zt = p.options.top_rim_cos_theta, zb = p.options.bottom_rim_cos_theta;
  const int k = p.options.corner_order;
  if (zeta >= zt) {
    const double tau = one_minus_zeta / (1.0 - zt);
    rho_m = p.radius_m * std::sqrt(std::max(0.0, -std::expm1(k * std::log1p(-tau))));  // 1 - (1 - tau)^k
    z_m = p.top_z_m;
  } else if (zeta >= zb) {
    rho_m = p.radius_m;
    z_m = p.top_z_m - p.thickness_m() * smooth_step((zt - zeta) / (zt - zb), k);
  } else {
    const double tau = one_plus_zeta / (1.0 + zb);
    rho_m = p.radius_m * std::sqrt(std::max(0.0, -std::expm1(k * std::log1p(-tau))));
    z_m = p.bottom_z_m;
  }
}
}  // namespace

void LayerProfile::profile(double zeta, double& rho_m, double& z_m) const {
  zeta = std::clamp(zeta, -1.0, 1.0);
  profile_at(*this, zeta, 1.0 - zeta, 1.0 + zeta, rho_m, z_m);
}

Eigen::Vector3d LayerProfile::position(const Eigen::Vector3d& u_in) const {
  const Eigen::Vector3d u = u_in.normalized();
  const double s = std::hypot(u.x(), u.y());
  const double zeta = std::clamp(u.z(), -1.0, 1.0);
  // 1 -+ zeta = s^2 / (1 +- zeta): exact near the poles.
  const double one_minus = zeta > 0.0 ? s * s / (1.0 + zeta) : 1.0 - zeta;
  const double one_plus = zeta < 0.0 ? s * s / (1.0 - zeta) : 1.0 + zeta;
  double rho, z;
  profile_at(*this, zeta, one_minus, one_plus, rho, z);
  if (s == 0.0) return {0.0, 0.0, z};  // rho = 0 at the poles
  return {rho * u.x() / s, rho * u.y() / s, z};
}

Eigen::Vector3d LayerProfile::top_face_direction(double x_m, double y_m) const {
  const double r = std::hypot(x_m, y_m);
  if (r == 0.0) return Eigen::Vector3d::UnitZ();
  const double g = std::min(1.0, (r / radius_m) * (r / radius_m));  // = 1 - (1 - tau)^k
  // tau = 1 - (1 - g)^(1/k), written to keep full relative precision near the axis.
  const double tau = -std::expm1(std::log1p(-g) / options.corner_order);
  const double one_minus_zeta = tau * (1.0 - options.top_rim_cos_theta);
  const double zeta = 1.0 - one_minus_zeta;
  const double s = std::sqrt(std::max(0.0, one_minus_zeta * (1.0 + zeta)));
  return {s * x_m / r, s * y_m / r, zeta};
}

// ----- LayerSurface --------------------------------------------------------------------

LayerSurface::LayerSurface(LayerProfile profile, ParametricSHSurface surface, SHFitReport report)
    : profile_(std::move(profile)),
      surface_(std::move(surface)),
      report_(report),
      workspace_(surface_.basis().count()) {}

LayerSurface LayerSurface::fit(double top_z_m, double bottom_z_m, double radius_m, int degree,
                               const LayerFitOptions& options) {
  if (!(top_z_m <= 0.0) || !(bottom_z_m < top_z_m) || !(radius_m > 0.0) ||
      !std::isfinite(bottom_z_m) || !std::isfinite(radius_m)) {
    throw std::invalid_argument("LayerSurface::fit: need bottom_z < top_z <= 0 and radius > 0 (got top_z = " +
                                std::to_string(top_z_m) + ", bottom_z = " + std::to_string(bottom_z_m) +
                                ", radius = " + std::to_string(radius_m) + ")");
  }
  if (degree < 2) throw std::invalid_argument("LayerSurface::fit: need SH degree >= 2");
  check_options(options);
  LayerProfile profile{top_z_m, bottom_z_m, radius_m, options};

  const RealSHBasis basis(degree);
  const int n_theta = int(std::ceil(options.oversampling * (degree + 1)));
  const SHGrid grid = make_sh_grid(n_theta, 2 * degree + 2);
  Eigen::MatrixXd positions(grid.size(), 3);
  for (int i = 0; i < grid.n_theta(); ++i)
    for (int j = 0; j < grid.n_phi(); ++j)
      positions.row(i * grid.n_phi() + j) = profile.position(grid.direction(i, j)).transpose();
  Eigen::MatrixXd coefficients;
  const SHFitReport report = fit_sh_on_grid(basis, grid, positions, coefficients);

  // By the axial symmetry of the disc only orders m = 0 (z) and m = +-1 (x, y)
  // are present; the fit returns the others at rounding level. Check that and
  // set them exactly to zero, so evaluation runs over |m| <= 1 only.
  const double length_scale = std::max(radius_m, top_z_m - bottom_z_m);
  for (int l = 2; l <= degree; ++l)
    for (int m = -l; m <= l; ++m) {
      if (std::abs(m) < 2) continue;
      const double c = coefficients.row(sh_index(l, m)).cwiseAbs().maxCoeff();
      if (!(c <= 1e-10 * length_scale)) {
        throw std::logic_error("LayerSurface::fit: coefficient of order m = " + std::to_string(m) +
                               " is " + std::to_string(c) + " m; the disc fit lost its axial symmetry");
      }
      coefficients.row(sh_index(l, m)).setZero();
    }

  LayerSurface layer(profile, ParametricSHSurface(degree, coefficients), report);
  layer.measure_errors();
  return layer;
}

void LayerSurface::measure_errors() {
  const double R = profile_.radius_m;
  // Top face within 0.9 R: lateral radii uniform in area, 8 azimuths, plus the axis.
  const int n_r = 200, n_phi = 8;
  double max_err = 0.0, sum_sq = 0.0;
  int n = 0;
  auto add_top = [&](double x, double y) {
    const double e = std::abs(surface_.position(profile_.top_face_direction(x, y), workspace_).z() - profile_.top_z_m);
    max_err = std::max(max_err, e);
    sum_sq += e * e;
    ++n;
  };
  add_top(0.0, 0.0);
  for (int i = 0; i < n_r; ++i) {
    const double r = 0.9 * R * std::sqrt((i + 0.5) / n_r);
    for (int j = 0; j < n_phi; ++j) {
      const double phi = 2.0 * kPi * (j + 0.5 * (i % 2)) / n_phi;
      add_top(r * std::cos(phi), r * std::sin(phi));
    }
  }
  top_face_max_error_m_ = max_err;
  top_face_rms_error_m_ = std::sqrt(sum_sq / n);

  // Whole surface: area-weighted rms over a Gauss-Legendre x uniform grid.
  const SHGrid grid = make_sh_grid(4 * degree() + 40, 8);
  double weighted = 0.0, area = 0.0;
  for (int i = 0; i < grid.n_theta(); ++i)
    for (int j = 0; j < grid.n_phi(); ++j) {
      const Eigen::Vector3d u = grid.direction(i, j);
      const double e2 = (surface_.position(u, workspace_) - profile_.position(u)).squaredNorm();
      weighted += grid.weights(i) * e2;
      area += grid.weights(i);
    }
  whole_surface_rms_error_m_ = std::sqrt(weighted / area);
}

void LayerSurface::gnomonic(double a, double b, Eigen::Vector3d& u, Eigen::Vector3d& du_da,
                            Eigen::Vector3d& du_db) {
  const double w = std::sqrt(1.0 + a * a + b * b);
  u = Eigen::Vector3d(a, b, 1.0) / w;
  du_da = (Eigen::Vector3d::UnitX() - u * u.x()) / w;
  du_db = (Eigen::Vector3d::UnitY() - u * u.y()) / w;
}

bool LayerSurface::intersect_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                 double& s, SurfacePoint& hit) const {
  if (!origin.allFinite() || !direction.allFinite()) return false;
  const double R = profile_.radius_m;
  const double length_scale = std::max({R, profile_.thickness_m(), std::abs(profile_.top_z_m)});
  const double tol = 1e-12 * length_scale;
  if (std::abs(direction.z()) < 1e-12 * direction.norm()) return false;  // parallel to the face

  // Warm start: the exact plane hit, mapped to the parameter sphere.
  double s_k = (profile_.top_z_m - origin.z()) / direction.z();
  const Eigen::Vector3d p0 = origin + s_k * direction;
  if (std::hypot(p0.x(), p0.y()) > R) return false;  // misses the disc
  const Eigen::Vector3d u0 = profile_.top_face_direction(p0.x(), p0.y());
  double a = u0.x() / u0.z(), b = u0.y() / u0.z();

  Eigen::Vector3d u, du_da, du_db, x;
  Eigen::Matrix3d jac, newton;
  bool converged = false;
  for (int iter = 0; iter < 12; ++iter) {
    gnomonic(a, b, u, du_da, du_db);
    surface_.position_and_jacobian(u, workspace_, x, jac);
    const Eigen::Vector3d residual = x - origin - s_k * direction;
    if (!residual.allFinite()) return false;
    if (residual.norm() <= tol) {
      converged = true;
      break;
    }
    newton.col(0) = jac * du_da;
    newton.col(1) = jac * du_db;
    newton.col(2) = -direction;
    const Eigen::PartialPivLU<Eigen::Matrix3d> lu(newton);
    if (!(std::abs(lu.determinant()) > 0.0)) return false;
    const Eigen::Vector3d step = lu.solve(-residual);
    if (!step.allFinite()) return false;
    a += step(0);
    b += step(1);
    s_k += step(2);
  }
  if (!converged) return false;
  if (s_k < 0.0) return false;
  if (u.z() < profile_.options.top_rim_cos_theta) return false;  // left the top face
  if (!normal_from_jacobian(u, jac, hit.normal)) return false;
  hit.position = x;
  s = s_k;
  return true;
}

SurfacePoint LayerSurface::project(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d u0 = profile_.top_face_direction(p.x(), p.y());
  double a = u0.x() / u0.z(), b = u0.y() / u0.z();
  const double tol = 1e-15;  // on the chart coordinates (dimensionless)
  Eigen::Vector3d u, du_da, du_db, x;
  Eigen::Matrix3d jac;
  Eigen::Matrix<double, 3, 2> j_ab;
  for (int iter = 0; iter < 30; ++iter) {
    gnomonic(a, b, u, du_da, du_db);
    surface_.position_and_jacobian(u, workspace_, x, jac);
    j_ab.col(0) = jac * du_da;
    j_ab.col(1) = jac * du_db;
    const Eigen::Matrix2d normal_matrix = j_ab.transpose() * j_ab;
    const Eigen::Vector2d step = normal_matrix.inverse() * (-j_ab.transpose() * (x - p));
    if (!step.allFinite()) {
      throw std::runtime_error("LayerSurface::project: singular chart Jacobian");
    }
    a += step(0);
    b += step(1);
    if (step.norm() <= tol * (1.0 + std::hypot(a, b))) break;
  }
  gnomonic(a, b, u, du_da, du_db);
  SurfacePoint result;
  surface_.position_and_jacobian(u, workspace_, result.position, jac);
  if (!normal_from_jacobian(u, jac, result.normal)) {
    throw std::runtime_error("LayerSurface::project: singular map at the projected point");
  }
  return result;
}

Eigen::Vector3d LayerSurface::position(const Eigen::Vector3d& u) const {
  return surface_.position(u, workspace_);
}

SurfacePoint LayerSurface::evaluate(const Eigen::Vector3d& u) const {
  return surface_.evaluate(u, workspace_);
}

Eigen::Vector3d LayerSurface::top_face_parameter(double x_m, double y_m) const {
  const Eigen::Vector3d u0 = profile_.top_face_direction(x_m, y_m);
  double a = u0.x() / u0.z(), b = u0.y() / u0.z();
  const double tol = 1e-13 * std::max(profile_.radius_m, profile_.thickness_m());
  Eigen::Vector3d u, du_da, du_db, x;
  Eigen::Matrix3d jac;
  for (int iter = 0; iter < 20; ++iter) {
    gnomonic(a, b, u, du_da, du_db);
    surface_.position_and_jacobian(u, workspace_, x, jac);
    const Eigen::Vector2d residual(x.x() - x_m, x.y() - y_m);
    if (residual.norm() <= tol) return u;
    Eigen::Matrix2d m;
    m.col(0) = (jac * du_da).head<2>();
    m.col(1) = (jac * du_db).head<2>();
    const Eigen::Vector2d step = m.inverse() * (-residual);
    if (!step.allFinite()) break;
    a += step(0);
    b += step(1);
  }
  throw std::runtime_error("LayerSurface::top_face_parameter: Newton did not converge at (" +
                           std::to_string(x_m) + ", " + std::to_string(y_m) + ") m");
}

void LayerSurface::tessellate(int n_theta, int n_phi, Eigen::MatrixX3d& vertices,
                              Eigen::MatrixX3i& triangles) const {
  if (n_theta < 2 || n_phi < 3) throw std::invalid_argument("LayerSurface::tessellate: need n_theta >= 2, n_phi >= 3");
  const int rings = n_theta - 1;
  vertices.resize(2 + rings * n_phi, 3);
  vertices.row(0) = position(Eigen::Vector3d::UnitZ()).transpose();
  for (int i = 0; i < rings; ++i) {
    const double theta = kPi * (i + 1) / n_theta;
    for (int j = 0; j < n_phi; ++j)
      vertices.row(1 + i * n_phi + j) = position(unit_vector_from_angles(theta, 2.0 * kPi * j / n_phi)).transpose();
  }
  const int south = 1 + rings * n_phi;
  vertices.row(south) = position(-Eigen::Vector3d::UnitZ()).transpose();

  triangles.resize(2 * n_phi * rings, 3);
  int t = 0;
  auto vid = [&](int ring, int j) { return 1 + ring * n_phi + (j % n_phi); };
  for (int j = 0; j < n_phi; ++j) triangles.row(t++) << 0, vid(0, j), vid(0, j + 1);
  for (int i = 0; i + 1 < rings; ++i)
    for (int j = 0; j < n_phi; ++j) {
      // theta grows downward, phi counter-clockwise: (a, b = a + dtheta, c = a + dphi) faces outward.
      triangles.row(t++) << vid(i, j), vid(i + 1, j), vid(i, j + 1);
      triangles.row(t++) << vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1);
    }
  for (int j = 0; j < n_phi; ++j) triangles.row(t++) << vid(rings - 1, j), south, vid(rings - 1, j + 1);
}

std::vector<LayerFitErrorRow> layer_fit_error_sweep(double top_z_m, double bottom_z_m, double radius_m,
                                                    const std::vector<int>& degrees,
                                                    const LayerFitOptions& options) {
  std::vector<LayerFitErrorRow> rows;
  rows.reserve(degrees.size());
  for (int degree : degrees) {
    const LayerSurface layer = LayerSurface::fit(top_z_m, bottom_z_m, radius_m, degree, options);
    LayerFitErrorRow row;
    row.degree = degree;
    row.top_face_max_error_m = layer.top_face_max_error_m();
    row.top_face_rms_error_m = layer.top_face_rms_error_m();
    row.whole_surface_rms_error_m = layer.whole_surface_rms_error_m();
    row.condition_number = layer.fit_report().condition_number;
    rows.push_back(row);
  }
  return rows;
}

}  // namespace puncture
