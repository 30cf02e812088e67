// compare_layer_deflection after a breakthrough: the real-time surface is
// taken when its resumption is done, or just before the next layer breaks if
// that comes first (the FEM's profile after a break is taken before the next
// layer breaks).
#include <gtest/gtest.h>

#include <cmath>

#include "../core/table2_scene.hpp"
#include "../core/thin_over_thick_scene.hpp"
#include "puncture/needle.hpp"
#include "puncture/simulator.hpp"
#include "puncture/validation/fem_comparison.hpp"

using namespace puncture;
using namespace puncture::validation;

namespace {

struct Recorded {
  ScriptedRunResult run;
  RingRecorder recorder;
};

/// 10 mm/s down from 0.5 mm above the first surface, 1 ms ticks, every tick recorded.
Recorded descend(const Scene& scene, int ticks) {
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  Recorded r{{}, RingRecorder(scene)};
  for (const NeedleState& n : test::descent(ticks)) {
    r.run.ticks.push_back(sim.tick(n));
    r.recorder.record(sim);
  }
  return r;
}

FemResultFiles fem_after_break_of_a() {
  FemResultFiles fem;
  RadialProfile after;
  after.depth_m = 1.5e-3;
  for (int i = 0; i <= 20; ++i) {
    after.r_m.push_back(i * 0.5e-3);
    after.uz_m.push_back(-0.5e-3 * std::exp(-i * 0.1));
  }
  fem.after_breakthrough["a"] = after;
  return fem;
}

std::size_t first_punctured(const ScriptedRunResult& run, std::size_t k) {
  for (std::size_t i = 0; i < run.ticks.size(); ++i)
    if (run.ticks[i].layers[k].state == LayerState::Punctured) return i;
  return run.ticks.size();
}

}  // namespace

TEST(RecoveryComparison, TakenWhenTheResumptionIsDoneIfTheNextLayerHolds) {
  const Scene scene = test::thin_over_thick(false, 1e3);
  const Recorded r = descend(scene, 400);
  const std::size_t broke = first_punctured(r.run, 0);
  ASSERT_LT(broke, r.run.ticks.size());
  ASSERT_EQ(first_punctured(r.run, 1), r.run.ticks.size());  // "b" never breaks
  const LayerDeflectionComparison c = compare_layer_deflection(scene, 0, r.run, r.recorder, fem_after_break_of_a());
  ASSERT_TRUE(c.recovery_compared);
  EXPECT_NEAR(c.recovery_delay_s, 0.02, 1e-12);
  EXPECT_DOUBLE_EQ(c.recovery_realtime_depth_m, r.run.ticks[broke + 20].depth_m);
}

TEST(RecoveryComparison, TakenBeforeTheNextLayerBreaksIfThatComesFirst) {
  const Scene scene = test::thin_over_thick(false, 0.05);  // "b" breaks a few ticks after "a"
  const Recorded r = descend(scene, 400);
  const std::size_t broke = first_punctured(r.run, 0), next = first_punctured(r.run, 1);
  ASSERT_LT(broke, next);
  ASSERT_LT(next, broke + 20);  // within the resumption time
  const LayerDeflectionComparison c = compare_layer_deflection(scene, 0, r.run, r.recorder, fem_after_break_of_a());
  ASSERT_TRUE(c.recovery_compared);
  EXPECT_NEAR(c.recovery_delay_s, r.run.ticks[next - 1].time_s - r.run.ticks[broke].time_s, 1e-12);
  EXPECT_LT(c.recovery_delay_s, 0.02);
  EXPECT_DOUBLE_EQ(c.recovery_realtime_depth_m, r.run.ticks[next - 1].depth_m);
  EXPECT_EQ(c.realtime_recovered_rings_m, r.recorder.rings(next - 1, 0));
}
