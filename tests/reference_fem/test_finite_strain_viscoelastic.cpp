// The 3D FiniteStrainSolver with a viscoelastic (Prony) layer, against closed forms.
//
// Simple shear u = gamma(t) Y e_x prescribed on the boundary of a 10 mm cube: the
// solution is homogeneous, J = 1 exactly, and for a neo-Hookean long-term law the first
// Piola shear stress is P_xy = mu gamma (the volumetric pressure p(1) = 0). Summed over
// the nodes of the top plane Y = L, the x-reaction is P_xy L^2 exactly (the sum of their
// shape functions rises linearly across the top layer of elements). With a Prony series
// on the isochoric part (viscoelastic_material.hpp) the reaction is
//   held after a sudden strain:  mu gamma L^2 (1 + sum_i beta_i exp(-t / tau_i)),
// exact for any time step; and, in the small-strain limit, for a ramp gamma = r t up to T
// (linear viscoelasticity, Boltzmann superposition):
//   t <= T:  mu r L^2 (t + sum_i beta_i tau_i (1 - exp(-t / tau_i))),
//   t >  T:  mu r L^2 (T + sum_i beta_i tau_i (exp(-(t - T) / tau_i) - exp(-t / tau_i))),
// which the midpoint rule of the history integral reaches at second order in dt.
#include <deal.II/base/mpi.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/grid/grid_generator.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>
#include <vector>

#include <puncture/fem/finite_strain_solver.hpp>
#include <puncture/fem/hyperelastic_materials.hpp>
#include <puncture/fem/viscoelastic_material.hpp>

using namespace dealii;
using namespace puncture;
using namespace puncture::fem;

namespace {

constexpr double kL = 0.01;       // cube edge, m
constexpr double kE = 3.0e4;      // long-term Young's modulus, Pa
constexpr double kNu = 0.45;
const std::vector<PronyTerm> kTerms = {{0.6, 0.5}, {0.3, 4.0}};  // beta, tau_s

double shear_modulus() { return kE / (2.0 * (1.0 + kNu)); }

/// A cube of 3 x 3 x 3 Q1 three-field cells, one neo-Hookean material with kTerms.
struct ShearedCube {
  parallel::distributed::Triangulation<3> tria{MPI_COMM_WORLD};
  std::unique_ptr<FiniteStrainSolver> solver;
  std::vector<DofPoint> points;
  std::vector<types::global_dof_index> top_x;  // x dofs of the plane Y = L

  explicit ShearedCube(const std::vector<PronyTerm>& terms) {
    GridGenerator::subdivided_hyper_cube(tria, 3, 0.0, kL);
    ContinuumMaterial m;
    m.model = "neo_hookean";
    m.youngs_modulus_Pa = kE;
    m.poisson_ratio = kNu;
    SolverSettings settings;
    settings.newton_tolerance = 1e-10;
    solver = std::make_unique<FiniteStrainSolver>(tria, std::vector<LayerMaterial>{LayerMaterial(m)}, settings);
    solver->set_viscoelastic_layers({terms});
    solver->setup();
    points = solver->locally_relevant_dof_points();
    for (const auto& p : points)
      if (p.component == 0 && p.X[1] > kL - 1e-9) top_x.push_back(p.dof);
  }
  static bool on_boundary(const Point<3>& X) {
    for (unsigned d = 0; d < 3; ++d)
      if (X[d] < 1e-9 || X[d] > kL - 1e-9) return true;
    return false;
  }
  /// Shear gamma on the boundary, one step of dt_s, committed; returns the shear force (N).
  double step(double gamma, double dt_s) {
    std::map<types::global_dof_index, double> targets;
    for (const auto& p : points)
      if (on_boundary(p.X)) targets[p.dof] = p.component == 0 ? gamma * p.X[1] : 0.0;
    solver->set_prescribed_displacements(targets);
    solver->set_time_step(dt_s);
    const NewtonReport r = solver->solve_step();
    EXPECT_TRUE(r.converged) << r.failure;
    solver->commit_time_step();
    return solver->sum_of_residual(top_x);
  }
};

double relaxation_sum(double t_s) {
  double s = 0.0;
  for (const PronyTerm& p : kTerms) s += p.beta * std::exp(-t_s / p.tau_s);
  return s;
}

/// Small-strain ramp-and-hold shear force (N), rate r (1/s) up to T_s.
double ramp_force(double r, double T_s, double t_s) {
  const double mu = shear_modulus();
  if (t_s <= T_s) {
    double s = t_s;
    for (const PronyTerm& p : kTerms) s += p.beta * p.tau_s * (1.0 - std::exp(-t_s / p.tau_s));
    return mu * r * kL * kL * s;
  }
  double s = T_s;
  for (const PronyTerm& p : kTerms)
    s += p.beta * p.tau_s * (std::exp(-(t_s - T_s) / p.tau_s) - std::exp(-t_s / p.tau_s));
  return mu * r * kL * kL * s;
}

/// Largest relative error of the ramp (to T = 1 s, then held to 3 s) in n_ramp steps per second.
double ramp_error(int n_per_s) {
  ShearedCube cube(kTerms);
  const double r = 1e-4, T = 1.0, dt = 1.0 / n_per_s;
  double worst = 0.0;
  for (int k = 1; k <= 3 * n_per_s; ++k) {
    const double t = k * dt;
    const double f = cube.step(r * std::min(t, T), dt);
    const double exact = ramp_force(r, T, t);
    worst = std::max(worst, std::abs(f - exact) / std::abs(exact));
  }
  return worst;
}

}  // namespace

TEST(ViscoelasticSolver, HeldShearRelaxesAsThePronySeriesForAnyTimeStep) {
  ShearedCube cube(kTerms);
  const double gamma = 0.3;  // finite strain: P_xy = mu gamma still holds exactly
  const double f0 = cube.step(gamma, 0.0);  // sudden strain: the instantaneous response
  const double scale = shear_modulus() * gamma * kL * kL;
  EXPECT_NEAR(f0, scale * (1.0 + relaxation_sum(0.0)), 1e-7 * scale);
  double t = 0.0;
  for (const double dt : {0.05, 0.2, 0.2, 1.0, 3.0, 10.0, 50.0}) {  // steps of any length
    t += dt;
    const double f = cube.step(gamma, dt);
    EXPECT_NEAR(f, scale * (1.0 + relaxation_sum(t)), 1e-7 * scale) << "t = " << t << " s";
  }
  // Fully relaxed: the long-term law alone.
  EXPECT_NEAR(cube.step(gamma, 1e3), scale, 1e-7 * scale);
}

TEST(ViscoelasticSolver, RampAndHoldMatchesBoltzmannSuperpositionAtSecondOrder) {
  const double coarse = ramp_error(10), fine = ramp_error(20);
  EXPECT_LT(fine, 2e-3);
  // Halving the step divides the error by about 4 (midpoint rule); strain-nonlinearity
  // (gamma <= 1e-4) is far below.
  EXPECT_GT(coarse / fine, 3.0);
  EXPECT_LT(coarse / fine, 5.0);
}

TEST(ViscoelasticSolver, ASnapshotCarriesTheHistory) {
  ShearedCube cube(kTerms);
  cube.step(0.1, 0.0);
  const auto before = cube.solver->snapshot();
  const double f1 = cube.step(0.1, 1.0);
  cube.step(0.1, 5.0);  // relaxes further
  cube.solver->restore(before);
  EXPECT_DOUBLE_EQ(cube.step(0.1, 1.0), f1);  // the same step from the same past
}

TEST(ViscoelasticSolver, WithoutPronyTermsTheTimeStepChangesNothing) {
  ShearedCube elastic({});
  EXPECT_FALSE(elastic.solver->has_viscoelastic_layers());
  const double f_a = elastic.step(0.2, 0.0), f_b = elastic.step(0.2, 100.0);
  EXPECT_DOUBLE_EQ(f_a, f_b);
  EXPECT_NEAR(f_a, shear_modulus() * 0.2 * kL * kL, 1e-7 * f_a);
}

TEST(ViscoelasticSolver, RefusesBadSeriesAndLateLayers) {
  parallel::distributed::Triangulation<3> tria(MPI_COMM_WORLD);
  GridGenerator::hyper_cube(tria, 0.0, kL);
  ContinuumMaterial m;
  m.model = "neo_hookean";
  m.youngs_modulus_Pa = kE;
  m.poisson_ratio = kNu;
  FiniteStrainSolver solver(tria, {LayerMaterial(m)}, SolverSettings{});
  EXPECT_THROW(solver.set_viscoelastic_layers({}), std::invalid_argument);             // one per material
  EXPECT_THROW(solver.set_viscoelastic_layers({{{-0.1, 1.0}}}), std::invalid_argument);  // beta < 0
  EXPECT_THROW(solver.set_viscoelastic_layers({{{0.1, 0.0}}}), std::invalid_argument);   // tau = 0
  solver.setup();
  EXPECT_THROW(solver.set_viscoelastic_layers({kTerms}), std::logic_error);
  EXPECT_THROW(solver.set_time_step(-1.0), std::invalid_argument);
  EXPECT_THROW(solver.set_time_step(std::nan("")), std::invalid_argument);
}
