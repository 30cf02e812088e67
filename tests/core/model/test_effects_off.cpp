// Effects that a scene switches off are not built (DESIGN.md, user demand 3):
// the default scene (scenes/default.json, SH degree from the scene) is
// modified effect by effect, assembled with build_realtime_model and driven
// along its scripted insertion. Off means: no force mesh / no resumption
// object exists, and the corresponding force is exactly 0.0 on every tick.
// With every effect on, the objects exist and the forces are non-zero where
// the physics says they must be; the damping force is checked against the
// closed form of Table 1, d h v with h = clamp(depth - top, 0, thickness).
// (What an effect costs in time is measured in tests/benchmarks/bench_effects.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "puncture/model/realtime_model.hpp"
#include "puncture/scene_io.hpp"

namespace puncture {
namespace {

Scene default_scene() { return load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json"); }

/// The paper's three tick effects as given; the force-law effects (cutting,
/// friction, stiffening, layer interaction) off unless asked for.
Scene scene_with_effects(bool surface_force, bool damping, bool resumption, bool cutting = false,
                         bool friction = false) {
  Scene s = default_scene();
  s.effects.surface_force = surface_force;
  s.effects.damping = damping;
  s.effects.resumption = resumption;
  s.effects.cutting = cutting;
  s.effects.friction = friction;
  s.effects.stiffening = false;
  s.effects.layer_interaction = false;
  validate_scene(s, "test_effects_off");
  return s;
}

/// Nodes of a hexagonal ring mesh with w rings: 1 + sum_{j=2..w} 6 (j - 1).
int hex_node_count(int w) { return 1 + 3 * w * (w - 1); }

/// Table 1 damping of one punctured layer, computed here from the scene.
double expected_damping_N(const Scene& s, std::size_t k, double depth_m, double velocity_m_per_s) {
  const double top = s.layer_top_depth_m(k);
  const double h = std::clamp(depth_m - top, 0.0, s.layers[k].thickness_m);
  return s.layers[k].damping_N_s_per_m2 * h * velocity_m_per_s;
}

TEST(EffectsOff, DefaultSceneHasEveryTickEffectOn) {
  // The other tests switch effects off relative to this.
  const Scene s = default_scene();
  EXPECT_TRUE(s.effects.surface_force);
  EXPECT_TRUE(s.effects.damping);
  EXPECT_TRUE(s.effects.resumption);
  EXPECT_TRUE(s.effects.cutting);
  EXPECT_TRUE(s.effects.friction);
}

TEST(EffectsOff, AllOnBuildsEveryForceMeshAndResumption) {
  const Scene s = scene_with_effects(true, true, true);
  RealtimeModel m = build_realtime_model(s);
  const PunctureSimulator& sim = *m.simulator;
  ASSERT_EQ(sim.layer_count(), s.layers.size());
  for (std::size_t k = 0; k < sim.layer_count(); ++k) {
    ASSERT_NE(sim.force_mesh(k), nullptr) << s.layers[k].name;
    EXPECT_EQ(sim.force_mesh(k)->node_count(), hex_node_count(s.layers[k].force_mesh.rings_w));
    EXPECT_EQ(sim.node_rest_positions(k).cols(), hex_node_count(s.layers[k].force_mesh.rings_w));
    ASSERT_NE(sim.resumption(k), nullptr) << s.layers[k].name;
    EXPECT_FALSE(sim.resumption(k)->active());  // nothing broke yet
  }

  const ScriptedRunResult run = run_scripted_insertion(m, s);
  ASSERT_GE(run.events.size(), 1u) << "the default scene must puncture at least the skin";
  double max_surface_force_N = 0.0;
  bool damping_seen = false;
  for (const TickResult& t : run.ticks)
    for (std::size_t k = 0; k < t.layers.size(); ++k) {
      const LayerTickResult& l = t.layers[k];
      if (l.state == LayerState::Pressed) max_surface_force_N = std::max(max_surface_force_N, l.surface_force_N);
      if (l.state == LayerState::Punctured) {
        const double expected = expected_damping_N(s, k, t.depth_m, t.velocity_m_per_s);
        EXPECT_NEAR(l.damping_force_N, expected, 1e-12 + 1e-12 * std::abs(expected));
        if (t.velocity_m_per_s > 0.0 && l.damping_force_N > 0.0) damping_seen = true;
      }
    }
  // Pressing the skin before it breaks takes a positive surface force.
  EXPECT_GT(max_surface_force_N, 0.0);
  EXPECT_TRUE(damping_seen);
  // The skin broke: its resumption was started.
  EXPECT_TRUE(m.simulator->resumption(0)->active());
  EXPECT_LT(m.simulator->resumption(0)->recovery_factor(), 1.0);
}

TEST(EffectsOff, SurfaceForceOffBuildsNoForceMeshAndGivesZeroSurfaceForce) {
  // Resumption stays requested: it needs a force mesh, so it is not built either.
  const Scene s = scene_with_effects(false, true, true);
  RealtimeModel m = build_realtime_model(s);
  const PunctureSimulator& sim = *m.simulator;
  for (std::size_t k = 0; k < sim.layer_count(); ++k) {
    EXPECT_EQ(sim.force_mesh(k), nullptr) << s.layers[k].name;
    EXPECT_EQ(sim.resumption(k), nullptr) << s.layers[k].name;
    EXPECT_EQ(sim.node_rest_positions(k).cols(), 0);
    EXPECT_TRUE(sim.node_rings(k).empty());
  }
  EXPECT_EQ(sim.mesh_energy_J(), 0.0);

  const ScriptedRunResult run = run_scripted_insertion(m, s);
  for (const TickResult& t : run.ticks) {
    double damping_sum_N = 0.0;
    for (const LayerTickResult& l : t.layers) {
      EXPECT_EQ(l.surface_force_N, 0.0);
      EXPECT_EQ(l.deformed_rings, 0);
      damping_sum_N += l.damping_force_N;
    }
    EXPECT_EQ(t.total_force_N, damping_sum_N);
  }
  for (std::size_t k = 0; k < sim.layer_count(); ++k) EXPECT_EQ(sim.force_mesh(k), nullptr);
  // Without a force mesh every layer the needle reaches breaks at its surface;
  // the 30 mm insertion reaches all three.
  const double target = s.insertion.target_depth_m;
  std::size_t reachable = 0;
  for (std::size_t k = 0; k < s.layers.size(); ++k)
    if (s.layer_top_depth_m(k) < target) ++reachable;
  EXPECT_EQ(run.events.size(), reachable);
  for (const PunctureEvent& e : run.events) {
    EXPECT_EQ(e.surface_force_N, 0.0);
    // At most one haptic step of travel past the fitted layer top (which is
    // off the exact plane by at most the fit's top-face error).
    const std::size_t k = static_cast<std::size_t>(e.layer);
    EXPECT_LE(e.depth_m - s.layer_top_depth_m(k),
              s.insertion.speed_m_per_s / s.realtime.haptic_rate_Hz + m.fits[k].top_face_max_error_m + 1e-12);
  }
}

TEST(EffectsOff, ResumptionOffBuildsNoResumptionButKeepsTheForceMeshes) {
  const Scene s = scene_with_effects(true, true, false);
  RealtimeModel m = build_realtime_model(s);
  const PunctureSimulator& sim = *m.simulator;
  for (std::size_t k = 0; k < sim.layer_count(); ++k) {
    EXPECT_NE(sim.force_mesh(k), nullptr) << s.layers[k].name;
    EXPECT_EQ(sim.resumption(k), nullptr) << s.layers[k].name;
  }
  const ScriptedRunResult run = run_scripted_insertion(m, s);
  ASSERT_GE(run.events.size(), 1u);
  for (std::size_t k = 0; k < sim.layer_count(); ++k) EXPECT_EQ(sim.resumption(k), nullptr);
  // A broken layer without resumption keeps reporting the force mesh's own
  // nodes (no shape-matching positions exist).
  EXPECT_EQ(&sim.node_positions(0), &sim.force_mesh(0)->positions());
}

TEST(EffectsOff, DampingOffGivesExactlyZeroDampingInPuncturedLayers) {
  const Scene s = scene_with_effects(true, false, true);
  RealtimeModel m = build_realtime_model(s);
  EXPECT_NE(m.simulator->force_mesh(0), nullptr);
  const ScriptedRunResult run = run_scripted_insertion(m, s);
  ASSERT_GE(run.events.size(), 1u);
  long punctured_moving_ticks = 0;
  for (const TickResult& t : run.ticks) {
    double surface_sum_N = 0.0;
    for (std::size_t k = 0; k < t.layers.size(); ++k) {
      const LayerTickResult& l = t.layers[k];
      surface_sum_N += l.surface_force_N;
      if (l.state != LayerState::Punctured) continue;
      EXPECT_EQ(l.damping_force_N, 0.0);
      // With damping on, this tick would have had a non-zero d h v.
      if (expected_damping_N(s, k, t.depth_m, t.velocity_m_per_s) != 0.0) ++punctured_moving_ticks;
    }
    EXPECT_EQ(t.total_force_N, surface_sum_N);
  }
  // The check above ran on ticks where damping would have acted.
  EXPECT_GT(punctured_moving_ticks, 0);
}

TEST(EffectsOff, AllOffBuildsNothingAndGivesZeroForce) {
  const Scene s = scene_with_effects(false, false, false);
  RealtimeModel m = build_realtime_model(s);
  const PunctureSimulator& sim = *m.simulator;
  for (std::size_t k = 0; k < sim.layer_count(); ++k) {
    EXPECT_EQ(sim.force_mesh(k), nullptr);
    EXPECT_EQ(sim.resumption(k), nullptr);
  }
  const ScriptedRunResult run = run_scripted_insertion(m, s);
  EXPECT_FALSE(run.events.empty());
  for (const TickResult& t : run.ticks) EXPECT_EQ(t.total_force_N, 0.0);
}

TEST(EffectsOff, CuttingAndFrictionOffGiveExactlyZeroAndBuildNoFriction) {
  // Off: no Karnopp state exists and the cutting and friction forces are
  // exactly 0 on every tick; on: both act after the punctures (cutting while
  // the tip advances a crack, friction growing with the shaft length) and
  // the friction reverses on withdrawal.
  for (bool on : {false, true}) {
    const Scene s = scene_with_effects(true, true, true, on, on);
    RealtimeModel m = build_realtime_model(s);
    for (std::size_t k = 0; k < s.layers.size(); ++k) EXPECT_EQ(m.simulator->friction(k) != nullptr, on);
    const ScriptedRunResult run = run_scripted_insertion(m, s);
    ASSERT_EQ(run.events.size(), 3u);
    double max_cutting = 0.0, min_friction = 0.0, max_friction = 0.0;
    std::vector<double> layer_cutting(s.layers.size(), 0.0);
    for (const TickResult& t : run.ticks) {
      double friction = 0.0, cutting = 0.0;
      for (const LayerTickResult& l : t.layers) friction += l.friction_force_N, cutting += l.cutting_force_N;
      for (std::size_t k = 0; k < s.layers.size(); ++k)
        layer_cutting[k] = std::max(layer_cutting[k], t.layers[k].cutting_force_N);
      // The layers' crack forces, less the bevel's part the tick counts as tip force (cutting.hpp).
      EXPECT_NEAR(t.cutting_force_N + (t.tip_force_N - t.surface_force_N), cutting, 1e-12);
      max_cutting = std::max(max_cutting, cutting);
      min_friction = std::min(min_friction, friction);
      max_friction = std::max(max_friction, friction);
      if (!on) EXPECT_EQ(cutting, 0.0);
      if (!on) EXPECT_EQ(friction, 0.0);
      double parts = t.tip_force_N + t.cutting_force_N + t.friction_force_N;
      EXPECT_NEAR(t.total_force_N, parts, 1e-12);
    }
    if (on) {
      // Every layer cuts with its scene value: the skin breaks below the
      // fat's rest surface, so the fat is pressed from the tip at once and
      // the tip cuts the squeezed skin meanwhile; the fat breaks above the
      // muscle and is cut until the muscle is touched; then the muscle.
      EXPECT_GT(run.events[0].depth_m, s.layer_top_depth_m(1));
      EXPECT_LT(run.events[1].depth_m, s.layer_top_depth_m(2));
      for (std::size_t k = 0; k < 3; ++k)
        EXPECT_NEAR(layer_cutting[k], s.layers[k].force_law.cutting_force_N, 1e-12) << s.layers[k].name;
      EXPECT_NEAR(max_cutting, s.layers[0].force_law.cutting_force_N, 1e-12);  // the skin's is the largest
      // Friction at the deepest point: f_d x shaft length in tissue (30 mm at 0.01 N/mm).
      EXPECT_NEAR(max_friction, 0.01e3 * s.insertion.target_depth_m, 1e-9);
      EXPECT_NEAR(min_friction, -max_friction, 1e-5);  // reversed on withdrawal
    }
  }
}

}  // namespace
}  // namespace puncture
