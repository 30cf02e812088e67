// Tests of the real SH basis against std::sph_legendre, closed forms,
// quadrature orthonormality and finite differences on the sphere.
#include <cmath>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "puncture/sh/real_sh.hpp"
#include "puncture/sh/sh_fit.hpp"

namespace puncture {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Independent reference: Y_lm from std::sph_legendre (which includes the
// Condon-Shortley phase (-1)^m and the orthonormal factor).
double reference_real_sh(int l, int m, double theta, double phi) {
  const int am = std::abs(m);
  const double legendre = std::sph_legendre(l, am, theta);  // Y_l^|m|(theta, 0)
  const double cs = (am % 2 == 0) ? 1.0 : -1.0;           // undo the Condon-Shortley phase
  if (m == 0) return legendre;
  if (m > 0) return std::sqrt(2.0) * cs * legendre * std::cos(am * phi);
  return std::sqrt(2.0) * cs * legendre * std::sin(am * phi);
}

TEST(RealSH, IndexAndCount) {
  EXPECT_EQ(sh_index(0, 0), 0);
  EXPECT_EQ(sh_index(1, -1), 1);
  EXPECT_EQ(sh_index(1, 1), 3);
  EXPECT_EQ(sh_index(4, 4), sh_count(4) - 1);
  EXPECT_EQ(RealSHBasis(16).count(), 289);
  EXPECT_THROW(RealSHBasis(-1), std::invalid_argument);
}

TEST(RealSH, LowDegreeClosedForms) {
  const double theta = 0.7, phi = 2.1;
  const Eigen::Vector3d u = unit_vector_from_angles(theta, phi);
  const double c1 = std::sqrt(3.0 / (4.0 * kPi));
  EXPECT_NEAR(real_sh(0, 0, theta, phi), 0.5 / std::sqrt(kPi), 1e-15);
  EXPECT_NEAR(real_sh(1, -1, theta, phi), c1 * u.y(), 1e-15);
  EXPECT_NEAR(real_sh(1, 0, theta, phi), c1 * u.z(), 1e-15);
  EXPECT_NEAR(real_sh(1, 1, theta, phi), c1 * u.x(), 1e-15);
  // Y_22 = (1/4) sqrt(15/pi) (x^2 - y^2), Y_2-2 = (1/2) sqrt(15/pi) x y, Y_20 = (1/4) sqrt(5/pi)(3z^2-1)
  EXPECT_NEAR(real_sh(2, 2, theta, phi), 0.25 * std::sqrt(15.0 / kPi) * (u.x() * u.x() - u.y() * u.y()), 1e-15);
  EXPECT_NEAR(real_sh(2, -2, theta, phi), 0.5 * std::sqrt(15.0 / kPi) * u.x() * u.y(), 1e-15);
  EXPECT_NEAR(real_sh(2, 0, theta, phi), 0.25 * std::sqrt(5.0 / kPi) * (3 * u.z() * u.z() - 1), 1e-15);
}

TEST(RealSH, NearPoleClosedForms) {
  // Y_11 = sqrt(3/4pi) sin(theta) cos(phi), Y_22 = (1/4) sqrt(15/pi) sin^2(theta) cos(2 phi)
  for (double theta : {1e-12, 1e-9, 1e-7}) {
    const double phi = 0.8;
    EXPECT_NEAR(real_sh(1, 1, theta, phi) / (std::sqrt(3.0 / (4.0 * kPi)) * std::sin(theta) * std::cos(phi)), 1.0, 1e-14);
    EXPECT_NEAR(real_sh(2, 2, theta, phi) /
                    (0.25 * std::sqrt(15.0 / kPi) * std::pow(std::sin(theta), 2) * std::cos(2 * phi)),
                1.0, 1e-14);
    const double south = kPi - theta;  // near the south pole
    EXPECT_NEAR(real_sh(3, -1, south, phi) /
                    (0.25 * std::sqrt(21.0 / (2.0 * kPi)) * std::sin(south) * (5 * std::pow(std::cos(south), 2) - 1) * std::sin(phi)),
                1.0, 1e-13);
  }
}

TEST(RealSH, MatchesStdSphLegendreUpToDegree20) {
  const int L = 20;
  const RealSHBasis basis(L);
  std::vector<double> v(basis.count());
  // Not closer to the poles than 1e-3: std::sph_legendre forms sqrt(1 - cos^2 theta)
  // and loses digits there (relative error 4e-4 at theta = 1e-7); the poles
  // themselves are exact in both. Near-pole values are checked in closed form below.
  const double thetas[] = {0.0, 1e-3, 0.3, 1.0, kPi / 2, 2.2, kPi - 1e-3, kPi};
  const double phis[] = {0.0, 0.9, 3.5, 5.9};
  for (double theta : thetas)
    for (double phi : phis) {
      basis.evaluate(unit_vector_from_angles(theta, phi), v.data());
      for (int l = 0; l <= L; ++l)
        for (int m = -l; m <= l; ++m)
          ASSERT_NEAR(v[sh_index(l, m)], reference_real_sh(l, m, theta, phi), 1e-12)
              << "l=" << l << " m=" << m << " theta=" << theta << " phi=" << phi;
    }
}

TEST(RealSH, MatchesStdSphLegendreAtDegree64) {
  const int L = 64;
  const RealSHBasis basis(L);
  std::vector<double> v(basis.count());
  for (double theta : {0.05, 0.8, 1.9, 3.0})
    for (double phi : {0.4, 4.0}) {
      basis.evaluate(unit_vector_from_angles(theta, phi), v.data());
      for (int l : {50, 63, 64})
        for (int m = -l; m <= l; ++m)
          ASSERT_NEAR(v[sh_index(l, m)], reference_real_sh(l, m, theta, phi), 1e-10)
              << "l=" << l << " m=" << m << " theta=" << theta;
    }
}

// Sectoral term in closed form with long double log-gamma:
// Y_ll = sqrt(2) sqrt((2l+1)/(4 pi) / (2l)!) (2l-1)!! sin^l(theta) cos(l phi).
TEST(RealSH, SectoralDegree64AgainstLongDoubleClosedForm) {
  const int l = 64;
  const RealSHBasis basis(l);
  std::vector<double> v(basis.count());
  for (double theta : {0.3, 1.2, kPi / 2}) {
    const double phi = 0.37;
    basis.evaluate(unit_vector_from_angles(theta, phi), v.data());
    const long double L = l;
    // (2l-1)!! = (2l)! / (2^l l!)
    const long double log_norm = 0.5L * (std::log((2 * L + 1) / (4 * 3.141592653589793238L)) - std::lgamma(2 * L + 1)) +
                                 std::lgamma(2 * L + 1) - L * std::log(2.0L) - std::lgamma(L + 1) +
                                 L * std::log(std::sin((long double)theta));
    const long double expected = std::sqrt(2.0L) * std::exp(log_norm) * std::cos(L * phi);
    EXPECT_NEAR(v[sh_index(l, l)], double(expected), 1e-12 * std::max(1.0, std::abs(double(expected))));
  }
}

// Gram matrix by Gauss-Legendre (n_theta = L+1) x uniform phi (n_phi = 2L+2),
// exact for products of two terms of degree <= L.
Eigen::MatrixXd gram_by_quadrature(int L, const std::vector<int>& terms) {
  const RealSHBasis basis(L);
  const SHGrid grid = make_sh_grid(L + 1, 2 * L + 2);
  std::vector<double> v(basis.count());
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(terms.size(), terms.size());
  Eigen::VectorXd sel(terms.size());
  for (int i = 0; i < grid.n_theta(); ++i)
    for (int j = 0; j < grid.n_phi(); ++j) {
      basis.evaluate(grid.direction(i, j), v.data());
      for (std::size_t a = 0; a < terms.size(); ++a) sel(a) = v[terms[a]];
      gram += grid.weights(i) * (2.0 * kPi / grid.n_phi()) * sel * sel.transpose();
    }
  return gram;
}

TEST(RealSH, OrthonormalUpToDegree20) {
  const int L = 20;
  std::vector<int> all(sh_count(L));
  for (int k = 0; k < sh_count(L); ++k) all[k] = k;
  const Eigen::MatrixXd gram = gram_by_quadrature(L, all);
  EXPECT_LT((gram - Eigen::MatrixXd::Identity(gram.rows(), gram.cols())).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(RealSH, OrthonormalSpotChecksAtDegree64) {
  const int L = 64;
  std::vector<int> terms;
  for (int l : {0, 1, 31, 62, 63, 64})
    for (int m : {-l, -l / 2, -1, 0, 1, 2, l / 3, l - 1, l})
      if (std::abs(m) <= l) terms.push_back(sh_index(l, m));
  const Eigen::MatrixXd gram = gram_by_quadrature(L, terms);
  // Duplicated (l, m) entries (e.g. m = l / 3 == 0) give off-diagonal ones; compare with the exact Gram.
  for (std::size_t a = 0; a < terms.size(); ++a)
    for (std::size_t b = 0; b < terms.size(); ++b)
      ASSERT_NEAR(gram(a, b), terms[a] == terms[b] ? 1.0 : 0.0, 1e-11) << terms[a] << " " << terms[b];
}

// Central difference of f along tangent t on the sphere: f(normalize(u +- h t)).
TEST(RealSH, TangentialGradientMatchesFiniteDifferencesIncludingPoles) {
  const int L = 10;
  const RealSHBasis basis(L);
  const int n = basis.count();
  std::vector<double> v(n), g(3 * n), vp(n), vm(n), gp(3 * n);
  std::vector<Eigen::Vector3d> points = {
      Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ(),
      unit_vector_from_angles(1e-9, 0.3), unit_vector_from_angles(1e-4, 2.0),
      unit_vector_from_angles(kPi - 1e-5, 4.0), unit_vector_from_angles(1.1, 0.7),
      unit_vector_from_angles(kPi / 2, 5.5)};
  const double h = 1e-5;
  for (const Eigen::Vector3d& u : points) {
    basis.evaluate_with_gradient(u, v.data(), g.data());
    Eigen::Vector3d a = std::abs(u.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d t1 = (a - u * u.dot(a)).normalized();
    const Eigen::Vector3d t2 = u.cross(t1);
    for (const Eigen::Vector3d& t : {t1, t2, Eigen::Vector3d((t1 + 0.3 * t2).normalized())}) {
      basis.evaluate((u + h * t).normalized(), vp.data());
      basis.evaluate((u - h * t).normalized(), vm.data());
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector3d grad(g[3 * k], g[3 * k + 1], g[3 * k + 2]);
        const double fd = (vp[k] - vm[k]) / (2 * h);
        ASSERT_NEAR(grad.dot(t), fd, 2e-7 * (1.0 + std::abs(fd))) << "term " << k << " at " << u.transpose();
        ASSERT_NEAR(grad.dot(u), 0.0, 1e-12);  // tangential
      }
    }
    // Values from evaluate_with_gradient equal those of evaluate.
    basis.evaluate(u, vp.data());
    for (int k = 0; k < n; ++k) ASSERT_EQ(v[k], vp[k]);
  }
  // Regular at the pole: the gradient there is the limit of the gradient nearby.
  basis.evaluate_with_gradient(Eigen::Vector3d::UnitZ(), v.data(), g.data());
  basis.evaluate_with_gradient(unit_vector_from_angles(1e-8, 1.3), vp.data(), gp.data());
  for (int k = 0; k < 3 * n; ++k) EXPECT_NEAR(g[k], gp[k], 1e-6);
}

TEST(RealSH, OrderLimitedEvaluationWritesOnlyLowOrders) {
  const RealSHBasis basis(12);
  const int n = basis.count();
  std::vector<double> full(n), grad_full(3 * n), part(n, 7.0), grad_part(3 * n, 7.0);
  const Eigen::Vector3d u = unit_vector_from_angles(0.6, 2.2);
  basis.evaluate_with_gradient(u, full.data(), grad_full.data());
  basis.evaluate_with_gradient(u, part.data(), grad_part.data(), 1);
  for (int l = 0; l <= 12; ++l)
    for (int m = -l; m <= l; ++m) {
      const int k = sh_index(l, m);
      if (std::abs(m) <= 1) {
        EXPECT_EQ(part[k], full[k]);
        for (int c = 0; c < 3; ++c) EXPECT_EQ(grad_part[3 * k + c], grad_full[3 * k + c]);
      } else {
        EXPECT_EQ(part[k], 7.0);  // untouched
      }
    }
}

TEST(RealSH, RejectsZeroDirection) {
  const RealSHBasis basis(2);
  std::vector<double> v(basis.count());
  EXPECT_THROW(basis.evaluate(Eigen::Vector3d::Zero(), v.data()), std::invalid_argument);
}

}  // namespace
}  // namespace puncture
