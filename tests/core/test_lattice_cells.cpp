// The lattice's cells (core/src/lattice_cells.hpp) and the stiffening mesh's
// step solved on them: the cells are the orbits of the hexagonal lattice's
// six-fold symmetry, and the implicit step on the cells gives every node the
// deflection of a backward-Euler Newton solve over all nodes (written here,
// dense, independent of the cells).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "../../core/src/lattice_cells.hpp"
#include "puncture/contact_surface.hpp"
#include "puncture/force_mesh.hpp"
#include "puncture/hex_lattice.hpp"

using namespace puncture;

TEST(LatticeCells, CellsAreTheOrbitsOfTheSixFoldSymmetry) {
  for (int w = 1; w <= 12; ++w) {
    const HexLattice lattice = make_hex_lattice(w);
    const detail::LatticeCells cells = detail::equitable_cells(lattice);
    // Ring j >= 2 (d = j - 1 steps out) has floor(d / 2) + 1 orbits: a twelfth of it.
    int orbits = 1;
    for (int d = 1; d < w; ++d) orbits += d / 2 + 1;
    EXPECT_EQ(cells.count(), orbits) << w;
    EXPECT_EQ(cells.cell_of[0], 0);
    EXPECT_EQ(cells.size[0], 1);
    // Nodes of one cell: same ring, same distance from the centre.
    for (int i = 0; i < lattice.node_count(); ++i) {
      const int r = cells.representative[cells.cell_of[i]];
      EXPECT_EQ(lattice.ring[i], lattice.ring[r]) << w << " " << i;
      EXPECT_NEAR(lattice.planar_position(i, 1.0).norm(), lattice.planar_position(r, 1.0).norm(), 1e-12) << i;
    }
    // The pairs count every spring between distinct cells once.
    int between = 0, listed = 0;
    for (int i = 0; i < lattice.node_count(); ++i)
      for (int k = lattice.neighbour_offsets[i]; k < lattice.neighbour_offsets[i + 1]; ++k)
        if (lattice.neighbours[k] > i && cells.cell_of[i] != cells.cell_of[lattice.neighbours[k]]) ++between;
    for (const auto& p : cells.pairs) {
      listed += p.edges;
      EXPECT_LT(p.a, p.b);
    }
    EXPECT_EQ(listed, between) << w;
  }
}

namespace {

/// Largest deviation (m) of an implicit mesh's deflections, and of its
/// velocities times dt, from a dense backward-Euler Newton solve over every
/// node, over 60 steps of a ramp then a hold of the contact deflection.
double deviation_from_dense_solve(double axial_stiffness_N_per_m, double virtual_stiffening_m) {
  ForceMeshParams p;
  p.rings_w = 5;
  p.virtual_stiffness_N_per_m = 20.0;
  p.surface_stiffness_N_per_m = 40.0;
  p.spacing_L_m = 1.5e-3;
  p.deformed_threshold_m = 0.05e-3;
  p.node_damping_N_s_per_m = 0.05;
  p.surface_axial_stiffness_N_per_m = axial_stiffness_N_per_m;
  p.virtual_stiffening_m = virtual_stiffening_m;
  const PlaneSurface plane(0.0);
  const double dt = 1e-3;
  MeshIntegrationSettings s;
  s.integrator = MeshIntegrator::Implicit;
  s.time_step_s = dt;
  ForceMesh mesh(plane, {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()}, p, 1e-3, 1050.0, s);
  const HexLattice& lat = mesh.lattice();
  const int n = mesh.node_count();
  const double m = mesh.node_mass_kg(), c = p.node_damping_N_s_per_m;
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n), v = Eigen::VectorXd::Zero(n);
  double worst = 0.0;
  for (int step = 0; step < 60; ++step) {
    const double z0 = step < 40 ? 1.5e-4 * step : 6e-3;  // a ramp, then held
    mesh.advance(z0);
    // Dense Newton on every free node: m (z - z_old - dt v_old) / dt^2 + c (z - z_old) / dt + f(z) = 0.
    Eigen::VectorXd x = z;
    x[0] = z0;
    for (int it = 0; it < 50; ++it) {
      Eigen::VectorXd g(n);
      Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
      for (int i = 0; i < n; ++i) {
        g[i] = m * (x[i] - z[i] - dt * v[i]) / (dt * dt) + c * (x[i] - z[i]) / dt + virtual_spring_force_N(p, x[i]);
        H(i, i) = m / (dt * dt) + c / dt + virtual_spring_stiffness_N_per_m(p, x[i]);
        for (int k = lat.neighbour_offsets[i]; k < lat.neighbour_offsets[i + 1]; ++k) {
          const int j = lat.neighbours[k];
          g[i] += surface_spring_force_N(p, x[i] - x[j]);
          H(i, i) += surface_spring_stiffness_N_per_m(p, x[i] - x[j]);
          H(i, j) -= surface_spring_stiffness_N_per_m(p, x[i] - x[j]);
        }
      }
      const Eigen::VectorXd dx = -H.bottomRightCorner(n - 1, n - 1).ldlt().solve(g.tail(n - 1));
      x.tail(n - 1) += dx;
      if (dx.cwiseAbs().maxCoeff() < 1e-16) break;
    }
    v = (x - z) / dt;
    z = x;
    worst = std::max(worst, (mesh.deflections_m() - z).cwiseAbs().maxCoeff());
    worst = std::max(worst, dt * (mesh.velocities_m_per_s().tail(n - 1) - v.tail(n - 1)).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(z[n - 1], 1e-6);  // the outer ring moved: not a trivial comparison
  return worst;
}

}  // namespace

TEST(LatticeCells, StiffeningImplicitStepOnTheCellsMatchesADenseSolveOfEveryNode) {
  // The mesh's Newton stops at a residual of 1e-10 of its springs' force.
  EXPECT_LT(deviation_from_dense_solve(2000.0, 2e-3), 2e-9 * 6e-3);
}

TEST(LatticeCells, LinearImplicitStepOnTheCellsMatchesADenseSolveOfEveryNode) {
  EXPECT_LT(deviation_from_dense_solve(0.0, 0.0), 1e-12 * 6e-3);
}
