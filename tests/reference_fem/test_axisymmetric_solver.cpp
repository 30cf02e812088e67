// Axisymmetric solver against closed forms: the flat punch on a thick block
// (Sneddon 1965 with the bonded-layer bottom-effect correction) and on a thin
// bonded layer (Garcia & Garcia 2018). (No patch test here: the solver holds
// the base and the lateral ring fixed and takes no other boundary data, so no
// non-trivial homogeneous deformation satisfies its boundary conditions; the
// 3D solver's patch test is in test_materials_and_solver.cpp.)
#include <gtest/gtest.h>

#include <cmath>

#include <puncture/fem/axisymmetric_solver.hpp>
#include <puncture/meshing/axisymmetric_slab_mesh.hpp>

#include "fem_test_scenes.hpp"

using namespace puncture;
using namespace puncture::fem;

namespace {

/// One homogeneous layer of thickness h on a rigid base, sample radius R_s,
/// punch radius a; neo-Hookean with E, nu; never punctures.
Scene block_scene(double a, double h, double R_s, double E, double nu, int per_radius) {
  Scene s;
  s.name = "block";
  s.sample.diameter_m = 2 * R_s;
  s.layers = {puncture::fem::testing::make_layer("block", h, E, nu, 1e9)};
  s.needle.radius_m = a;
  s.needle.tip = "blunt";
  s.insertion.target_depth_m = 0.1 * h;
  s.fem.mesh.elements_per_needle_radius = per_radius;
  s.fem.mesh.min_elements_per_layer = 8;
  s.fem.mesh.path_element_size_mm = 1e3 * 2 * a;
  s.fem.mesh.radial_growth = 1.25;
  return s;
}

struct Indentation {
  double force_N;
  std::size_t dofs;
};

/// Flat-punch indentation to `depth` in `steps` equal steps.
Indentation indent(const Scene& s, double depth, int steps, unsigned degree, int refinement, bool no_slip = true) {
  const auto mesh = meshing::build_axisymmetric_slab_mesh(s, refinement);
  std::vector<LayerMaterial> materials;
  std::vector<LayerCrack> cracks;
  std::vector<FrictionCoefficients> friction;
  for (const Layer& l : s.layers) {
    materials.emplace_back(l.material);
    LayerCrack c;
    c.kind = LayerCrack::Kind::TiedUntilBroken;
    cracks.push_back(c);
    friction.push_back({});
  }
  AxisymmetricSettings settings;
  settings.degree = degree;
  settings.newton_tolerance = 1e-10;
  settings.blunt_tip_no_slip = no_slip;
  AxisymmetricSolver solver(mesh, materials, cracks, friction, settings);
  solver.setup(0.5 * s.sample.diameter_m, s.total_thickness_m());
  for (int k = 1; k <= steps; ++k) {
    solver.set_flat_punch(s.needle.radius_m, -depth * k / steps);
    const auto report = solver.solve_step(k > 1 ? 1.0 : 0.0);
    EXPECT_TRUE(report.converged) << report.failure;
  }
  return {solver.needle_force().total_N, solver.n_dofs()};
}

/// Sneddon's flat punch on an incompressible-ish half-space, F = 2 E a d / (1 - nu^2),
/// times the bottom-effect correction of a layer bonded to a rigid base
/// (Garcia & Garcia 2018, Biophys. J. 114:2923, cylindrical punch, nu = 0.5,
/// with chi = a / h): 1 + 1.133 chi + 1.283 chi^2 + 0.769 chi^3 + 0.0975 chi^4.
double sneddon_bonded_layer(double E, double nu, double a, double h, double depth) {
  const double chi = a / h;
  const double correction = 1 + 1.133 * chi + 1.283 * chi * chi + 0.769 * std::pow(chi, 3) + 0.0975 * std::pow(chi, 4);
  return 2 * E * a * depth / (1 - nu * nu) * correction;
}

}  // namespace

TEST(AxisymmetricSolver, ThickBlockMatchesSneddonFlatPunch) {
  // a = 1 mm, h = 20 mm (chi = 0.05, correction 1.060), R_s = 60 mm,
  // nu = 0.499, indentation 1 % of a (small strain). Punch held laterally
  // (no slip); for nu -> 0.5 the half-space solution is the same with a
  // frictionless punch (Dundurs beta = 0).
  const double a = 1e-3, h = 20e-3, E = 3e4, nu = 0.499, depth = 0.01 * a;
  const Scene s = block_scene(a, h, 60e-3, E, nu, 8);
  const double exact = sneddon_bonded_layer(E, nu, a, h, depth);
  for (unsigned degree : {1u, 2u}) {
    const Indentation q = indent(s, depth, 1, degree, 0);
    EXPECT_NEAR(q.force_N / exact, 1.0, 0.03) << "Q" << degree << " with " << q.dofs << " dofs";
  }
}

TEST(AxisymmetricSolver, ThinBondedLayerMatchesBottomEffectCorrection) {
  // Layer of thickness 2a on a rigid base: F / F_Sneddon about 1.95 for
  // nu -> 0.5 (Garcia & Garcia 2018), within 5 %.
  const double a = 1e-3, h = 2 * a, E = 3e4, nu = 0.499, depth = 0.01 * a;
  Scene s = block_scene(a, h, 30e-3, E, nu, 8);
  s.fem.mesh.min_elements_per_layer = 16;
  const Indentation q = indent(s, depth, 1, 2, 0);
  const double sneddon = 2 * E * a * depth / (1 - nu * nu);
  EXPECT_NEAR(q.force_N / sneddon, 1.95, 0.05 * 1.95) << q.dofs << " dofs";
}
