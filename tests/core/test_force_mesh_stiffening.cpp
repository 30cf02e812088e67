// Stiffening in the force mesh (force_mesh.hpp, "Stiffening in the mesh"):
// the springs' laws against the geometry of a stretched spring and finite
// differences; the fixed-pattern LDLT against a dense solve; the quasi-static
// equilibrium against the w = 2 closed form (bisection here) and against a
// dense energy minimisation; the linearised split step; hard cases.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "../../core/src/fixed_pattern_ldlt.hpp"
#include "allocation_counter.hpp"
#include "puncture/contact_surface.hpp"
#include "puncture/force_mesh.hpp"
#include "puncture/hex_lattice.hpp"

using namespace puncture;

namespace {

ForceMeshParams stiffening_params(int w, double ka = 2000.0, double zv = 2e-3) {
  ForceMeshParams p;
  p.rings_w = w;
  p.virtual_stiffness_N_per_m = 20.0;
  p.surface_stiffness_N_per_m = 40.0;
  p.spacing_L_m = 1.5e-3;
  p.deformed_threshold_m = 0.05e-3;
  p.node_damping_N_s_per_m = 0.05;
  p.surface_axial_stiffness_N_per_m = ka;
  p.virtual_stiffening_m = zv;
  return p;
}

ForceMesh make_mesh(const ForceMeshParams& p, MeshIntegrator integrator, double dt = 1e-3) {
  static const PlaneSurface plane(0.0);
  MeshIntegrationSettings s;
  s.integrator = integrator;
  s.time_step_s = dt;
  return ForceMesh(plane, {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()}, p, 1e-3, 1050.0, s);
}

// Transverse force of a surface spring from 3D geometry: the membrane part
// k_s delta plus the z component of an axial spring k_a between (0, 0, 0) and (L, 0, delta).
double spring_force_from_geometry(const ForceMeshParams& p, double delta) {
  const Eigen::Vector3d d(p.spacing_L_m, 0.0, delta);
  const double tension = p.surface_axial_stiffness_N_per_m * (d.norm() - p.spacing_L_m);
  return p.surface_stiffness_N_per_m * delta + tension * d.z() / d.norm();
}

double virtual_force_closed_form(const ForceMeshParams& p, double z) {
  return p.virtual_stiffness_N_per_m * (z + z * z * z / (p.virtual_stiffening_m * p.virtual_stiffening_m));
}

}  // namespace

TEST(ForceMeshStiffening, SpringLawsMatchTheGeometryAndTheirDerivatives) {
  const ForceMeshParams p = stiffening_params(3);
  for (double delta : {-4e-3, -1e-3, -1e-6, 0.0, 2e-7, 3e-4, 1.5e-3, 6e-3, 2e-2}) {
    EXPECT_NEAR(surface_spring_force_N(p, delta), spring_force_from_geometry(p, delta),
                1e-12 * (1.0 + std::abs(spring_force_from_geometry(p, delta))))
        << delta;
    EXPECT_NEAR(virtual_spring_force_N(p, delta), virtual_force_closed_form(p, delta), 1e-12) << delta;
    const double h = 1e-7;
    const double fd_k = (surface_spring_force_N(p, delta + h) - surface_spring_force_N(p, delta - h)) / (2 * h);
    EXPECT_NEAR(surface_spring_stiffness_N_per_m(p, delta), fd_k, 1e-6 * (1.0 + fd_k)) << delta;
    const double fd_f = (surface_spring_energy_J(p, delta + h) - surface_spring_energy_J(p, delta - h)) / (2 * h);
    EXPECT_NEAR(surface_spring_force_N(p, delta), fd_f, 1e-7 * (1.0 + std::abs(fd_f))) << delta;
    const double fd_kv = (virtual_spring_force_N(p, delta + h) - virtual_spring_force_N(p, delta - h)) / (2 * h);
    EXPECT_NEAR(virtual_spring_stiffness_N_per_m(p, delta), fd_kv, 1e-6 * (1.0 + fd_kv)) << delta;
    const double fd_fv = (virtual_spring_energy_J(p, delta + h) - virtual_spring_energy_J(p, delta - h)) / (2 * h);
    EXPECT_NEAR(virtual_spring_force_N(p, delta), fd_fv, 1e-7 * (1.0 + std::abs(fd_fv))) << delta;
  }
  // Small slopes: k_a delta^3 / (2 L^2) on top of the membrane (the leading term of the geometry).
  const double delta = 1e-5;
  EXPECT_NEAR(surface_spring_force_N(p, delta) - p.surface_stiffness_N_per_m * delta,
              p.surface_axial_stiffness_N_per_m * delta * delta * delta / (2 * p.spacing_L_m * p.spacing_L_m),
              1e-4 * p.surface_axial_stiffness_N_per_m * delta * delta * delta / (2 * p.spacing_L_m * p.spacing_L_m));
  // Off: exactly the linear springs.
  ForceMeshParams linear = p;
  linear.surface_axial_stiffness_N_per_m = 0.0;
  linear.virtual_stiffening_m = 0.0;
  EXPECT_FALSE(linear.nonlinear());
  EXPECT_EQ(surface_spring_force_N(linear, 3e-3), linear.surface_stiffness_N_per_m * 3e-3);
  EXPECT_EQ(virtual_spring_force_N(linear, 3e-3), linear.virtual_stiffness_N_per_m * 3e-3);
}

TEST(ForceMeshStiffening, FixedPatternLdltSolvesLikeADenseFactorisation) {
  const HexLattice lat = make_hex_lattice(5);
  const int n = lat.node_count();
  std::vector<std::pair<int, int>> lower;
  for (int i = 0; i < n; ++i) lower.push_back({i, i});
  for (int i = 0; i < n; ++i)
    for (int k = lat.neighbour_offsets[i]; k < lat.neighbour_offsets[i + 1]; ++k)
      if (lat.neighbours[k] > i) lower.push_back({lat.neighbours[k], i});
  detail::FixedPatternLdlt ldlt;
  ldlt.analyse(n, lower);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.1, 2.0);
  for (int trial = 0; trial < 3; ++trial) {
    // A = sum over springs of k_e (e_i - e_j)(e_i - e_j)^T + diag(d): SPD with the lattice's pattern.
    std::vector<double> values(lower.size(), 0.0);
    Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i) values[i] = u(rng) * (trial == 2 ? 1e-2 : 1.0);
    for (std::size_t e = n; e < lower.size(); ++e) {
      const double k = u(rng) * 100.0;
      values[e] = -k;
      values[lower[e].first] += k;
      values[lower[e].second] += k;
    }
    for (std::size_t e = 0; e < lower.size(); ++e) {
      dense(lower[e].first, lower[e].second) += values[e];
      if (lower[e].first != lower[e].second) dense(lower[e].second, lower[e].first) += values[e];
    }
    ASSERT_TRUE(ldlt.factorize(values.data())) << trial;
    const Eigen::VectorXd b = Eigen::VectorXd::Random(n);
    Eigen::VectorXd x(n);
    ldlt.solve(b, x);
    const Eigen::VectorXd want = dense.ldlt().solve(b);
    EXPECT_LT((x - want).norm(), 1e-9 * want.norm()) << trial;
    EXPECT_LT((dense * x - b).norm(), 1e-9 * b.norm()) << trial;
  }
  // Not positive definite: reported, not factorised.
  std::vector<double> bad(lower.size(), 0.0);
  for (int i = 0; i < n; ++i) bad[i] = -1.0;
  EXPECT_FALSE(ldlt.factorize(bad.data()));
}

TEST(ForceMeshStiffening, TwoRingEquilibriumMatchesTheClosedForm) {
  // w = 2: the six ring-2 nodes move alike, so f_v(z1) = f_s(z0 - z1)
  // (bisection here, from the geometry), and the reaction is f_v(z0) + 6 f_s(z0 - z1).
  const ForceMeshParams p = stiffening_params(2);
  ForceMesh mesh = make_mesh(p, MeshIntegrator::QuasiStatic);
  for (double z0 : {1e-4, 2e-3, 8e-3, 2e-2}) {
    mesh.advance(z0);
    double lo = 0.0, hi = z0;
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi);
      (virtual_force_closed_form(p, mid) > spring_force_from_geometry(p, z0 - mid) ? hi : lo) = mid;
    }
    const double z1 = 0.5 * (lo + hi);
    const double reaction = virtual_force_closed_form(p, z0) + 6.0 * spring_force_from_geometry(p, z0 - z1);
    EXPECT_NEAR(mesh.ring_mean_deflection_m(2), z1, 1e-10 * z0) << z0;
    EXPECT_NEAR(mesh.contact_reaction_N(), reaction, 1e-9 * reaction) << z0;
    // Eq. (5) with each virtual spring's own force carries the whole reaction at equilibrium.
    EXPECT_NEAR(mesh.eq5_force_N(), reaction, 1e-9 * reaction) << z0;
  }
}

TEST(ForceMeshStiffening, EquilibriumMinimisesTheEnergyOfADenseSolve) {
  // Dense Newton on the total energy of the free nodes (every pair at
  // distance L a spring, from the node positions), independent of the
  // mesh's sparse assembly and factorisation.
  const ForceMeshParams p = stiffening_params(4);
  ForceMesh mesh = make_mesh(p, MeshIntegrator::QuasiStatic);
  const double z0 = 6e-3;
  mesh.advance(z0);
  const int n = mesh.node_count();
  std::vector<std::pair<int, int>> springs;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if (std::abs((mesh.rest_positions().col(i) - mesh.rest_positions().col(j)).norm() - p.spacing_L_m) < 1e-9)
        springs.push_back({i, j});
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
  z[0] = z0;
  for (int it = 0; it < 100; ++it) {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i) g[i] = virtual_spring_force_N(p, z[i]), H(i, i) = virtual_spring_stiffness_N_per_m(p, z[i]);
    for (const auto& [i, j] : springs) {
      const double f = surface_spring_force_N(p, z[i] - z[j]), k = surface_spring_stiffness_N_per_m(p, z[i] - z[j]);
      g[i] += f, g[j] -= f;
      H(i, i) += k, H(j, j) += k, H(i, j) -= k, H(j, i) -= k;
    }
    const Eigen::VectorXd dz = -H.bottomRightCorner(n - 1, n - 1).ldlt().solve(g.tail(n - 1));
    double alpha = 1.0;
    z.tail(n - 1) += alpha * dz;
    if (dz.cwiseAbs().maxCoeff() < 1e-15) break;
  }
  EXPECT_LT((mesh.deflections_m() - z).cwiseAbs().maxCoeff(), 1e-11);
  EXPECT_GT(mesh.last_newton_iterations(), 0);
}

TEST(ForceMeshStiffening, StretchedSpringsWidenTheTentWithDepth) {
  // Linear mesh: the deflection profile scales with z0. With stretch
  // stiffening the outer rings carry a growing share (the tissue's tent widens).
  ForceMeshParams linear = stiffening_params(6, 0.0, 0.0);
  ForceMeshParams stretching = stiffening_params(6, 4000.0, 0.0);
  ForceMesh a = make_mesh(linear, MeshIntegrator::QuasiStatic), b = make_mesh(stretching, MeshIntegrator::QuasiStatic);
  a.advance(1e-6);
  b.advance(1e-6);
  const double linear_small = a.ring_mean_deflection_m(3) / 1e-6, stretch_small = b.ring_mean_deflection_m(3) / 1e-6;
  a.advance(6e-3);
  b.advance(6e-3);
  EXPECT_NEAR(a.ring_mean_deflection_m(3) / 6e-3, linear_small, 1e-12);
  EXPECT_GT(b.ring_mean_deflection_m(3) / 6e-3, 1.5 * stretch_small);
  EXPECT_NEAR(stretch_small, linear_small, 1e-3 * linear_small);  // small slopes: the linear mesh
}

TEST(ForceMeshStiffening, SplitStepIsLinearisedToSecondOrder) {
  // predict() linearises the step at the last contact deflection z0*: the
  // reaction it predicts at z0* + dz differs from the solved equilibrium
  // there (quasi-static: a mesh with no memory, solved afresh) by O(dz^2),
  // which a wrong sensitivity dz/dz0 would make O(dz).
  const ForceMeshParams p = stiffening_params(5);
  const double z_star = 5e-3;
  double errors[2];
  int k = 0;
  for (double dz : {8e-5, 4e-5}) {
    ForceMesh m = make_mesh(p, MeshIntegrator::QuasiStatic);
    m.advance(z_star);
    m.predict();
    const double predicted = m.predicted_reaction_N(z_star + dz);
    ForceMesh fresh = make_mesh(p, MeshIntegrator::QuasiStatic);
    fresh.advance(z_star + dz);
    fresh.predict();  // solved and linearised exactly at z_star + dz
    const double exact = fresh.predicted_reaction_N(z_star + dz);
    errors[k++] = std::abs(predicted - exact);
    EXPECT_LT(std::abs(predicted - exact), 1e-3 * exact) << dz;
    // The slope is the tangent of the solved reaction curve (central difference of fresh solves).
    ForceMesh lo = make_mesh(p, MeshIntegrator::QuasiStatic), hi = make_mesh(p, MeshIntegrator::QuasiStatic);
    lo.advance(z_star - 1e-7);
    hi.advance(z_star + 1e-7);
    const double fd_slope = (hi.contact_reaction_N() - lo.contact_reaction_N()) / 2e-7;
    EXPECT_NEAR(m.reaction_slope_N_per_m(), fd_slope, 1e-5 * fd_slope);
  }
  EXPECT_GT(errors[0] / errors[1], 3.0);
  EXPECT_LT(errors[0] / errors[1], 5.0);
}

TEST(ForceMeshStiffening, HardCasesStayFiniteAndMonotone) {
  // 3 cm of contact deflection on 1 mm springs that stiffen from 0.5 mm: Newton with its line search converges.
  ForceMeshParams p = stiffening_params(8, 1e4, 0.5e-3);
  p.spacing_L_m = 1e-3;
  for (MeshIntegrator integrator : {MeshIntegrator::QuasiStatic, MeshIntegrator::Implicit, MeshIntegrator::Explicit}) {
    ForceMesh m = make_mesh(p, integrator);
    if (integrator == MeshIntegrator::Explicit) EXPECT_TRUE(m.explicit_falls_back_to_implicit());
    double last = 0.0;
    for (int i = 1; i <= 300; ++i) {
      ASSERT_NO_THROW(m.advance(30e-3 * i / 300.0)) << i;
      const double f = m.contact_reaction_N();
      ASSERT_TRUE(std::isfinite(f));
      EXPECT_GT(f, last) << i;
      last = f;
    }
    EXPECT_GT(m.energy_J(), 0.0);
    m.reset();
    EXPECT_EQ(m.contact_reaction_N(), 0.0);
  }
}

TEST(ForceMeshStiffening, ImplicitMeshSettlesOnTheQuasiStaticEquilibrium) {
  const ForceMeshParams p = stiffening_params(5);
  ForceMesh dynamic = make_mesh(p, MeshIntegrator::Implicit), still = make_mesh(p, MeshIntegrator::QuasiStatic);
  for (int i = 1; i <= 100; ++i) dynamic.advance(4e-3 * i / 100.0);
  for (int i = 0; i < 3000; ++i) dynamic.advance(4e-3);
  still.advance(4e-3);
  EXPECT_LT((dynamic.deflections_m() - still.deflections_m()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_NEAR(dynamic.contact_reaction_N(), still.contact_reaction_N(), 1e-7 * still.contact_reaction_N());
}

TEST(ForceMeshStiffening, AStepAllocatesNothing) {
  ForceMesh m = make_mesh(stiffening_params(8), MeshIntegrator::Implicit);
  m.advance(1e-4);
  double sum = 0.0;
  test::start_counting_allocations();
  for (int i = 2; i <= 200; ++i) {
    m.predict();
    sum += m.predicted_reaction_N(5e-5 * i);
    m.commit(5e-5 * i);
    // The per-node state and the ring means are expanded from the cells when asked: no allocation either.
    sum += m.deformed_rings() + m.ring_mean_deflection_m(3) + m.deflections_m()[5] + m.contact_reaction_N();
  }
  EXPECT_EQ(test::stop_counting_allocations(), 0);
  EXPECT_TRUE(std::isfinite(sum));
}

TEST(ForceMeshStiffening, ACopyIsIndependent) {
  // The tangent's factorisation is copied, not shared: a copy steps on its own.
  ForceMesh original = make_mesh(stiffening_params(5), MeshIntegrator::Implicit);
  for (int i = 1; i <= 20; ++i) original.advance(1e-4 * i);
  ForceMesh copy = original;
  copy.advance(5e-3);
  original.advance(2.1e-3);
  ForceMesh again = make_mesh(stiffening_params(5), MeshIntegrator::Implicit);
  for (int i = 1; i <= 20; ++i) again.advance(1e-4 * i);
  again.advance(2.1e-3);
  EXPECT_EQ(original.contact_reaction_N(), again.contact_reaction_N());
  EXPECT_GT(copy.contact_reaction_N(), original.contact_reaction_N());
}

namespace {

// Ring means of a mesh's node deflections, summed in node order.
Eigen::VectorXd ring_means_of_nodes(const ForceMesh& m) {
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(m.rings()), count = Eigen::VectorXd::Zero(m.rings());
  const Eigen::VectorXd& z = m.deflections_m();
  for (int i = 0; i < m.node_count(); ++i) {
    sum[m.node_rings()[i] - 1] += z[i];
    count[m.node_rings()[i] - 1] += 1.0;
  }
  return sum.cwiseQuotient(count);
}

int deformed_rings_of(const Eigen::VectorXd& means, double threshold_m) {
  int j = 0;
  while (j < means.size() && means[j] > threshold_m) ++j;
  return j;
}

}  // namespace

TEST(ForceMeshStiffening, RingMeansAndDeformedRingsAreThoseOfTheNodes) {
  // A stiffening mesh keeps its state on the lattice's cells and expands it to
  // the nodes when asked; the ring means, the deformed rings (checked per tick
  // from the cells' range) and the velocities must be exactly those of the
  // nodes, over a press, a fast withdrawal that lifts rings above the surface
  // (negative deflections) and the rebound.
  ForceMeshParams light = stiffening_params(9);
  light.node_damping_N_s_per_m = 1e-4;  // little damping: the released rings overshoot
  ForceMesh m = make_mesh(light, MeshIntegrator::Implicit);
  std::vector<double> path;
  for (int i = 1; i <= 120; ++i) path.push_back(4e-3 * i / 120.0);
  for (int i = 0; i < 300; ++i) path.push_back(0.0);
  int checked = 0, negative = 0;
  double ring4_at_mid = 0.0;
  for (std::size_t t = 0; t < path.size(); ++t) {
    m.advance(path[t]);
    const int rings = m.deformed_rings();  // before anything expands the nodes
    const Eigen::VectorXd means = ring_means_of_nodes(m);
    ASSERT_EQ(rings, deformed_rings_of(means, m.params().deformed_threshold_m)) << "tick " << t;
    for (int j = 1; j <= m.rings(); ++j) ASSERT_EQ(m.ring_mean_deflection_m(j), means[j - 1]) << "tick " << t;
    negative += means.minCoeff() < 0.0;
    if (t == 60) ring4_at_mid = means[3];
    ++checked;
  }
  EXPECT_EQ(checked, static_cast<int>(path.size()));
  EXPECT_GT(negative, 0);  // the withdrawal did lift some ring
  // A threshold exactly at a ring's mean: that ring is not deformed (mean > threshold is false),
  // the case the cells' range cannot decide.
  ForceMeshParams p = light;
  ForceMesh a = make_mesh(p, MeshIntegrator::Implicit);
  for (int t = 0; t <= 60; ++t) a.advance(path[t]);
  p.deformed_threshold_m = a.ring_mean_deflection_m(4);
  ASSERT_EQ(p.deformed_threshold_m, ring4_at_mid);
  ForceMesh b = make_mesh(p, MeshIntegrator::Implicit);
  for (int t = 0; t <= 60; ++t) b.advance(path[t]);
  const Eigen::VectorXd means_b = ring_means_of_nodes(b);
  ASSERT_EQ(means_b[3], p.deformed_threshold_m);  // the same path: the threshold does not set its scale here
  ASSERT_GT(means_b.head(3).minCoeff(), p.deformed_threshold_m);
  EXPECT_EQ(b.deformed_rings(), 3);
}
