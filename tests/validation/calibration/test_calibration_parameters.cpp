// The parameter table (calibration_parameters.hpp): the rupture release
// length is never shorter than the haptic ticks resolve; a layer whose force
// mesh the surface fit identified keeps K and the stiffening, the others tune
// them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "calibration_parameters.hpp"
#include "puncture/scene_io.hpp"

namespace pc = puncture::validation::calibration_detail;
using puncture::Scene;

namespace {

Scene default_scene() {
  return puncture::load_scene(std::filesystem::path(PUNCTURE_SOURCE_DIR) / "scenes" / "default_force_law.json");
}

/// exp(-tick / l): the share of the release R the force keeps on the tick after a break.
double kept_after_one_tick(const Scene& s, double l_m) {
  return std::exp(-s.insertion.speed_m_per_s / s.realtime.haptic_rate_Hz / l_m);
}

}  // namespace

TEST(CalibrationParameters, TheRuptureReleaseSpansAtLeastFiveHapticTicksAndATenthOfAMillimetre) {
  Scene s = default_scene();
  ASSERT_DOUBLE_EQ(s.realtime.haptic_rate_Hz, 1000.0);
  ASSERT_DOUBLE_EQ(s.insertion.speed_m_per_s, 0.01);
  double lo = 0.0, hi = 0.0;
  pc::physical_range(s, 0, pc::ParamKind::RuptureRelease, lo, hi);
  EXPECT_DOUBLE_EQ(lo, 1e-4);  // 5 ticks at 10 mm/s are 50 um: the floor holds
  EXPECT_DOUBLE_EQ(hi, 0.05);
  // At the floor the tick after the break keeps over 90 % of R at 10 mm/s and
  // over 80 % at 20 mm/s, where 10 um kept 37 % (a drop set by the tick).
  EXPECT_GT(kept_after_one_tick(s, lo), 0.9);
  EXPECT_LT(kept_after_one_tick(s, 1e-5), 0.37);

  // A fast scene: 100 mm/s at 1 kHz is 0.1 mm per tick, so 5 ticks are 0.5 mm.
  s.insertion.speed_m_per_s = 0.1;
  pc::physical_range(s, 0, pc::ParamKind::RuptureRelease, lo, hi);
  EXPECT_NEAR(lo, 5e-4, 1e-15);
  EXPECT_GT(kept_after_one_tick(s, lo), 0.8);

  // A start below the floor (the earlier bound, 10 um) is moved onto it, and said so.
  s = default_scene();
  s.layers[0].force_law.rupture_release_m = 1e-5;
  bool moved = false;
  const pc::Parameter p = pc::make_parameter(s, 0, pc::ParamKind::RuptureRelease, 1000.0, moved);
  EXPECT_TRUE(moved);
  EXPECT_DOUBLE_EQ(p.value_lo, 1e-4);
  EXPECT_DOUBLE_EQ(p.lower, std::log(1e-4));
}

TEST(CalibrationParameters, OnlyTheLayersWhoseMeshWasIdentifiedKeepKAndTheStiffening) {
  const Scene s = default_scene();
  ASSERT_TRUE(s.effects.surface_force && s.effects.stiffening);
  puncture::validation::TunedParameterSet t;
  t.mesh_identified_layers = {"skin"};  // the surface fit identified the skin only
  const auto has = [](const std::vector<pc::ParamKind>& kinds, pc::ParamKind k) {
    return std::find(kinds.begin(), kinds.end(), k) != kinds.end();
  };
  const std::vector<pc::ParamKind> skin = pc::layer_kinds(s, 0, t), muscle = pc::layer_kinds(s, 2, t);
  EXPECT_FALSE(has(skin, pc::ParamKind::VirtualStiffness));
  EXPECT_FALSE(has(skin, pc::ParamKind::StiffeningQuadratic) || has(skin, pc::ParamKind::StiffeningExponential));
  EXPECT_TRUE(has(skin, pc::ParamKind::CriticalForce));
  EXPECT_TRUE(has(muscle, pc::ParamKind::VirtualStiffness));
  EXPECT_TRUE(has(muscle, pc::ParamKind::StiffeningQuadratic) || has(muscle, pc::ParamKind::StiffeningExponential));
}

TEST(CalibrationParameters, AValueAtItsUpperBoundIsTheBoundExactlyAndTheSceneStaysValid) {
  // exp(ln 0.05) rounds above 0.05 m: the fat's release length at its upper
  // bound (a slab of the slab rule's family) failed the scene's limit of 50 mm.
  Scene s = default_scene();
  bool moved = false;
  const pc::Parameter p = pc::make_parameter(s, 1, pc::ParamKind::RuptureRelease, 1000.0, moved);
  ASSERT_TRUE(p.log_space);
  EXPECT_LE(p.value_of(p.upper), p.value_hi);  // never above by rounding
  EXPECT_NEAR(p.value_of(p.upper), p.value_hi, 1e-12 * p.value_hi);
  EXPECT_GE(p.value_of(p.lower), p.value_lo);
  EXPECT_EQ(p.value_of(p.upper + 1.0), p.value_hi);  // nor beyond
  EXPECT_EQ(p.value_of(p.lower - 1.0), p.value_lo);
  pc::set_param(s, p, p.value_of(p.upper));
  EXPECT_NO_THROW(puncture::validate_scene(s, "test"));
}
