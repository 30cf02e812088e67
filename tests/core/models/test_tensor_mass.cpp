// Tensor-mass models against independent references: Cotin's linear
// tensor-mass stiffness against the linear P1 FEM stiffness assembled here in
// Voigt notation (B^T D B V), and the StVK (Picinbono) internal force and
// tangent against finite differences of the StVK energy.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>

#include "comparison_test_meshes.hpp"
#include "puncture/comparison/internal_forces.hpp"
#include "puncture/comparison/tet_elements.hpp"

namespace puncture::comparison {
namespace {

/// Textbook P1 elasticity: B (6 x 12) from the shape gradients, isotropic D.
Eigen::MatrixXd voigt_fem_stiffness(const TetMesh& mesh, double E, double nu) {
  const int n = mesh.node_count();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  Eigen::Matrix<double, 6, 6> D = Eigen::Matrix<double, 6, 6>::Zero();
  D.topLeftCorner<3, 3>().setConstant(lambda);
  for (int i = 0; i < 3; ++i) D(i, i) += 2 * mu, D(3 + i, 3 + i) = mu;
  for (const Eigen::Vector4i& t : mesh.tets) {
    // Gradients from the inverse of [1 x y z] (independent of tet_shape).
    Eigen::Matrix4d C;
    for (int a = 0; a < 4; ++a) C.row(a) << 1.0, mesh.points_m.col(t[a]).transpose();
    const Eigen::Matrix4d Ci = C.inverse();  // column a: coefficients of N_a
    const double V = std::abs(C.determinant()) / 6.0;
    Eigen::Matrix<double, 6, 12> B = Eigen::Matrix<double, 6, 12>::Zero();
    for (int a = 0; a < 4; ++a) {
      const double gx = Ci(1, a), gy = Ci(2, a), gz = Ci(3, a);
      B(0, 3 * a) = gx, B(1, 3 * a + 1) = gy, B(2, 3 * a + 2) = gz;
      B(3, 3 * a + 1) = gz, B(3, 3 * a + 2) = gy;  // gamma_yz
      B(4, 3 * a) = gz, B(4, 3 * a + 2) = gx;      // gamma_xz
      B(5, 3 * a) = gy, B(5, 3 * a + 1) = gx;      // gamma_xy
    }
    const Eigen::Matrix<double, 12, 12> Ke = V * B.transpose() * D * B;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) K.block<3, 3>(3 * t[a], 3 * t[b]) += Ke.block<3, 3>(3 * a, 3 * b);
  }
  return K;
}

TetMesh distorted_box() {
  TetMesh mesh = testing::kuhn_box(2, 1e-3);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.15e-3, 0.15e-3);
  for (int a = 0; a < mesh.node_count(); ++a)
    for (int i = 0; i < 3; ++i) mesh.points_m(i, a) += jitter(rng);
  for (Eigen::Vector4i& t : mesh.tets)
    if (meshing::tet_signed_volume(mesh.points_m.col(t[0]), mesh.points_m.col(t[1]), mesh.points_m.col(t[2]),
                          mesh.points_m.col(t[3])) < 0)
      std::swap(t[2], t[3]);
  return mesh;
}

TEST(LinearTensorMass, StiffnessEqualsLinearP1FemStiffness) {
  const TetMesh mesh = distorted_box();
  const double E = 35e3, nu = 0.45;
  const std::vector<LayerElasticity> layers{{E, nu, 1000.0}};
  LinearTensorMass law(mesh, layers);
  const Eigen::MatrixXd K_fem = voigt_fem_stiffness(mesh, E, nu);

  NodeBlockMatrix K(mesh.node_count(), tet_node_pairs(mesh));
  law.add_tangent(Eigen::Map<const Eigen::VectorXd>(mesh.points_m.data(), mesh.points_m.size()), 0.0, K);
  const Eigen::MatrixXd K_tm = Eigen::MatrixXd(K.matrix());
  EXPECT_LT((K_tm - K_fem).norm(), 1e-10 * K_fem.norm());

  // Forces of the vertex / edge tensors: f = -K u for a random displacement.
  std::mt19937 rng(3);
  std::normal_distribution<double> normal(0.0, 1e-5);
  Eigen::VectorXd u(3 * mesh.node_count());
  for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = normal(rng);
  const Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(mesh.points_m.data(), mesh.points_m.size()) + u;
  Eigen::VectorXd f = Eigen::VectorXd::Zero(u.size());
  law.add_forces(x, Eigen::VectorXd::Zero(u.size()), nullptr, f, nullptr);
  const Eigen::VectorXd expected = -K_fem * u;
  EXPECT_LT((f - expected).norm(), 1e-10 * expected.norm());
  EXPECT_NEAR(law.energy_J(x), 0.5 * u.dot(K_fem * u), 1e-10 * u.dot(K_fem * u));
}

TEST(LinearTensorMass, RigidTranslationIsForceFree) {
  const TetMesh mesh = distorted_box();
  LinearTensorMass law(mesh, {{10e3, 0.3, 1000.0}});
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(mesh.points_m.data(), mesh.points_m.size());
  for (int a = 0; a < mesh.node_count(); ++a) x.segment<3>(3 * a) += Eigen::Vector3d(1e-3, -2e-3, 0.5e-3);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  law.add_forces(x, x, nullptr, f, nullptr);
  EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-12);
}

Matrix34d random_deformed(const Matrix34d& X, unsigned seed, double amplitude) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> d(-amplitude, amplitude);
  Matrix34d x = X;
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) x(i, a) += d(rng);
  return x;
}

TEST(StvkTensorMass, ForceIsMinusEnergyGradientByFiniteDifferences) {
  Matrix34d X;
  X << 0, 1e-3, 0, 0.2e-3, 0, 0.1e-3, 1.2e-3, 0.1e-3, 0, 0, 0.1e-3, 0.9e-3;
  const TetShape shape = tet_shape(X);
  const LameParameters lame = lame_from_young(35e3, 0.45);
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Matrix34d x = random_deformed(X, seed, 0.4e-3);  // large, not small-strain
    const Matrix34d f = stvk_forces(shape, x, lame);
    const double h = 1e-9;
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) {
        Matrix34d xp = x, xm = x;
        xp(i, a) += h, xm(i, a) -= h;
        const double grad = (stvk_energy_J(shape, xp, lame) - stvk_energy_J(shape, xm, lame)) / (2 * h);
        EXPECT_NEAR(f(i, a), -grad, 1e-6 * f.cwiseAbs().maxCoeff()) << "seed " << seed << " node " << a;
      }
  }
}

TEST(StvkTensorMass, TangentIsForceDerivativeByFiniteDifferences) {
  Matrix34d X;
  X << 0, 1e-3, 0, 0.2e-3, 0, 0.1e-3, 1.2e-3, 0.1e-3, 0, 0, 0.1e-3, 0.9e-3;
  const TetShape shape = tet_shape(X);
  const LameParameters lame = lame_from_young(15e3, 0.48);
  const Matrix34d x = random_deformed(X, 11, 0.3e-3);
  const Matrix12d K = stvk_tangent(shape, x, lame);
  EXPECT_LT((K - K.transpose()).norm(), 1e-10 * K.norm());
  const double h = 1e-9;
  for (int b = 0; b < 4; ++b)
    for (int j = 0; j < 3; ++j) {
      Matrix34d xp = x, xm = x;
      xp(j, b) += h, xm(j, b) -= h;
      const Matrix34d df = (stvk_forces(shape, xp, lame) - stvk_forces(shape, xm, lame)) / (2 * h);
      for (int a = 0; a < 4; ++a)
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(K(3 * a + i, 3 * b + j), -df(i, a), 1e-5 * K.cwiseAbs().maxCoeff());
    }
}

TEST(StvkTensorMass, MeshForceIsEnergyGradientAndRotationInvariant) {
  const TetMesh mesh = distorted_box();
  StvkTensorMass law(mesh, {{20e3, 0.4, 1000.0}});
  const Eigen::VectorXd X = Eigen::Map<const Eigen::VectorXd>(mesh.points_m.data(), mesh.points_m.size());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> d(-0.2e-3, 0.2e-3);
  Eigen::VectorXd x = X;
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] += d(rng);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  law.add_forces(x, x, nullptr, f, nullptr);
  const double h = 1e-9;
  for (Eigen::Index i = 0; i < x.size(); i += 7) {
    Eigen::VectorXd xp = x, xm = x;
    xp[i] += h, xm[i] -= h;
    EXPECT_NEAR(f[i], -(law.energy_J(xp) - law.energy_J(xm)) / (2 * h), 1e-6 * f.cwiseAbs().maxCoeff());
  }
  // A rigid rotation of the rest shape stores no energy (the linear model would).
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::VectorXd xr(X.size());
  for (int a = 0; a < mesh.node_count(); ++a) xr.segment<3>(3 * a) = R * X.segment<3>(3 * a);
  EXPECT_LT(law.energy_J(xr), 1e-20);
  LinearTensorMass linear(mesh, {{20e3, 0.4, 1000.0}});
  EXPECT_GT(linear.energy_J(xr), 1e-6);
}

TEST(StvkTensorMass, SmallStrainForcesMatchTheLinearModel) {
  const TetMesh mesh = distorted_box();
  const std::vector<LayerElasticity> layers{{20e3, 0.4, 1000.0}};
  StvkTensorMass nonlinear(mesh, layers);
  LinearTensorMass linear(mesh, layers);
  const Eigen::VectorXd X = Eigen::Map<const Eigen::VectorXd>(mesh.points_m.data(), mesh.points_m.size());
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> d(-1e-9, 1e-9);
  Eigen::VectorXd x = X;
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] += d(rng);
  Eigen::VectorXd f1 = Eigen::VectorXd::Zero(x.size()), f2 = f1;
  nonlinear.add_forces(x, x, nullptr, f1, nullptr);
  linear.add_forces(x, x, nullptr, f2, nullptr);
  EXPECT_LT((f1 - f2).norm(), 1e-5 * f2.norm());
}

TEST(ViscoelasticTensorMass, ConstantStrainRateFollowsTheHereditaryIntegral) {
  // One tetrahedron stretched homogeneously at a small constant rate:
  // E_xx(t) = eps_dot t, so S_e(t) = C eps_dot t and the Prony law
  // dQ/dt = g dS_e/dt - Q / tau gives S(t) = C eps_dot [t + g tau (1 - exp(-t/tau))].
  TetMesh mesh;
  mesh.points_m.resize(3, 4);
  mesh.points_m << 0, 1e-3, 0, 0, 0, 0, 1e-3, 0, 0, 0, 0, 1e-3;
  mesh.tets = {Eigen::Vector4i(0, 1, 2, 3)};
  mesh.layer = {0};
  mesh.needle_column = {0};
  const double g = 0.6, tau = 0.3, rate = 1e-4;  // strain per second: stays small
  ViscoelasticTensorMass law(mesh, {{10e3, 0.3, 1000.0}}, PronySeries{{g}, {tau}});
  const Eigen::VectorXd X = Eigen::Map<const Eigen::VectorXd>(mesh.points_m.data(), mesh.points_m.size());
  auto positions = [&](double t) {
    Eigen::VectorXd x = X;
    for (int a = 0; a < 4; ++a) x[3 * a] *= 1.0 + rate * t;  // F = diag(1 + rate t, 1, 1)
    return x;
  };
  Eigen::VectorXd v = Eigen::VectorXd::Zero(X.size());
  for (int a = 0; a < 4; ++a) v[3 * a] = rate * X[3 * a];
  std::vector<double> q(6, 0.0), k1(6), k2(6), k3(6), k4(6), tmp(6);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(X.size());
  const double dt = 1e-3, T = 1.0;
  auto qdot = [&](double t, const std::vector<double>& state, std::vector<double>& out) {
    f.setZero();
    law.add_forces(positions(t), v, state.data(), f, out.data());
  };
  for (double t = 0.0; t < T - 1e-12; t += dt) {  // RK4
    qdot(t, q, k1);
    for (int i = 0; i < 6; ++i) tmp[i] = q[i] + 0.5 * dt * k1[i];
    qdot(t + 0.5 * dt, tmp, k2);
    for (int i = 0; i < 6; ++i) tmp[i] = q[i] + 0.5 * dt * k2[i];
    qdot(t + 0.5 * dt, tmp, k3);
    for (int i = 0; i < 6; ++i) tmp[i] = q[i] + dt * k3[i];
    qdot(t + dt, tmp, k4);
    for (int i = 0; i < 6; ++i) q[i] += dt / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
  }
  const LameParameters lame = lame_from_young(10e3, 0.3);
  const double C = lame.lambda_Pa + 2 * lame.mu_Pa;  // S_xx per E_xx
  // dE_xx/dt = (1 + rate t) rate, so Q_xx(T) = g C rate int_0^T (1 + rate s) exp(-(T - s)/tau) ds
  //   = g C rate [tau (1 - e) + rate (tau T - tau^2 (1 - e))], e = exp(-T/tau).
  const double e = std::exp(-T / tau);
  const double history = tau * (1 - e) + rate * (tau * T - tau * tau * (1 - e));
  const double expected_q = C * rate * g * history;
  EXPECT_NEAR(q[0], expected_q, 1e-9 * expected_q);
  const double expected_lateral = lame.lambda_Pa * rate * g * history;  // S_yy = lambda tr(E)
  EXPECT_NEAR(q[1], expected_lateral, 1e-9 * expected_lateral);
  EXPECT_NEAR(q[3], 0.0, 1e-12);
}

}  // namespace
}  // namespace puncture::comparison
