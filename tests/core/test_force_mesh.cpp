// Force mesh (force_mesh.hpp): lattice topology, equilibrium against an
// independent dense solve and the w = 2 closed form, the Eq. (5) identity at
// equilibrium, and the stability of the three integrators.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdlib>

#include "puncture/contact_surface.hpp"
#include "puncture/force_mesh.hpp"
#include "puncture/hex_lattice.hpp"

using namespace puncture;

namespace {

ForceMeshParams params(int w, double K = 160.0, double ks = 400.0) {
  ForceMeshParams p;
  p.rings_w = w;
  p.virtual_stiffness_N_per_m = K;
  p.surface_stiffness_N_per_m = ks;
  p.spacing_L_m = 2e-3;
  p.deformed_threshold_m = 0.05e-3;
  p.node_damping_N_s_per_m = 0.05;
  return p;
}

SurfacePoint top_contact() { return {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()}; }

ForceMesh make_mesh(const ForceMeshParams& p, MeshIntegrator integrator, double dt = 1e-3) {
  static const PlaneSurface plane(0.0);
  MeshIntegrationSettings s;
  s.integrator = integrator;
  s.time_step_s = dt;
  return ForceMesh(plane, top_contact(), p, 0.8e-3, 1050.0, s);
}

// Dense K_full (N x N) assembled here from the geometry only: K on the
// diagonal, k_s for every pair of nodes at distance L (independent of the
// lattice's neighbour list).
Eigen::MatrixXd dense_stiffness(const ForceMesh& mesh) {
  const int n = mesh.node_count();
  const double K = mesh.params().virtual_stiffness_N_per_m, ks = mesh.params().surface_stiffness_N_per_m;
  const double L = mesh.params().spacing_L_m;
  Eigen::MatrixXd A = K * Eigen::MatrixXd::Identity(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (i != j && std::abs((mesh.rest_positions().col(i) - mesh.rest_positions().col(j)).norm() - L) < 1e-9) {
        A(i, i) += ks;
        A(i, j) -= ks;
      }
  return A;
}

}  // namespace

TEST(HexLattice, RingCountsNeighboursAndSpacing) {
  for (int w : {1, 2, 3, 8}) {
    const HexLattice lat = make_hex_lattice(w);
    ASSERT_EQ(lat.node_count(), 1 + 3 * w * (w - 1));
    std::vector<int> per_ring(w + 1, 0);
    for (int i = 0; i < lat.node_count(); ++i) {
      const auto& a = lat.axial[i];
      const int hex_distance = (std::abs(a.x()) + std::abs(a.y()) + std::abs(a.x() + a.y())) / 2;
      EXPECT_EQ(lat.ring[i], hex_distance + 1);
      ++per_ring[lat.ring[i]];
      for (int k = lat.neighbour_offsets[i]; k < lat.neighbour_offsets[i + 1]; ++k) {
        const double d = (lat.planar_position(i, 2.0) - lat.planar_position(lat.neighbours[k], 2.0)).norm();
        EXPECT_NEAR(d, 2.0, 1e-12);
      }
      if (lat.ring[i] < w) EXPECT_EQ(lat.neighbour_count(i), 6);  // inside: six neighbours
    }
    EXPECT_EQ(per_ring[1], 1);
    for (int j = 2; j <= w; ++j) EXPECT_EQ(per_ring[j], 6 * (j - 1));
  }
  EXPECT_THROW(make_hex_lattice(0), std::invalid_argument);
}

TEST(ForceMesh, NodesLieOnTheSurfaceAtSpacingL) {
  const ForceMesh mesh = make_mesh(params(4), MeshIntegrator::QuasiStatic);
  for (int i = 0; i < mesh.node_count(); ++i) EXPECT_DOUBLE_EQ(mesh.rest_positions()(2, i), 0.0);
  EXPECT_NEAR((mesh.rest_positions().col(1) - mesh.rest_positions().col(0)).norm(), 2e-3, 1e-15);
  EXPECT_NEAR(mesh.node_mass_kg(), 1050.0 * 0.8e-3 * std::sqrt(3.0) / 2.0 * 4e-6, 1e-18);
}

TEST(ForceMesh, TwoRingClosedForm) {
  const double K = 160.0, ks = 400.0, z0 = 1e-3;
  ForceMesh mesh = make_mesh(params(2, K, ks), MeshIntegrator::QuasiStatic);
  mesh.advance(z0);
  // Ring-2 node: (K + 3 ks) z - ks z0 - 2 ks z = 0.
  const double z = ks * z0 / (K + ks);
  for (int i = 1; i < 7; ++i) EXPECT_NEAR(mesh.deflections_m()[i], z, 1e-15);
  const double F = K * z0 + 6.0 * ks * (z0 - z);
  EXPECT_NEAR(mesh.contact_reaction_N(), F, 1e-12);
  EXPECT_NEAR(mesh.eq5_force_N(), F, 1e-12);
  EXPECT_NEAR(mesh.static_stiffness_N_per_m(), F / z0, 1e-9);
}

TEST(ForceMesh, EquilibriumMatchesDenseSolveAndEq5) {
  for (int w : {3, 6, 8}) {
    ForceMesh mesh = make_mesh(params(w), MeshIntegrator::QuasiStatic);
    const double z0 = 2.5e-3;
    mesh.advance(z0);
    const Eigen::MatrixXd A = dense_stiffness(mesh);
    const int n = mesh.node_count();
    // Free block solve with the contact deflection prescribed.
    const Eigen::VectorXd zf =
        A.bottomRightCorner(n - 1, n - 1).ldlt().solve(-A.col(0).tail(n - 1) * z0);
    for (int i = 1; i < n; ++i) EXPECT_NEAR(mesh.deflections_m()[i], zf[i - 1], 1e-12) << "w=" << w << " node " << i;
    const double reaction = A(0, 0) * z0 + A.row(0).tail(n - 1).dot(zf);
    EXPECT_NEAR(mesh.contact_reaction_N(), reaction, 1e-9 * reaction);
    // Eq. (5): global force balance, reaction = sum of the virtual-spring forces.
    double eq5 = 160.0 * z0;
    for (int j = 2; j <= w; ++j) {
      double mean = 0.0;
      int count = 0;
      for (int i = 1; i < n; ++i)
        if (mesh.node_rings()[i] == j) mean += zf[i - 1], ++count;
      eq5 += 160.0 * 6 * (j - 1) * mean / count;
    }
    EXPECT_NEAR(mesh.eq5_force_N(), eq5, 1e-9 * eq5);
    EXPECT_NEAR(mesh.eq5_force_N(), mesh.contact_reaction_N(), 1e-9 * eq5);
    // Deflection decays outward and stays between 0 and z0.
    for (int j = 2; j <= w; ++j) {
      EXPECT_LT(mesh.ring_mean_deflection_m(j), mesh.ring_mean_deflection_m(j - 1));
      EXPECT_GT(mesh.ring_mean_deflection_m(j), 0.0);
    }
  }
}

TEST(ForceMesh, DeformedRingsAndBreakthrough) {
  ForceMesh mesh = make_mesh(params(4), MeshIntegrator::QuasiStatic);
  mesh.advance(0.0);
  EXPECT_EQ(mesh.deformed_rings(), 0);
  // Contact deflection at which the outer ring mean reaches the threshold.
  const double u_outer = [&] {
    double s = 0.0;
    int c = 0;
    for (int i = 0; i < mesh.node_count(); ++i)
      if (mesh.node_rings()[i] == 4) s += mesh.unit_influence()[i], ++c;
    return s / c;
  }();
  mesh.advance(0.99 * 0.05e-3 / u_outer);
  EXPECT_EQ(mesh.deformed_rings(), 3);
  EXPECT_FALSE(mesh.broken());
  mesh.advance(1.01 * 0.05e-3 / u_outer);
  EXPECT_EQ(mesh.deformed_rings(), 4);
  EXPECT_TRUE(mesh.broken());
  mesh.advance(-1.0);  // a negative deflection is clamped: the tip cannot pull the surface
  EXPECT_EQ(mesh.deflections_m()[0], 0.0);
}

TEST(ForceMesh, GershgorinBoundsTheTrueOmegaMax) {
  const ForceMesh mesh = make_mesh(params(5), MeshIntegrator::Explicit);
  const Eigen::MatrixXd A = dense_stiffness(mesh);
  const int n = mesh.node_count();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A.bottomRightCorner(n - 1, n - 1));
  const double omega_sq = es.eigenvalues().maxCoeff() / mesh.node_mass_kg();
  EXPECT_GE(mesh.omega_max_squared_bound(), omega_sq);
  EXPECT_LE(mesh.omega_max_squared_bound(), 1.5 * omega_sq);  // and is not absurdly loose
  // Undamped limit of dt_crit is 2 / omega.
  ForceMeshParams p = params(5);
  p.node_damping_N_s_per_m = 0.0;
  const ForceMesh undamped = make_mesh(p, MeshIntegrator::Explicit);
  EXPECT_NEAR(undamped.critical_time_step_s(), 2.0 / std::sqrt(undamped.omega_max_squared_bound()), 1e-15);
}

// Drives a mesh with a ramp then a hold and checks stability and convergence.
class IntegratorStability : public ::testing::TestWithParam<std::tuple<MeshIntegrator, double>> {};

TEST_P(IntegratorStability, BoundedEnergyAndConvergenceToEquilibrium) {
  const auto [integrator, factor] = GetParam();
  const ForceMeshParams p = params(6, 160.0, 400.0);
  // The critical step of this mesh, then a mesh stepping at factor * dt_crit.
  const double dt_crit = make_mesh(p, MeshIntegrator::Explicit).critical_time_step_s();
  const double dt = factor * dt_crit;
  ForceMesh mesh = make_mesh(p, integrator, dt);
  ForceMesh reference = make_mesh(p, MeshIntegrator::QuasiStatic, dt);
  const double z_max = 3e-3;
  reference.advance(z_max);
  const double e_static = reference.energy_J();
  // Ramp over ~20 ms of simulated time, then hold for ~3 s (or at least 2000 steps).
  const int ramp = std::max(5, static_cast<int>(0.02 / dt));
  const int hold = std::max(2000, static_cast<int>(3.0 / dt));
  double e_max = 0.0;
  for (int s = 1; s <= ramp + hold; ++s) {
    mesh.advance(z_max * std::min(1.0, static_cast<double>(s) / ramp));
    ASSERT_TRUE(std::isfinite(mesh.contact_reaction_N()));
    e_max = std::max(e_max, mesh.energy_J());
  }
  // Energy stays bounded: the needle's work on a damped mesh cannot exceed a
  // few times the static energy at the final deflection.
  EXPECT_LT(e_max, 10.0 * e_static);
  EXPECT_NEAR(mesh.contact_reaction_N(), reference.contact_reaction_N(), 1e-3 * reference.contact_reaction_N());
  EXPECT_NEAR(mesh.eq5_force_N(), mesh.contact_reaction_N(), 1e-3 * mesh.contact_reaction_N());
  if (integrator == MeshIntegrator::Explicit) {
    EXPECT_EQ(mesh.explicit_substeps(), factor < 0.9 ? 1 : (factor < 50 ? 2 : 65));
    EXPECT_EQ(mesh.explicit_falls_back_to_implicit(), factor > 50);
  }
}

INSTANTIATE_TEST_SUITE_P(
    CriticalStepMultiples, IntegratorStability,
    ::testing::Combine(::testing::Values(MeshIntegrator::Explicit, MeshIntegrator::Implicit),
                       ::testing::Values(0.5, 0.95, 1.05, 100.0)));

TEST(ForceMesh, ImplicitStepMatchesDenseBackwardEuler) {
  const ForceMeshParams p = params(4);
  const double dt = 1e-3;
  ForceMesh mesh = make_mesh(p, MeshIntegrator::Implicit, dt);
  const Eigen::MatrixXd A = dense_stiffness(mesh);
  const int n = mesh.node_count();
  const double m = mesh.node_mass_kg(), c = p.node_damping_N_s_per_m;
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n - 1), v = z;
  for (int s = 1; s <= 10; ++s) {
    const double z0 = 1e-4 * s;
    mesh.advance(z0);
    const Eigen::MatrixXd S = (m / (dt * dt) + c / dt) * Eigen::MatrixXd::Identity(n - 1, n - 1) +
                              A.bottomRightCorner(n - 1, n - 1);
    const Eigen::VectorXd rhs = m / (dt * dt) * (z + dt * v) + c / dt * z - A.col(0).tail(n - 1) * z0;
    const Eigen::VectorXd z_new = S.ldlt().solve(rhs);
    v = (z_new - z) / dt;
    z = z_new;
  }
  for (int i = 1; i < n; ++i) EXPECT_NEAR(mesh.deflections_m()[i], z[i - 1], 1e-14);
}

TEST(ForceMesh, SingleRingIsTheContactNodeAlone) {
  ForceMesh mesh = make_mesh(params(1), MeshIntegrator::Implicit);
  mesh.advance(1e-3);
  EXPECT_EQ(mesh.node_count(), 1);
  EXPECT_NEAR(mesh.contact_reaction_N(), 0.16, 1e-15);
  EXPECT_NEAR(mesh.eq5_force_N(), 0.16, 1e-15);
  EXPECT_TRUE(mesh.broken());
}

TEST(ForceMesh, RejectsBadParameters) {
  ForceMeshParams p = params(3);
  p.virtual_stiffness_N_per_m = 0.0;
  EXPECT_THROW(make_mesh(p, MeshIntegrator::Implicit), std::invalid_argument);
  p = params(3);
  p.spacing_L_m = -1.0;
  EXPECT_THROW(make_mesh(p, MeshIntegrator::Implicit), std::invalid_argument);
  EXPECT_THROW(parse_mesh_integrator("rk4"), std::invalid_argument);
  EXPECT_EQ(parse_mesh_integrator("quasi_static"), MeshIntegrator::QuasiStatic);
}

// The damped stability limit used for dt_crit, checked on a plain symplectic
// Euler loop written here on the dense matrices with the exact omega_max: a
// step 5 % below the limit stays bounded, 5 % above it blows up. (This is why
// the mesh substeps: without substepping the second case is what it would do.)
TEST(ForceMesh, DampedCriticalStepFormulaIsSharp) {
  ForceMeshParams p = params(3);
  const ForceMesh mesh = make_mesh(p, MeshIntegrator::Explicit);
  const Eigen::MatrixXd A = dense_stiffness(mesh);
  const int nf = mesh.node_count() - 1;
  const Eigen::MatrixXd Kff = A.bottomRightCorner(nf, nf);
  const double m = mesh.node_mass_kg(), c = p.node_damping_N_s_per_m;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Kff);
  const double w2 = es.eigenvalues().maxCoeff() / m;
  // Closed form for a damped oscillator under symplectic Euler: omega dt < 2 (sqrt(1 + zeta^2) - zeta).
  const double omega = std::sqrt(w2), zeta = c / (2.0 * m * omega);
  const double dt_exact = 2.0 / omega * (std::sqrt(1.0 + zeta * zeta) - zeta);
  EXPECT_LE(mesh.critical_time_step_s(), dt_exact);  // the Gershgorin version is on the safe side
  auto growth = [&](double dt) {
    Eigen::VectorXd z = es.eigenvectors().col(nf - 1), v = Eigen::VectorXd::Zero(nf);  // highest mode
    for (int s = 0; s < 2000; ++s) {
      v += dt * (-(Kff * z) - c * v) / m;
      z += dt * v;
    }
    return z.norm();
  };
  EXPECT_LT(growth(0.95 * dt_exact), 1.0);
  EXPECT_GT(growth(1.05 * dt_exact), 1e6);
}
