// The real-time model inside `puncture compare` is the model of the haptic
// tick with the scene's whole force law: its contact force plus the shaft
// forces the comparison harness adds for every model (through the tick's own
// rule, shaft_forces.hpp, fed with the model's layer states, contacts and
// crack fronts) must give the total force PunctureSimulator computes.
#include <gtest/gtest.h>

#include <cmath>

#include "puncture/comparison/model_factory.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/model_comparison.hpp"

using namespace puncture;

namespace {

void expect_same_total(const Scene& scene) {
  RealtimeModel offline = build_realtime_model(scene);
  const ScriptedRunResult tick_run = run_scripted_insertion(offline, scene);

  auto model = comparison::make_comparison_model("realtime", scene, nullptr);
  const validation::ModelRun run = validation::run_comparison_model(*model, scene);
  ASSERT_FALSE(run.failed()) << run.failure;
  ASSERT_EQ(run.steps(), tick_run.ticks.size());

  // The harness calls the tick's shaft-force rule (shaft_forces.hpp) with the
  // model's layer states and contacts: every tick must agree to rounding.
  double shaft_peak = 0.0;
  std::size_t differing = 0;
  for (std::size_t i = 0; i < run.steps(); ++i) {
    const TickResult& t = tick_run.ticks[i];
    ASSERT_EQ(run.contact_force_N[i], t.surface_force_N) << "step " << i;
    const double total = run.contact_force_N[i] + run.post_puncture_force_N[i];
    shaft_peak = std::max(shaft_peak, std::abs(t.cutting_force_N + t.friction_force_N));
    if (std::abs(total - t.total_force_N) <= 1e-9 * (1.0 + std::abs(t.total_force_N))) continue;
    if (differing++ < 5) {
      std::string states;
      for (const LayerTickResult& l : t.layers) states += std::string(" ") + to_string(l.state);
      ADD_FAILURE() << "step " << i << " depth " << t.depth_m * 1e3 << " mm v " << t.velocity_m_per_s
                    << ": harness " << total << " N, tick " << t.total_force_N << " N (cutting " << t.cutting_force_N
                    << " N), states" << states;
    }
  }
  EXPECT_GT(shaft_peak, 0.0) << "the scene has no shaft force: the comparison tests nothing";
  EXPECT_EQ(differing, 0u);
}

}  // namespace

TEST(ComparisonRealtimeModel, ContactPlusShaftForcesIsTheTickTotalOfTheDefaultScene) {
  Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  ASSERT_TRUE(scene.effects.cutting && scene.effects.friction && scene.effects.damping);
  expect_same_total(scene);
}

TEST(ComparisonRealtimeModel, ContactPlusShaftForcesIsTheTickTotalWithPreslidingAndStiffening) {
  // The physical force law of scenes/default_force_law.json: critical-force
  // breakthrough, stiffening, presliding friction (phi follows the shaft
  // travel), every layer broken below the next one's rest surface or cut.
  Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default_force_law.json");
  ASSERT_GT(scene.layers[0].force_law.friction.presliding_m, 0.0);
  ASSERT_TRUE(scene.effects.stiffening);
  expect_same_total(scene);
}

TEST(ComparisonRealtimeModel, ContactPlusShaftForcesIsTheTickTotalWithTheRateLawsOfCuttingAndRelease) {
  // The rate laws of cutting.hpp on: the bevel's part of the crack force is
  // tip force in the tick, cutting in the harness; the total must agree.
  Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default_force_law.json");
  for (Layer& l : scene.layers) {
    l.force_law.cutting_rate.viscous_fraction = 0.4;
    l.force_law.rupture_release_rate.exponent = 0.5;
  }
  scene.insertion.speed_m_per_s = 0.015;  // away from v_ref
  expect_same_total(scene);
}

TEST(ComparisonRealtimeModel, ContactPlusShaftForcesIsTheTickTotalWithoutCutting) {
  Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  scene.effects.cutting = false;
  expect_same_total(scene);
}
