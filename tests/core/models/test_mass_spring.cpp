// Volumetric mass-spring law against closed forms: Van Gelder's rule on one
// tetrahedron, and the effective elastic constants of the Kuhn lattice
// (cubes of side h, six tetrahedra each) derived by hand:
//   every Kuhn tetrahedron has 3 axis edges (one per direction), 2 face
//   diagonals and 1 body diagonal; with k_e l_e^2 = E sum_{T ∋ e} V_T the
//   small-strain energy density is (1/2) C_ijkl e_ij e_kl with
//   C_ijkl = (E / V) sum_T V_T sum_{e in T} n_i n_j n_k n_l.
// Per cube: 6 tetrahedra of volume h^3/6; over them, 6 x-axis edges (n_x^4 = 1),
// 8 face diagonals in a plane containing x (1/4 each; 4 in the xy plane, with
// n_x^2 n_y^2 = 1/4) and 6 body diagonals (n_x^4 = n_x^2 n_y^2 = 1/9):
//   C_1111 = E/6 (6 + 8/4 + 6/9) = 13 E / 9,   C_1122 = E/6 (4/4 + 6/9) = 5 E / 18.
#include <gtest/gtest.h>

#include "comparison_test_meshes.hpp"
#include "puncture/comparison/internal_forces.hpp"

namespace puncture::comparison {
namespace {

TEST(MassSpring, VanGelderStiffnessOnOneTetrahedron) {
  TetMesh mesh;
  mesh.points_m.resize(3, 4);
  mesh.points_m << 0, 2e-3, 0, 0, 0, 0, 1e-3, 0, 0, 0, 0, 3e-3;
  mesh.tets = {Eigen::Vector4i(0, 1, 2, 3)};
  mesh.layer = {0};
  mesh.needle_column = {0};
  const double E = 12e3;
  MassSpringLaw law(mesh, {{E, 0.45, 1000.0}}, {2.0});
  const double V = 2e-3 * 1e-3 * 3e-3 / 6.0;
  ASSERT_EQ(law.edges().size(), 6u);
  for (std::size_t e = 0; e < 6; ++e) {
    const double l = law.rest_length_m()[e];
    EXPECT_NEAR(law.stiffness_N_per_m()[e], 2.0 * E * V / (l * l), 1e-12 * law.stiffness_N_per_m()[e]);
  }
}

double energy_under_strain(const MassSpringLaw& law, const TetMesh& mesh, const Eigen::Matrix3d& strain) {
  Eigen::VectorXd x(3 * mesh.node_count());
  for (int a = 0; a < mesh.node_count(); ++a) x.segment<3>(3 * a) = (Eigen::Matrix3d::Identity() + strain) * mesh.points_m.col(a);
  return law.energy_J(x);
}

TEST(MassSpring, KuhnLatticeMatchesClosedFormElasticConstants) {
  const double h = 1e-3, E = 30e3;
  const int n = 4;
  const TetMesh mesh = testing::kuhn_box(n, h);
  const MassSpringLaw law(mesh, {{E, 0.45, 1000.0}});
  const double volume = std::pow(n * h, 3);
  const double eps = 1e-7;  // small strain: the quadratic energy to 1e-7 relative
  // Uniaxial strain e_xx: W = V C_1111 eps^2 / 2.
  Eigen::Matrix3d uniaxial = Eigen::Matrix3d::Zero();
  uniaxial(0, 0) = eps;
  EXPECT_NEAR(energy_under_strain(law, mesh, uniaxial), 0.5 * volume * (13.0 / 9.0) * E * eps * eps,
              1e-5 * 0.5 * volume * E * eps * eps);
  // Biaxial e_xx = e_yy = eps: W = V (C_1111 + C_1122) eps^2 (C_2222 = C_1111 by the cube symmetry).
  Eigen::Matrix3d biaxial = Eigen::Matrix3d::Zero();
  biaxial(0, 0) = biaxial(1, 1) = eps;
  EXPECT_NEAR(energy_under_strain(law, mesh, biaxial), volume * (13.0 / 9.0 + 5.0 / 18.0) * E * eps * eps,
              1e-5 * volume * E * eps * eps);
}

class MassSpringKinds : public ::testing::TestWithParam<SpringKind> {};

TEST_P(MassSpringKinds, ForcesAreEnergyGradientAndTangentIsTheirDerivative) {
  const TetMesh mesh = testing::kuhn_box(2, 1e-3);
  const MassSpringLaw law(mesh, {{10e3, 0.45, 1000.0}}, {}, GetParam());
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(mesh.points_m.data(), mesh.points_m.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] += 1e-4 * std::sin(1.7 * i);  // stretched springs only matter
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  law.add_forces(x, x, nullptr, f, nullptr);
  const double hstep = 1e-9;
  for (Eigen::Index i = 0; i < x.size(); i += 5) {
    Eigen::VectorXd xp = x, xm = x;
    xp[i] += hstep, xm[i] -= hstep;
    EXPECT_NEAR(f[i], -(law.energy_J(xp) - law.energy_J(xm)) / (2 * hstep), 1e-6 * f.cwiseAbs().maxCoeff());
  }
  // At rest the tangent is exact (no compressed springs): compare with a difference of forces.
  const Eigen::VectorXd X = Eigen::Map<const Eigen::VectorXd>(mesh.points_m.data(), mesh.points_m.size());
  NodeBlockMatrix K(mesh.node_count(), tet_node_pairs(mesh));
  law.add_tangent(X, 0.0, K);
  Eigen::VectorXd u(X.size());
  for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = std::cos(0.3 * i);
  Eigen::VectorXd fp = Eigen::VectorXd::Zero(X.size()), fm = fp;
  law.add_forces(X + 1e-9 * u, X, nullptr, fp, nullptr);
  law.add_forces(X - 1e-9 * u, X, nullptr, fm, nullptr);
  const Eigen::VectorXd Ku = K.matrix() * u;
  EXPECT_LT((Ku + (fp - fm) / 2e-9).norm(), 1e-5 * Ku.norm());
}

INSTANTIATE_TEST_SUITE_P(BothSpringKinds, MassSpringKinds,
                         ::testing::Values(SpringKind::Linear, SpringKind::Nonlinear),
                         [](const ::testing::TestParamInfo<SpringKind>& info) { return std::string(to_string(info.param)); });

TEST(MassSpring, LinearSpringUnderARigidRotationMatchesItsClosedForm) {
  // One spring from (0,0,0) to (l0,0,0), its end turned by theta about z: the
  // exact spring keeps its length (no force); the linearised one measures
  // n0 . d - l0 = l0 (cos theta - 1) and pulls along n0 = x.
  TetMesh mesh;
  mesh.points_m.resize(3, 4);
  const double l0 = 2e-3;
  mesh.points_m << 0, l0, 0, 0, 0, 0, 1e-3, 0, 0, 0, 0, 1e-3;
  mesh.tets = {Eigen::Vector4i(0, 1, 2, 3)};
  mesh.layer = {0};
  mesh.needle_column = {0};
  const MassSpringLaw linear(mesh, {{12e3, 0.45, 1000.0}}, {}, SpringKind::Linear);
  const MassSpringLaw exact(mesh, {{12e3, 0.45, 1000.0}}, {}, SpringKind::Nonlinear);
  const double theta = 0.3;
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(mesh.points_m.data(), mesh.points_m.size());
  x.segment<3>(3) = Eigen::Vector3d(l0 * std::cos(theta), l0 * std::sin(theta), 0.0);
  // Node 0's force is the 0-1 spring's alone (its springs to nodes 2 and 3 are at rest).
  const double k = linear.stiffness_N_per_m()[0];  // edges sorted: (0,1) first
  ASSERT_EQ(linear.edges()[0], std::make_pair(0, 1));
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  linear.add_forces(x, x, nullptr, f, nullptr);
  EXPECT_NEAR(f[0], k * l0 * (std::cos(theta) - 1.0), 1e-12 * k * l0);
  EXPECT_NEAR(f[1], 0.0, 1e-12 * k * l0);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  exact.add_forces(x, x, nullptr, g, nullptr);
  EXPECT_NEAR(g.segment<3>(0).norm(), 0.0, 1e-12 * k * l0);
}

TEST(MassSpring, LinearSpringsAreExactSpringsToFirstOrder) {
  // Seed 001's constant K is the exact springs' tangent at rest: the two
  // forces differ at second order in the displacement.
  const TetMesh mesh = testing::kuhn_box(2, 1e-3);
  const MassSpringLaw linear(mesh, {{10e3, 0.45, 1000.0}}, {}, SpringKind::Linear);
  const MassSpringLaw exact(mesh, {{10e3, 0.45, 1000.0}}, {}, SpringKind::Nonlinear);
  const Eigen::VectorXd X = Eigen::Map<const Eigen::VectorXd>(mesh.points_m.data(), mesh.points_m.size());
  Eigen::VectorXd u(X.size());
  for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = std::sin(0.7 * i + 0.2);
  auto relative_difference = [&](double eps) {
    Eigen::VectorXd fl = Eigen::VectorXd::Zero(X.size()), fe = fl;
    linear.add_forces(X + eps * u, X, nullptr, fl, nullptr);
    exact.add_forces(X + eps * u, X, nullptr, fe, nullptr);
    return (fl - fe).norm() / fl.norm();
  };
  const double coarse = relative_difference(1e-5), fine = relative_difference(1e-6);
  EXPECT_GT(coarse, 0.0);
  EXPECT_NEAR(fine / coarse, 0.1, 0.02);  // first order in eps
  // And linear: forces add.
  Eigen::VectorXd v(X.size());
  for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = std::cos(1.3 * i);
  Eigen::VectorXd fu = Eigen::VectorXd::Zero(X.size()), fv = fu, fuv = fu;
  linear.add_forces(X + 2e-4 * u, X, nullptr, fu, nullptr);
  linear.add_forces(X + 3e-4 * v, X, nullptr, fv, nullptr);
  linear.add_forces(X + 2e-4 * u + 3e-4 * v, X, nullptr, fuv, nullptr);
  EXPECT_LT((fuv - fu - fv).norm(), 1e-9 * fuv.norm());
}

TEST(MassSpring, SpringKindsByName) {
  EXPECT_EQ(parse_spring_kind("linear"), SpringKind::Linear);
  EXPECT_EQ(parse_spring_kind("nonlinear"), SpringKind::Nonlinear);
  EXPECT_THROW(parse_spring_kind("hooke"), std::invalid_argument);
}

TEST(MassSpring, RemovedTetrahedraTakeTheirStiffnessWithThem) {
  const TetMesh mesh = testing::kuhn_box(1, 1e-3);  // 6 tetrahedra sharing the body diagonal
  MassSpringLaw law(mesh, {{10e3, 0.45, 1000.0}});
  std::vector<std::uint8_t> removed(mesh.tets.size(), 1);
  law.set_removed(removed);
  for (double k : law.stiffness_N_per_m()) EXPECT_EQ(k, 0.0);
  EXPECT_THROW(MassSpringLaw(mesh, {{10e3, 0.45, 1000.0}}, {-1.0}), std::invalid_argument);
}

}  // namespace
}  // namespace puncture::comparison
