// The haptic tick does no heap allocation: every allocation of the process
// is counted (allocation_counter.hpp: counting operator new and malloc, or
// AddressSanitizer's allocation hook in a sanitizer build) and must stay at
// zero over many ticks of the Table 2 scene with every effect on, for each
// integrator.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "allocation_counter.hpp"
#include "puncture/simulator.hpp"
#include "table2_scene.hpp"

using namespace puncture;

TEST(NoAllocation, CounterSeesAnAllocation) {
  // The instrument works (with and without AddressSanitizer): operator new
  // (the vector object and its buffer) and malloc (Eigen's buffer) are counted.
  test::start_counting_allocations();
  auto* v = new std::vector<int>(10);
  const long after_new = test::stop_counting_allocations();
  test::start_counting_allocations();
  Eigen::VectorXd e(100);
  const long after_eigen = test::stop_counting_allocations();
  delete v;
  EXPECT_EQ(after_new, 2) << (test::allocation_count_from_sanitizer() ? "ASan hook" : "interposed malloc/new");
  EXPECT_GE(after_eigen, 1);
  e.setZero();
}

class NoAllocationTick : public ::testing::TestWithParam<const char*> {};

namespace {

/// The scene's scripted insertion, one state per 1 ms tick, sampled outside
/// the counted region (NeedleState is plain data).
std::vector<NeedleState> scripted_states(const Scene& scene) {
  const ScriptedTrajectory tr(scene.insertion);
  const int ticks = static_cast<int>(tr.duration() / 1e-3);
  std::vector<NeedleState> states;
  states.reserve(ticks);
  for (int i = 0; i < ticks; ++i) states.push_back(tr.sample(i * 1e-3));
  return states;
}

/// Ticks the whole insertion while counting allocations; returns their count.
long allocations_over_insertion(PunctureSimulator& sim, const std::vector<NeedleState>& states) {
  double sum = 0.0;
  test::start_counting_allocations();
  for (const NeedleState& s : states) sum += sim.tick(s).total_force_N;
  const long count = test::stop_counting_allocations();
  EXPECT_TRUE(std::isfinite(sum));
  return count;
}

}  // namespace

TEST_P(NoAllocationTick, FullInsertionAllocatesNothing) {
  Scene scene = test::table2_scene(GetParam());
  ASSERT_TRUE(scene.effects.surface_force && scene.effects.damping && scene.effects.resumption);
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  EXPECT_EQ(allocations_over_insertion(sim, scripted_states(scene)), 0) << GetParam();
  EXPECT_EQ(sim.puncture_events().size(), 3u);  // the counted ticks did the whole job
}

INSTANTIATE_TEST_SUITE_P(Integrators, NoAllocationTick, ::testing::Values("quasi_static", "explicit", "implicit"));

// Every force-law effect on (layer interaction, cutting, Karnopp friction
// whose contact pressure relaxes, with a tau short enough that every tick
// pushes a pass-time entry, tip stiffening, critical-force and
// critical-energy breakthrough) and the
// needle off the scene axis, so that the force meshes are laid out again at
// the contact point inside the counted ticks.
TEST_P(NoAllocationTick, EveryForceLawEffectOffAxisAllocatesNothing) {
  Scene scene = test::table2_scene(GetParam());
  scene.effects.layer_interaction = scene.effects.cutting = scene.effects.friction = scene.effects.stiffening = true;
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    ForceLaw& law = scene.layers[k].force_law;
    law.breakthrough.kind = k == 1 ? BreakthroughCriterion::Kind::CriticalEnergy : BreakthroughCriterion::Kind::CriticalForce;
    law.breakthrough.critical_force_N = 0.6;
    law.breakthrough.critical_energy_J = 0.2e-3;
    law.cutting_force_N = 0.3;
    law.friction.dynamic_N_per_m = law.friction.static_N_per_m = 10.0;
    law.friction.pressure_relaxes_with_material = true;
    scene.layers[k].material.viscoelastic.terms = {{0.5, 0.02}};  // merge window 0.2 ms < the 1 ms tick
    law.stiffening.quadratic_N_per_m2 = 2e4;
  }
  scene.layers[0].force_mesh.virtual_stiffness_N_per_m = 2000.0;
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  const ScriptedTrajectory tr(scene.insertion);
  const int ticks = static_cast<int>(tr.duration() / 1e-3);
  std::vector<NeedleState> states;
  states.reserve(ticks);
  for (int i = 0; i < ticks; ++i) {
    states.push_back(tr.sample(i * 1e-3));
    states.back().tip_position_m.x() += 2e-3;
    states.back().tip_position_m.y() -= 1e-3;
  }

  double sum = 0.0, cutting = 0.0, friction = 0.0;
  test::start_counting_allocations();
  for (const NeedleState& s : states) {
    const TickResult& r = sim.tick(s);
    sum += r.total_force_N;
    cutting += r.cutting_force_N;
    friction += std::abs(r.friction_force_N);
  }
  EXPECT_EQ(test::stop_counting_allocations(), 0) << GetParam();
  EXPECT_TRUE(std::isfinite(sum));
  EXPECT_EQ(sim.puncture_events().size(), 3u);
  EXPECT_GT(cutting, 0.0);
  EXPECT_GT(friction, 0.0);
  ASSERT_NE(sim.shaft_contact_pressure(2), nullptr);
  EXPECT_TRUE(sim.shaft_contact_pressure(2)->relaxes());
  EXPECT_NEAR(sim.force_mesh(0)->rest_positions()(0, 0), 2e-3, 1e-15);  // laid where the needle touched
  EXPECT_NEAR(sim.force_mesh(2)->rest_positions()(1, 0), -1e-3, 1e-15);
}

// Stiffening in the force meshes (Newton on the fixed-pattern tangent every tick).
TEST_P(NoAllocationTick, StiffeningMeshesAllocateNothing) {
  Scene scene = test::table2_scene(GetParam());
  for (Layer& layer : scene.layers) {
    layer.force_mesh.surface_axial_stiffness_N_per_m = 300.0;
    layer.force_mesh.virtual_stiffening_m = 2e-3;
  }
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  EXPECT_EQ(allocations_over_insertion(sim, scripted_states(scene)), 0) << GetParam();
  EXPECT_EQ(sim.puncture_events().size(), 3u);
}
