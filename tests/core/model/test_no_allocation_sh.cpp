// The haptic tick on the SH layer surfaces allocates nothing, also when an
// off-axis needle makes the simulator lay the force meshes again at the
// contact point (LayerSurface::project and intersect_ray inside the tick)
// and with every force-law effect on. Same allocation counter as
// tests/core/test_no_allocation.cpp (tests/core/allocation_counter.hpp,
// linked into this suite's executable too; it works under AddressSanitizer).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../allocation_counter.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/needle.hpp"
#include "puncture/scene_io.hpp"

using namespace puncture;

TEST(NoAllocationSh, OffAxisInsertionOnShSurfacesWithEveryEffectAllocatesNothing) {
  Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  scene.realtime.sh_degree = 8;
  scene.effects.stiffening = scene.effects.layer_interaction = true;
  for (Layer& l : scene.layers) {
    l.force_law.breakthrough.kind = BreakthroughCriterion::Kind::CriticalForce;
    l.force_law.breakthrough.critical_force_N = 1.0;
    l.force_law.stiffening.quadratic_N_per_m2 = 2e4;
  }
  scene.layers[0].force_mesh.virtual_stiffness_N_per_m = 2000.0;
  RealtimeModel model = build_realtime_model(scene);
  const ScriptedTrajectory tr(scene.insertion);
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  std::vector<NeedleState> states;
  for (int i = 0; i * dt <= tr.duration(); ++i) {
    states.push_back(tr.sample(i * dt));
    states.back().tip_position_m.x() += 3e-3;  // off the scene axis
  }
  double sum = 0.0;
  test::start_counting_allocations();
  for (const NeedleState& s : states) sum += model.simulator->tick(s).total_force_N;
  EXPECT_EQ(test::stop_counting_allocations(), 0);
  EXPECT_TRUE(std::isfinite(sum));
  EXPECT_GE(model.simulator->puncture_events().size(), 2u);
  // The meshes were laid where the off-axis needle met each surface.
  for (std::size_t k = 0; k < model.simulator->puncture_events().size(); ++k)
    EXPECT_NEAR(model.simulator->force_mesh(k)->rest_positions()(0, 0), 3e-3, 1e-9) << k;
}

TEST(NoAllocationSh, TunedPresetOffAxisInsertionAllocatesNothing) {
  // The committed tuned preset: stiffening skin and muscle meshes (a Newton
  // solve in every tick that presses them), laid again off the axis.
  const Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/results/tuned_preset/default_tuned.json");
  RealtimeModel model = build_realtime_model(scene);
  ASSERT_TRUE(scene.layers[0].force_mesh.nonlinear() && scene.layers[2].force_mesh.nonlinear());
  const ScriptedTrajectory tr(scene.insertion);
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  std::vector<NeedleState> states;
  for (int i = 0; i * dt <= tr.duration(); ++i) {
    states.push_back(tr.sample(i * dt));
    states.back().tip_position_m.x() += 3e-3;
  }
  double sum = 0.0;
  int newton_ticks = 0;
  test::start_counting_allocations();
  for (const NeedleState& s : states) {
    sum += model.simulator->tick(s).total_force_N;
    if (model.simulator->force_mesh(0)->last_newton_iterations() > 0) ++newton_ticks;
  }
  EXPECT_EQ(test::stop_counting_allocations(), 0);
  EXPECT_TRUE(std::isfinite(sum));
  EXPECT_EQ(model.simulator->puncture_events().size(), 3u);
  EXPECT_GT(newton_ticks, 100);
  EXPECT_NEAR(model.simulator->force_mesh(2)->rest_positions()(0, 0), 3e-3, 1e-9);
}

TEST(ContactPointSh, OffAxisMeshIsProjectedOntoTheShSurfaceOverTicks) {
  // An off-axis needle on the fitted SH surfaces: the skin's mesh is laid in
  // the tangent plane at the contact at once, its nodes are projected onto
  // the surface kLayoutNodesPerTick per tick, and the force does not depend
  // on it (the same as on the axis, the top face being flat to the fit error).
  Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  scene.realtime.sh_degree = 12;
  RealtimeModel on = build_realtime_model(scene), off = build_realtime_model(scene);
  const ScriptedTrajectory tr(scene.insertion);
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  const int nodes = off.simulator->force_mesh(0)->node_count();
  int contact_tick = -1, complete_tick = -1;
  for (int i = 0; i * dt <= 0.40; ++i) {
    NeedleState s = tr.sample(i * dt);
    const double f_on = on.simulator->tick(s).total_force_N;
    s.tip_position_m.x() += 5e-3;
    s.tip_position_m.y() -= 2e-3;
    const double f_off = off.simulator->tick(s).total_force_N;
    // The two contacts lie on the fitted surface at different places: their
    // heights differ by at most twice the top face's fit error.
    const double tolerance = 2.0 * off.fits[0].top_face_max_error_m * off.simulator->force_mesh(0)->static_stiffness_N_per_m();
    EXPECT_NEAR(f_off, f_on, tolerance + 1e-12) << "tick " << i;
    if (contact_tick < 0 && off.simulator->has_contact(0)) contact_tick = i;
    if (contact_tick >= 0 && complete_tick < 0 && !off.simulator->force_mesh(0)->layout_pending()) complete_tick = i;
  }
  ASSERT_GE(contact_tick, 0);
  ASSERT_GE(complete_tick, 0);
  EXPECT_LE(complete_tick - contact_tick, (nodes - 1 + kLayoutNodesPerTick - 1) / kLayoutNodesPerTick + 1);
  const ForceMesh& mesh = *off.simulator->force_mesh(0);
  const LayerSurface& surface = *off.surfaces[0];
  EXPECT_NEAR(mesh.rest_positions()(0, 0), 5e-3, 1e-9);
  for (int i = 0; i < mesh.node_count(); ++i) {
    const SurfacePoint p = surface.project(mesh.rest_positions().col(i));
    EXPECT_LT((p.position - mesh.rest_positions().col(i)).norm(), 1e-12) << i;
    EXPECT_LT((p.normal - mesh.normals().col(i)).norm(), 1e-9) << i;
  }
}
