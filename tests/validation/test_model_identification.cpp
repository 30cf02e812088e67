// A comparison model's stiffness factors and critical forces identified at a
// reference: the reference is the BEM itself with known factors (skin x 2,
// fat x 0.5, muscle x 1.5) and known critical forces. The muscle, pressed on
// the rigid base alone, has a force proportional to its modulus: its factor
// is found exactly. The skin and fat are identified while the layers below
// are still at factor 1, so theirs compensate; the force while each is
// pressed must then match the reference's (the BEM's force is linear in the
// indentation, so one factor can match it exactly). The critical forces are
// the reference's within one step of needle travel, and the identified model
// punctures where the reference does. A layer the reference does not puncture
// is not identified.
#include <gtest/gtest.h>

#include <cmath>

#include "puncture/comparison/model_factory.hpp"
#include "puncture/comparison/surface_models.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/model_comparison.hpp"
#include "puncture/validation/model_identification.hpp"
#include "puncture/validation/puncture_events.hpp"

using namespace puncture;

namespace {

Scene default_scene() { return load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json"); }

/// The default scene's BEM with these factors, breaking each layer when its
/// force reaches the force of an indentation of indentation_m[k] (a value
/// above the trajectory's reach: never), and its run as a reference curve.
struct Reference {
  Scene scene;
  std::vector<double> forces;
  validation::ModelRun run;
  validation::ReferenceData data;
};
Reference reference_of(const std::vector<double>& scale, const std::vector<double>& indentation_m) {
  Reference r{default_scene(), {}, {}, {}};
  r.scene.comparison.stiffness_scale = scale;
  const comparison::BoundaryElementModel scaled(r.scene);
  for (std::size_t k = 0; k < indentation_m.size(); ++k) {
    r.forces.push_back(scaled.stiffness_N_per_m(k) * indentation_m[k]);
    r.scene.layers[k].force_law.breakthrough.kind = BreakthroughCriterion::Kind::CriticalForce;
    r.scene.layers[k].force_law.breakthrough.critical_force_N = r.forces.back();
  }
  auto bem = comparison::make_comparison_model("bem", r.scene, nullptr);
  r.run = validation::run_comparison_model(*bem, r.scene);
  r.data.curve = validation::curve_from_model_run(r.scene, r.run, false);
  return r;
}

double first_puncture_depth(const validation::ModelRun& run, std::size_t k) {
  for (std::size_t i = 0; i < run.steps(); ++i)
    if (run.states[i][k] == LayerState::Punctured) return run.depth_m[i];
  return -1.0;
}

/// The curve without the loading samples strictly between from_m and to_m
/// but the last one before to_m (a reference sampled too coarsely there).
validation::InsertionCurve thinned(const validation::InsertionCurve& c, double from_m, double to_m) {
  validation::InsertionCurve t = c;
  std::vector<std::size_t> keep;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const bool inside = c.velocity_m_per_s[i] > 0.0 && c.depth_m[i] > from_m && c.depth_m[i] < to_m;
    const bool last_inside = inside && i + 1 < c.size() && c.depth_m[i + 1] >= to_m;
    if (!inside || last_inside) keep.push_back(i);
  }
  auto pick = [&](auto& v, const auto& from) {
    if (from.empty()) return;
    v.clear();
    for (std::size_t i : keep) v.push_back(from[i]);
  };
  pick(t.time_s, c.time_s), pick(t.depth_m, c.depth_m), pick(t.velocity_m_per_s, c.velocity_m_per_s);
  pick(t.force_N, c.force_N), pick(t.phase, c.phase);
  pick(t.tip_force_N, c.tip_force_N), pick(t.cutting_force_N, c.cutting_force_N);
  pick(t.friction_force_N, c.friction_force_N);
  for (std::size_t k = 0; k < c.layer_states.size(); ++k) pick(t.layer_states[k], c.layer_states[k]);
  return t;
}

TEST(ModelIdentification, LinearModelRecoversTheFactorsAndForcesOfAReferenceMadeByItself) {
  const std::vector<double> scale{2.0, 0.5, 1.5};
  const Reference reference = reference_of(scale, {4e-3, 3e-3, 5e-3});
  const std::vector<double>& forces = reference.forces;
  const Scene scene = default_scene();
  const validation::ModelIdentification id =
      validation::identify_comparison_model("bem", scene, nullptr, reference.data, true);
  ASSERT_EQ(id.layers.size(), 3u);
  EXPECT_GE(id.model_runs, 6);  // two partial runs per layer and the optimiser's
  const comparison::BoundaryElementModel unit(scene);
  for (std::size_t k = 0; k < 3; ++k) {
    const validation::LayerIdentification& l = id.layers[k];
    ASSERT_TRUE(l.identified) << l.layer << ": " << l.note;
    EXPECT_NEAR(l.reference_depth_m, first_puncture_depth(reference.run, k), 1e-12) << l.layer;
    EXPECT_GT(l.window_samples, 10u) << l.layer;
    EXPECT_TRUE(l.stiffness_note.empty()) << l.stiffness_note;
    if (k == 2) EXPECT_NEAR(l.stiffness_scale, scale[k], 1e-6 * scale[k]);
    EXPECT_LT(l.window_rmse_after_N, 0.02 * l.window_rmse_before_N) << l.layer;
    // The reference breaks on the first step with F >= F_k; the identified
    // force is the model's on that step: F_k <= F <= F_k + s S 10 um (to the
    // fit's accuracy).
    EXPECT_GE(l.critical_force_N, 0.99 * forces[k]) << l.layer;
    EXPECT_LE(l.critical_force_N, 1.01 * forces[k] + 4.0 * unit.stiffness_N_per_m(k) * 1.1e-5) << l.layer;
  }
  const Scene identified = validation::with_identified_parameters(scene, id);
  auto model = comparison::make_comparison_model("bem", identified, nullptr);
  const validation::ModelRun run = validation::run_comparison_model(*model, identified);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(identified.layers[k].force_law.breakthrough.kind, BreakthroughCriterion::Kind::CriticalForce);
    EXPECT_NEAR(first_puncture_depth(run, k), first_puncture_depth(reference.run, k), 1.1e-5) << k;
  }
  // The identified scene is a valid scene file.
  EXPECT_NO_THROW(parse_scene(scene_to_json_text(identified), "identified"));
}

TEST(ModelIdentification, CriticalForcesOnlyKeepTheModuli) {
  const Reference reference = reference_of({2.0, 1.0, 1.0}, {4e-3, 3e-3, 5e-3});
  const validation::ModelIdentification id =
      validation::identify_comparison_model("shf", default_scene(), nullptr, reference.data, false);
  EXPECT_EQ(id.model_runs, 3);
  for (const validation::LayerIdentification& l : id.layers) {
    EXPECT_TRUE(l.identified) << l.layer;
    EXPECT_EQ(l.stiffness_scale, 1.0);
  }
}

TEST(ModelIdentification, ALayerTheReferenceDoesNotPunctureIsNotIdentified) {
  const Reference reference = reference_of({1.0, 1.0, 1.0}, {4e-3, 1.0, 1.0});  // only the skin breaks
  const Scene scene = default_scene();
  const validation::ModelIdentification id =
      validation::identify_comparison_model("shf", scene, nullptr, reference.data, true);
  ASSERT_GE(id.layers.size(), 2u);
  EXPECT_TRUE(id.layers[0].identified);
  EXPECT_FALSE(id.layers[1].identified);
  EXPECT_FALSE(id.layers[1].note.empty());
  const Scene identified = validation::with_identified_parameters(scene, id);
  EXPECT_EQ(identified.layers[1].force_law.breakthrough.kind, scene.layers[1].force_law.breakthrough.kind);
  EXPECT_EQ(identified.comparison.stiffness_scale[1], 1.0);
}

TEST(ModelIdentification, ALayerWithFewerThanTwoReferenceSamplesWhilePressedIsNotRunForItsFactor) {
  // The reference sampled only once while it presses the fat: the fat's
  // factor stays 1 and no run is spent on it (the start run and the
  // optimiser's runs of the full reference), its window RMSE is not a number
  // (not fitted, not "0"), and its critical force is still identified.
  const Reference full = reference_of({2.0, 0.5, 1.5}, {4e-3, 3e-3, 5e-3});
  const Scene scene = default_scene();
  const validation::ModelIdentification all =
      validation::identify_comparison_model("bem", scene, nullptr, full.data, true);
  validation::ReferenceData coarse = full.data;
  // (The skin's puncture sample goes too: the fat is pressed from it on, by
  // the curve's states, so the reference's skin breaks on the one sample kept.)
  coarse.curve =
      thinned(full.data.curve, first_puncture_depth(full.run, 0) - 1e-9, first_puncture_depth(full.run, 1));
  ASSERT_LT(coarse.curve.size(), full.data.curve.size());
  const validation::ModelIdentification id =
      validation::identify_comparison_model("bem", scene, nullptr, coarse, true);
  ASSERT_EQ(id.layers.size(), 3u);
  const validation::LayerIdentification& fat = id.layers[1];
  EXPECT_TRUE(fat.identified) << fat.note;
  EXPECT_LT(fat.window_samples, 2u);
  EXPECT_EQ(fat.stiffness_scale, 1.0);
  EXPECT_FALSE(std::isfinite(fat.window_rmse_before_N));
  EXPECT_FALSE(std::isfinite(fat.window_rmse_after_N));
  EXPECT_NEAR(fat.reference_depth_m, first_puncture_depth(full.run, 1), 1e-12);
  EXPECT_GT(all.layers[1].window_samples, 10u);
  EXPECT_NE(all.layers[1].stiffness_scale, 1.0);
  // The fat's start run and its optimiser runs (at least two) are saved.
  EXPECT_LE(id.model_runs + 2, all.model_runs);
  // The other layers are fitted as before.
  EXPECT_NEAR(id.layers[2].stiffness_scale, all.layers[2].stiffness_scale, 1e-9);
  EXPECT_GT(id.layers[0].window_samples, 10u);
}

TEST(ModelIdentification, ALayerPressedWhileTheTipForceStaysPositiveIsFittedOnItsPressedStates) {
  // The FEM's curve: its tip force stays positive after the fat's break (the
  // needle presses on through the cut fat), so the cut through the fat has
  // no end by the force's parts and layer_segments gives the muscle no
  // pressing window before its puncture; its state column says where the
  // muscle is pressed. The reference here is the BEM with those parts: the
  // whole force on the tip.
  // The fat breaks below its undeformed bottom (9.2 mm), as the FEM's does:
  // its cut then reaches to the muscle's puncture by the layers' geometry.
  const std::vector<double> scale{2.0, 0.5, 1.5};
  Reference reference = reference_of(scale, {4e-3, 6e-3, 5e-3});
  ASSERT_GT(first_puncture_depth(reference.run, 1), 9.2e-3);
  validation::InsertionCurve& curve = reference.data.curve;
  ASSERT_TRUE(curve.has_layer_states());
  curve.tip_force_N = curve.force_N;
  for (double& f : curve.tip_force_N) f = std::max(f, 1e-3);  // never back to 0 after a break
  curve.cutting_force_N.assign(curve.size(), 0.0);
  curve.friction_force_N.assign(curve.size(), 0.0);
  const Scene scene = default_scene();
  const std::vector<validation::LayerSegments> segments = validation::layer_segments(
      validation::reference_events(curve, validation::layer_geometry(scene)), validation::layer_geometry(scene));
  ASSERT_LE(segments[2].pressing_from_m, segments[2].pressing_to_m);
  ASSERT_GE(segments[2].pressing_from_m, first_puncture_depth(reference.run, 2) - 1e-12)
      << "the segments give the muscle no window: the case this test is about";
  const validation::ModelIdentification id =
      validation::identify_comparison_model("bem", scene, nullptr, reference.data, true);
  ASSERT_EQ(id.layers.size(), 3u);
  const validation::LayerIdentification& muscle = id.layers[2];
  EXPECT_GT(muscle.window_samples, 10u);
  EXPECT_NEAR(muscle.stiffness_scale, scale[2], 1e-6 * scale[2]);  // pressed on the rigid base alone: exact
}

TEST(ModelIdentification, AForceDropAtOneDepthIsLeftOutOfTheWindow) {
  // A quasi-static reference records a break as two samples at one depth
  // (before and after the drop), the second with the next layer pressed; the
  // model's force at that depth is on either side of its own drop, so both
  // are left out. Here the sample after the drop carries a wild force: the
  // fat's factor is the one found without it.
  const Reference reference = reference_of({2.0, 0.5, 1.5}, {4e-3, 3e-3, 5e-3});
  const Scene scene = default_scene();
  const validation::ModelIdentification clean =
      validation::identify_comparison_model("bem", scene, nullptr, reference.data, true);
  validation::ReferenceData dropped = reference.data;
  validation::InsertionCurve& c = dropped.curve;
  const int fat = c.layer_index("fat");
  ASSERT_GE(fat, 0);
  std::size_t i = 0;
  while (i < c.size() && c.layer_states[static_cast<std::size_t>(fat)][i] != LayerState::Pressed) ++i;
  ASSERT_LT(i, c.size());
  auto duplicate = [&](auto& v) {
    if (!v.empty()) v.insert(v.begin() + static_cast<std::ptrdiff_t>(i), v[i]);
  };
  duplicate(c.time_s), duplicate(c.depth_m), duplicate(c.velocity_m_per_s), duplicate(c.force_N), duplicate(c.phase);
  duplicate(c.tip_force_N), duplicate(c.cutting_force_N), duplicate(c.friction_force_N);
  for (auto& states : c.layer_states) duplicate(states);
  c.force_N[i + 1] = 100.0;  // the second sample at that depth
  const validation::ModelIdentification id =
      validation::identify_comparison_model("bem", scene, nullptr, dropped, true);
  ASSERT_EQ(id.layers.size(), 3u);
  EXPECT_EQ(id.layers[1].window_samples + 1, clean.layers[1].window_samples);  // sample i left out with its twin
  EXPECT_NEAR(id.layers[1].stiffness_scale, clean.layers[1].stiffness_scale, 1e-3 * clean.layers[1].stiffness_scale);
}

TEST(ModelIdentification, ALayerBrokenOnTheStepThatBreaksTheLayerAboveEndsItBeforeAnyRunBelow) {
  // The fat punctured on the sample that punctures the skin (the default
  // slab's FEM does this): the reference never presses the fat, so it has no
  // critical force to identify and the muscle below would be fitted for
  // nothing. No run reaches below the skin's puncture, the skin is identified
  // as with the muscle unfitted, and the fat's note gives the reason.
  const Reference reference = reference_of({2.0, 0.5, 1.5}, {4e-3, 3e-3, 5e-3});
  validation::ReferenceData same_step = reference.data;
  validation::InsertionCurve& c = same_step.curve;
  const auto skin = static_cast<std::size_t>(c.layer_index("skin"));
  const auto fat = static_cast<std::size_t>(c.layer_index("fat"));
  std::size_t i = 0;
  while (i < c.size() && c.layer_states[skin][i] != LayerState::Punctured) ++i;
  ASSERT_LT(i, c.size());
  for (std::size_t j = i; j < c.size(); ++j) c.layer_states[fat][j] = LayerState::Punctured;
  const Scene scene = default_scene();
  std::vector<std::string> lines;
  const validation::ModelIdentification id = validation::identify_comparison_model(
      "bem", scene, nullptr, same_step, true, [&](const std::string& line) { lines.push_back(line); });
  ASSERT_EQ(id.layers.size(), 2u);
  EXPECT_TRUE(id.layers[0].identified) << id.layers[0].note;
  EXPECT_FALSE(id.layers[1].identified);
  EXPECT_NE(id.layers[1].note.find("on the haptic step that punctures skin"), std::string::npos) << id.layers[1].note;
  EXPECT_TRUE(id.joint_note.empty()) << id.joint_note;  // one factor fitted: no joint step
  for (const std::string& line : lines)
    EXPECT_EQ(line.rfind("skin", 0), 0u) << "a run for another layer: " << line;
  // The skin's window and force are those of the reference: its factor is
  // fitted with the layers below at factor 1, as the identified scene has them.
  const Scene identified = validation::with_identified_parameters(scene, id);
  EXPECT_EQ(identified.comparison.stiffness_scale[1], 1.0);
  EXPECT_EQ(identified.comparison.stiffness_scale[2], 1.0);
  EXPECT_LT(id.layers[0].window_rmse_after_N, 0.5 * id.layers[0].window_rmse_before_N);
}

/// The two window costs in a "not needed" joint-fit note ("... cost A together, B in their own fits ...").
std::pair<double, double> uncoupled_costs(const std::string& note) {
  const std::size_t cost = note.find(" cost ");
  const std::size_t together = note.find(" together, ", cost);
  const std::size_t own = note.find(" in their own fits", together);
  if (cost == std::string::npos || together == std::string::npos || own == std::string::npos) return {-1.0, -1.0};
  return {std::stod(note.substr(cost + 6, together - cost - 6)), std::stod(note.substr(together + 11, own - together - 11))};
}

TEST(ModelIdentification, TheJointFitStopsAtItsStartWhereTheWindowsAreUncoupled) {
  // After the bottom-up pass the fitted factors are fitted again jointly only
  // when a window moved with the other layers' factors. In the BEM a layer's
  // pressing sees the layers below it, never the broken ones above, so the
  // bottom-up pass is already the joint optimum: one run confirms it, on the
  // BEM's own reference (exact factors) and on one whose skin stiffens with
  // depth (force x (1 + 200 depth/m)), which no skin factor matches. (The
  // volumetric models, whose skin rests on the fat, are coupled:
  // tests/meshing/tet/test_joint_identification.cpp.)
  const std::vector<double> scale{2.0, 0.5, 1.5};
  Reference reference = reference_of(scale, {4e-3, 3e-3, 5e-3});
  const Scene scene = default_scene();
  const validation::ModelIdentification exact =
      validation::identify_comparison_model("bem", scene, nullptr, reference.data, true);
  EXPECT_NE(exact.joint_note.find("not needed"), std::string::npos) << exact.joint_note;
  const auto [exact_together, exact_own] = uncoupled_costs(exact.joint_note);
  EXPECT_GE(exact_together, 0.0) << exact.joint_note;
  EXPECT_LE(exact_together, 1.01 * exact_own + 1e-12) << exact.joint_note;
  EXPECT_NEAR(exact.layers[2].stiffness_scale, scale[2], 1e-3 * scale[2]) << exact.joint_note;

  validation::InsertionCurve& c = reference.data.curve;
  const int skin = c.layer_index("skin");
  for (std::size_t i = 0; i < c.size(); ++i)
    if (c.layer_states[static_cast<std::size_t>(skin)][i] == LayerState::Pressed)
      c.force_N[i] *= 1.0 + 200.0 * c.depth_m[i];  // another shape: no skin factor alone matches it
  const validation::ModelIdentification stiffening =
      validation::identify_comparison_model("bem", scene, nullptr, reference.data, true);
  const auto [together, own] = uncoupled_costs(stiffening.joint_note);
  ASSERT_GT(own, 0.0) << stiffening.joint_note;  // the skin's misfit
  EXPECT_NEAR(together, own, 1e-9 * own) << stiffening.joint_note;
  for (const validation::LayerIdentification& l : stiffening.layers) EXPECT_TRUE(l.identified) << l.layer;
}

TEST(ModelIdentification, AFactorStoppedByTheSearchsBoundIsMarked) {
  // Within a factor 1.1 of 1000 or of 1/1000, and nowhere else.
  EXPECT_TRUE(validation::near_stiffness_scale_bound(973.2));
  EXPECT_TRUE(validation::near_stiffness_scale_bound(910.0));
  EXPECT_FALSE(validation::near_stiffness_scale_bound(909.0));
  EXPECT_TRUE(validation::near_stiffness_scale_bound(1.05e-3));
  EXPECT_FALSE(validation::near_stiffness_scale_bound(1.2e-3));
  EXPECT_FALSE(validation::near_stiffness_scale_bound(1.0));
  EXPECT_FALSE(validation::near_stiffness_scale_bound(0.0));
  // A reference whose muscle is 3000 times the scene's: the fit ends at the
  // bound and says so; the skin's and fat's factors (2 and 0.5) are not marked.
  const Reference reference = reference_of({2.0, 0.5, 3000.0}, {4e-3, 3e-3, 5e-3});
  const validation::ModelIdentification id =
      validation::identify_comparison_model("bem", default_scene(), nullptr, reference.data, true);
  ASSERT_EQ(id.layers.size(), 3u);
  ASSERT_TRUE(id.layers[2].identified) << id.layers[2].note;
  EXPECT_NEAR(id.layers[2].stiffness_scale, validation::kStiffnessScaleBound, 1e-6 * validation::kStiffnessScaleBound);
  EXPECT_TRUE(id.layers[2].stiffness_scale_near_bound());
  for (std::size_t k = 0; k < 2; ++k) {
    ASSERT_TRUE(id.layers[k].identified) << id.layers[k].note;
    EXPECT_FALSE(id.layers[k].stiffness_scale_near_bound()) << id.layers[k].layer << " x " << id.layers[k].stiffness_scale;
  }
}

}  // namespace
