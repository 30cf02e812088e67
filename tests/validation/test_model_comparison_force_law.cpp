// The real-time model inside `puncture compare` is the model of the haptic
// tick with the scene's whole force law: its contact force plus the shaft
// forces the comparison harness adds for every model (cutting, Karnopp
// friction, d h v, from the layer states) must give the tick's own total
// force, computed independently by PunctureSimulator (run_scripted_insertion).
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

  // The harness sees layer states only: on the tick at which the needle
  // touches the next layer (its contact is set, its deflection still 0, so
  // its state is still Untouched) it keeps the cutting force one tick longer
  // than the simulator. Every other tick must agree to rounding.
  auto contact_tick = [&](std::size_t i) {
    const TickResult& t = tick_run.ticks[i];
    std::size_t k = 0;
    while (k < t.layers.size() && t.layers[k].state == LayerState::Punctured) ++k;
    return k > 0 && k < t.layers.size() && t.layers[k].state == LayerState::Untouched && t.cutting_force_N == 0.0 &&
           i + 1 < tick_run.ticks.size() && tick_run.ticks[i + 1].layers[k].state != LayerState::Untouched;
  };
  double shaft_peak = 0.0;
  std::size_t differing = 0, contact_ticks = 0;
  for (std::size_t i = 0; i < run.steps(); ++i) {
    const TickResult& t = tick_run.ticks[i];
    ASSERT_EQ(run.contact_force_N[i], t.tip_force_N) << "step " << i;
    const double total = run.contact_force_N[i] + run.post_puncture_force_N[i];
    shaft_peak = std::max(shaft_peak, std::abs(t.cutting_force_N + t.friction_force_N));
    if (std::abs(total - t.total_force_N) <= 1e-9 * (1.0 + std::abs(t.total_force_N))) continue;
    if (contact_tick(i)) {
      ++contact_ticks;
      continue;
    }
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
  EXPECT_LT(contact_ticks, scene.layers.size());  // at most one per layer below the skin
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

TEST(ComparisonRealtimeModel, ContactPlusShaftForcesIsTheTickTotalWithoutCutting) {
  Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  scene.effects.cutting = false;
  expect_same_total(scene);
}
