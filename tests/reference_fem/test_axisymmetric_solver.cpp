// Axisymmetric solver against closed forms: the flat punch on a thick block
// (Sneddon 1965 with the bonded-layer bottom-effect correction) and on a thin
// bonded layer (Garcia & Garcia 2018). (No patch test here: the solver holds
// the base and the lateral ring fixed and takes no other boundary data, so no
// non-trivial homogeneous deformation satisfies its boundary conditions; the
// 3D solver's patch test is in test_materials_and_solver.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

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
  std::vector<double> solution;  ///< the nodal displacements at the end (m)
};

/// Flat-punch indentation to `depth` in `steps` equal steps.
Indentation indent(const Scene& s, double depth, int steps, unsigned degree, int refinement, bool no_slip = true,
                   unsigned threads = 1) {
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
  settings.assembly_threads = threads;
  AxisymmetricSolver solver(mesh, materials, cracks, friction, settings);
  solver.setup(0.5 * s.sample.diameter_m, s.total_thickness_m());
  for (int k = 1; k <= steps; ++k) {
    solver.set_flat_punch(s.needle.radius_m, -depth * k / steps);
    const auto report = solver.solve_step(k > 1 ? 1.0 : 0.0);
    EXPECT_TRUE(report.converged) << report.failure;
  }
  return {solver.needle_force().total_N, solver.n_dofs(),
          std::vector<double>(solver.solution().begin(), solver.solution().end())};
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

TEST(AxisymmetricSolver, AnyNumberOfAssemblyThreadsGivesTheSameSolutionBitForBit) {
  // Cells are evaluated on threads and added in cell order, and their geometry
  // is computed once in cell order: 1, 2, 3 and 5 threads must give the same
  // bits (a per-thread FEValues reusing mapping data from the previous similar
  // cell of its own range did not). Uniform cells along the punch path make
  // long runs of translated cells.
  const double a = 1e-3, h = 6e-3, E = 3e4, nu = 0.45, depth = 0.3 * a;
  Scene s = block_scene(a, h, 12e-3, E, nu, 4);
  s.fem.mesh.radial_growth = 1.0;
  const Indentation one = indent(s, depth, 3, 1, 0, true, 1);
  for (unsigned threads : {2u, 3u, 5u}) {
    const Indentation many = indent(s, depth, 3, 1, 0, true, threads);
    EXPECT_EQ(many.force_N, one.force_N) << threads << " threads";
    ASSERT_EQ(many.solution.size(), one.solution.size());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < one.solution.size(); ++i) differing += many.solution[i] != one.solution[i] ? 1 : 0;
    EXPECT_EQ(differing, 0u) << threads << " threads: displacements that differ from 1 thread's";
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

namespace {

/// Flat punch pressed suddenly (one step of 1e-6 s) to `depth` and held,
/// with hold steps doubling from 0.01 s to t_end: the punch force at each
/// time (s, N). Prony series per layer (empty: elastic); no viscous
/// stabilisation (it would resist the sudden step).
std::vector<std::pair<double, double>> indent_and_hold(const Scene& s, double depth,
                                                       const std::vector<std::vector<PronyTerm>>& prony,
                                                       double t_end) {
  const auto mesh = meshing::build_axisymmetric_slab_mesh(s, 0);
  std::vector<LayerMaterial> materials;
  std::vector<LayerCrack> cracks(s.layers.size());
  for (LayerCrack& c : cracks) c.kind = LayerCrack::Kind::TiedUntilBroken;
  for (const Layer& l : s.layers) materials.emplace_back(l.material);
  AxisymmetricSettings settings;
  settings.newton_tolerance = 1e-10;
  settings.stabilization_time_s = 0.0;
  AxisymmetricSolver solver(mesh, materials, cracks, std::vector<FrictionCoefficients>(s.layers.size()), settings);
  solver.set_viscoelasticity(prony);
  solver.setup(0.5 * s.sample.diameter_m, s.total_thickness_m());
  std::vector<std::pair<double, double>> out;
  solver.set_flat_punch(s.needle.radius_m, -depth);
  solver.set_time_step(1e-6);
  double t = 1e-6;
  for (double dt = 0.01;; dt *= 2.0) {
    const auto report = solver.solve_step();
    EXPECT_TRUE(report.converged) << report.failure << " at t = " << t;
    out.emplace_back(t, solver.needle_force().total_N);
    if (t >= t_end) break;
    solver.set_time_step(dt);
    t += dt;
  }
  return out;
}

}  // namespace

TEST(AxisymmetricSolver, ViscoelasticBlockRelaxesAsItsPronySeries) {
  // Thick nearly incompressible block (as the Sneddon test), long-term
  // E = 30 kPa, two Prony terms (beta 1.0 at 0.2 s, 0.5 at 3 s). At small
  // strain the held punch force of an incompressible solid is proportional to
  // the shear relaxation function (correspondence principle), so
  // F(t) / F(0+) = g(t) = (1 + sum beta_i exp(-t/tau_i)) / (1 + sum beta_i);
  // the bulk stays elastic, so with nu = 0.499 within 2 % of g(0+) - g(inf).
  // Fully relaxed, the force is the elastic long-term block's, and at 0+ it
  // is (1 + sum beta_i) times it (Sneddon's force is proportional to mu).
  const double a = 1e-3, h = 20e-3, E = 3e4, nu = 0.499, depth = 0.01 * a;
  const Scene s = block_scene(a, h, 60e-3, E, nu, 4);
  const std::vector<PronyTerm> terms{{1.0, 0.2}, {0.5, 3.0}};
  const auto held = indent_and_hold(s, depth, {terms}, 100.0);
  const auto elastic = indent_and_hold(s, depth, {{}}, 0.01);
  const double F0 = held.front().second, F_long = elastic.back().second;
  const double factor = 1.0 + 1.0 + 0.5;
  EXPECT_NEAR(F0 / F_long, factor, 0.02 * factor);
  for (const auto& [t, F] : held) {
    const double g = (1.0 + 1.0 * std::exp(-t / 0.2) + 0.5 * std::exp(-t / 3.0)) / factor;
    EXPECT_NEAR(F / F0, g, 0.02 * (1.0 - 1.0 / factor)) << "t = " << t << " s";
  }
  EXPECT_NEAR(held.back().second / F_long, 1.0, 1e-3) << "fully relaxed: the long-term elastic block";
  // An elastic layer (no Prony terms) does not relax.
  const auto elastic_held = indent_and_hold(s, depth, {{}}, 10.0);
  EXPECT_NEAR(elastic_held.back().second / elastic_held.front().second, 1.0, 1e-9);
}
