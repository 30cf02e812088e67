// Tests of least-squares SH fitting and the radial / parametric SH surfaces.
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "puncture/sh/sh_fit.hpp"
#include "puncture/sh/sh_surface.hpp"

namespace puncture {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::MatrixX3d random_directions(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::MatrixX3d d(n, 3);
  for (int i = 0; i < n; ++i) d.row(i) = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized().transpose();
  return d;
}

TEST(GaussLegendre, KnownNodesAndExactness) {
  Eigen::VectorXd x, w;
  gauss_legendre(2, x, w);
  EXPECT_NEAR(x(0), -1.0 / std::sqrt(3.0), 1e-15);
  EXPECT_NEAR(x(1), 1.0 / std::sqrt(3.0), 1e-15);
  EXPECT_NEAR(w(0), 1.0, 1e-15);
  gauss_legendre(3, x, w);
  EXPECT_NEAR(x(2), std::sqrt(0.6), 1e-15);
  EXPECT_NEAR(w(1), 8.0 / 9.0, 1e-15);
  // n points integrate x^(2n-2) exactly: 2 / (2n - 1).
  for (int n : {1, 5, 20, 65}) {
    gauss_legendre(n, x, w);
    double s = 0.0;
    for (int i = 0; i < n; ++i) s += w(i) * std::pow(x(i), 2 * n - 2);
    EXPECT_NEAR(s, 2.0 / (2 * n - 1), 1e-14) << n;
    EXPECT_NEAR(w.sum(), 2.0, 1e-14);
  }
}

TEST(GaussLegendre, TheEightPointTableAgreesWithTheComputedRuleToTheLastDigits) {
  Eigen::VectorXd x, w, xt, wt;
  gauss_legendre(8, x, w);
  gauss_legendre(8, xt, wt, GaussLegendreValues::Table16Digits);
  ASSERT_EQ(xt.size(), 8);
  for (int i = 0; i < 8; ++i) {
    EXPECT_NEAR(xt(i), x(i), 2e-16) << i;
    EXPECT_NEAR(wt(i), w(i), 2e-16) << i;
  }
  EXPECT_THROW(gauss_legendre(7, xt, wt, GaussLegendreValues::Table16Digits), std::invalid_argument);
}

TEST(SHFit, SphereGivesOnlyTheConstantTerm) {
  const double R = 0.037;
  const Eigen::MatrixX3d dirs = random_directions(200, 1);
  SHFitReport report;
  const RadialSHSurface sphere =
      RadialSHSurface::fit(6, dirs, Eigen::VectorXd::Constant(dirs.rows(), R), &report);
  EXPECT_NEAR(sphere.coefficients()(0), 2.0 * std::sqrt(kPi) * R, 1e-14);
  EXPECT_LT(sphere.coefficients().tail(sphere.coefficients().size() - 1).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_EQ(report.samples, 200);
  EXPECT_EQ(report.unknowns, 49);
  EXPECT_LT(report.max_residual, 1e-15);
  EXPECT_GE(report.condition_number, 1.0);
  // Position and normal of the sphere.
  const Eigen::Vector3d u = Eigen::Vector3d(0.3, -0.2, 0.9).normalized();
  const SurfacePoint p = sphere.evaluate(u);
  EXPECT_NEAR((p.position - R * u).norm(), 0.0, 1e-15);
  EXPECT_NEAR((p.normal - u).norm(), 0.0, 1e-12);
}

TEST(SHFit, RecoversRandomBandLimitedFunction) {
  const int L = 8;
  const RealSHBasis basis(L);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  Eigen::VectorXd truth(basis.count());
  for (int k = 0; k < truth.size(); ++k) truth(k) = uni(rng);
  // Values computed from the closed-form-checked basis at random directions.
  const Eigen::MatrixX3d dirs = random_directions(3 * basis.count(), 3);
  Eigen::VectorXd f(dirs.rows()), y(basis.count());
  for (int i = 0; i < dirs.rows(); ++i) {
    basis.evaluate(dirs.row(i).transpose(), y.data());
    f(i) = truth.dot(y);
  }
  Eigen::MatrixXd c;
  const SHFitReport report = fit_sh_least_squares(basis, dirs, f, c);
  EXPECT_LT((c.col(0) - truth).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT(report.rms_residual, 1e-12);

  // The same on a Gauss-Legendre x uniform grid with the fast per-order solver.
  const SHGrid grid = make_sh_grid(L + 3, 2 * L + 1);
  Eigen::VectorXd fg(grid.size());
  for (int i = 0; i < grid.n_theta(); ++i)
    for (int j = 0; j < grid.n_phi(); ++j) {
      basis.evaluate(grid.direction(i, j), y.data());
      fg(i * grid.n_phi() + j) = truth.dot(y);
    }
  Eigen::MatrixXd cg;
  fit_sh_on_grid(basis, grid, fg, cg);
  EXPECT_LT((cg.col(0) - truth).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(SHFit, GridSolverEqualsDenseSolverForNonBandLimitedData) {
  // The per-order split must give the same minimiser (and the same condition
  // number and residuals) as the dense SVD on the same samples.
  const int L = 6;
  const RealSHBasis basis(L);
  const SHGrid grid = make_sh_grid(L + 4, 2 * L + 3);
  const Eigen::MatrixX3d dirs = grid.directions();
  Eigen::MatrixXd f(grid.size(), 2);
  for (int i = 0; i < grid.size(); ++i) {
    const Eigen::Vector3d u = dirs.row(i).transpose();
    f(i, 0) = std::exp(u.x() + 0.5 * u.y() * u.z());
    f(i, 1) = std::abs(u.z() - 0.2) + u.x() * u.x() * u.y();
  }
  Eigen::MatrixXd c_dense, c_grid;
  const SHFitReport dense = fit_sh_least_squares(basis, dirs, f, c_dense);
  const SHFitReport fast = fit_sh_on_grid(basis, grid, f, c_grid);
  EXPECT_LT((c_dense - c_grid).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(dense.condition_number, fast.condition_number, 1e-9 * dense.condition_number);
  EXPECT_NEAR(dense.rms_residual, fast.rms_residual, 1e-12);
  EXPECT_NEAR(dense.max_residual, fast.max_residual, 1e-12);
  EXPECT_GT(dense.rms_residual, 1e-4);  // the data are not band-limited
}

TEST(SHFit, RejectsUnderDeterminedAndRankDeficientProblems) {
  const RealSHBasis basis(4);  // 25 unknowns
  const Eigen::MatrixX3d few = random_directions(24, 5);
  Eigen::MatrixXd c;
  EXPECT_THROW(fit_sh_least_squares(basis, few, Eigen::VectorXd::Ones(24), c), std::invalid_argument);
  // 100 samples all on the equator: Y_10 = c z vanishes on every one of them.
  Eigen::MatrixX3d equator(100, 3);
  for (int i = 0; i < 100; ++i) equator.row(i) << std::cos(0.1 * i), std::sin(0.1 * i), 0.0;
  try {
    fit_sh_least_squares(basis, equator, Eigen::VectorXd::Ones(100), c);
    FAIL() << "rank-deficient fit did not throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rank deficient"), std::string::npos) << e.what();
  }
  const SHGrid coarse_phi = make_sh_grid(10, 8);
  EXPECT_THROW(fit_sh_on_grid(basis, coarse_phi, Eigen::VectorXd::Ones(coarse_phi.size()), c), std::invalid_argument);
  const SHGrid coarse_theta = make_sh_grid(4, 12);
  EXPECT_THROW(fit_sh_on_grid(basis, coarse_theta, Eigen::VectorXd::Ones(coarse_theta.size()), c), std::invalid_argument);
  EXPECT_THROW(fit_sh_least_squares(basis, random_directions(30, 2), Eigen::VectorXd::Constant(30, NAN), c),
               std::invalid_argument);
}

// Ellipsoid x = a u_x, y = b u_y, z = c u_z: position, tangent derivatives
// and normal (x/a^2, y/b^2, z/c^2)/|.| in closed form.
TEST(ParametricSHSurface, EllipsoidPositionsDerivativesAndNormals) {
  const double a = 0.03, b = 0.02, c = 0.008;
  const Eigen::MatrixX3d dirs = random_directions(150, 11);
  Eigen::MatrixX3d pos = dirs;
  pos.col(0) *= a;
  pos.col(1) *= b;
  pos.col(2) *= c;
  SHFitReport report;
  const ParametricSHSurface ell = ParametricSHSurface::fit(4, dirs, pos, &report);
  EXPECT_LT(report.max_residual, 1e-15);
  SHWorkspace ws = ell.make_workspace();
  std::vector<Eigen::Vector3d> tests = {Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ(),
                                        unit_vector_from_angles(1e-9, 2.0), unit_vector_from_angles(0.7, 1.1),
                                        unit_vector_from_angles(2.0, 4.4), Eigen::Vector3d::UnitX()};
  for (const Eigen::Vector3d& u : tests) {
    const Eigen::Vector3d x(a * u.x(), b * u.y(), c * u.z());
    const SurfacePoint p = ell.evaluate(u, ws);
    EXPECT_LT((p.position - x).norm(), 1e-15);
    const Eigen::Vector3d n = Eigen::Vector3d(x.x() / (a * a), x.y() / (b * b), x.z() / (c * c)).normalized();
    EXPECT_LT((p.normal - n).norm(), 1e-12) << u.transpose();
    Eigen::Vector3d e1, e2, d1, d2;
    sphere_tangent_frame(u, e1, e2);
    EXPECT_NEAR(e1.cross(e2).dot(u), 1.0, 1e-15);
    ell.tangent_derivatives(u, e1, e2, ws, d1, d2);
    EXPECT_LT((d1 - Eigen::Vector3d(a * e1.x(), b * e1.y(), c * e1.z())).norm(), 1e-15);
    EXPECT_LT((d2 - Eigen::Vector3d(a * e2.x(), b * e2.y(), c * e2.z())).norm(), 1e-15);
  }
}

// A bumpy star-shaped radial surface: normal against the cross product of
// finite-difference tangents of the position.
TEST(RadialSHSurface, NormalMatchesFiniteDifferenceTangents) {
  const int L = 5;
  Eigen::VectorXd coeff = Eigen::VectorXd::Zero(sh_count(L));
  coeff(sh_index(0, 0)) = 2.0 * std::sqrt(kPi) * 0.02;
  coeff(sh_index(2, 0)) = 0.004;
  coeff(sh_index(3, -2)) = 0.002;
  coeff(sh_index(5, 4)) = -0.001;
  const RadialSHSurface surf(L, coeff);
  SHWorkspace ws = surf.make_workspace();
  const double h = 1e-6;
  for (const Eigen::Vector3d& u : {Eigen::Vector3d(Eigen::Vector3d::UnitZ()), unit_vector_from_angles(0.4, 0.3),
                                   unit_vector_from_angles(2.9, 5.0), Eigen::Vector3d(-Eigen::Vector3d::UnitZ())}) {
    Eigen::Vector3d e1, e2;
    sphere_tangent_frame(u, e1, e2);
    const Eigen::Vector3d x1 = (surf.position((u + h * e1).normalized(), ws) - surf.position((u - h * e1).normalized(), ws)) / (2 * h);
    const Eigen::Vector3d x2 = (surf.position((u + h * e2).normalized(), ws) - surf.position((u - h * e2).normalized(), ws)) / (2 * h);
    const Eigen::Vector3d n_fd = x1.cross(x2).normalized();
    const SurfacePoint p = surf.evaluate(u, ws);
    EXPECT_LT((p.normal - n_fd).norm(), 1e-7) << u.transpose();
    EXPECT_GT(p.normal.dot(u), 0.0);  // outward
  }
}

TEST(SHSurfaces, RejectWrongCoefficientCounts) {
  EXPECT_THROW(RadialSHSurface(3, Eigen::VectorXd::Zero(15)), std::invalid_argument);
  EXPECT_THROW(ParametricSHSurface(3, Eigen::MatrixX3d::Zero(17, 3)), std::invalid_argument);
  // A zero map has no normal.
  const ParametricSHSurface flat(2, Eigen::MatrixX3d::Zero(9, 3));
  EXPECT_THROW(flat.evaluate(Eigen::Vector3d::UnitZ()), std::domain_error);
}

}  // namespace
}  // namespace puncture
