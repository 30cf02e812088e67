// layer_acceptance: the per-layer acceptance of a tuned preset, read from the
// whole-trajectory comparison.
#include <gtest/gtest.h>

#include <cmath>

#include "puncture/validation/acceptance.hpp"

using namespace puncture::validation;

namespace {

ObjectiveTerm term(const std::string& name, const std::string& layer, bool available, double value, double raw,
                   std::size_t samples, const std::string& note = "") {
  ObjectiveTerm t;
  t.name = name, t.layer = layer, t.available = available, t.value = value, t.raw = raw, t.samples = samples,
  t.note = note;
  return t;
}

}  // namespace

TEST(LayerAcceptance, CombinesPressingAndCutAndChecksEachCriterion) {
  const std::vector<LayerGeometry> layers = {{"skin", 0.0, 0.8e-3, 2e-3}, {"fat", 0.8e-3, 8e-3, 2e-3},
                                             {"muscle", 8.8e-3, 20e-3, 2.5e-3}};
  TrajectoryComparison c;
  c.reference_peak_force_N = 4.0;
  c.terms = {term("overall", "", true, 0.05, 0.2, 100),
             term("pressing", "skin", true, 0.08, 0.32, 10),
             term("after_puncture", "skin", true, 0.12, 0.48, 30),
             term("puncture_depth", "skin", true, 0.5, 1e-3, 1),
             term("puncture_force", "skin", true, -0.05, -0.1, 1),
             term("pressing", "fat", false, 0, 0, 0, "no pressing segment"),
             term("after_puncture", "fat", true, 0.04, 0.16, 5),
             term("puncture_depth", "fat", true, -1.5, -3e-3, 1),
             term("puncture_force", "fat", true, 0.099, 0.2, 1),
             term("pressing", "muscle", true, 0.02, 0.08, 4),
             term("after_puncture", "muscle", true, 0.03, 0.12, 6),
             term("puncture_depth", "muscle", false, 0, 0, 0, "the model does not puncture"),
             term("puncture_force", "muscle", false, 0, 0, 0, "the model does not puncture"),
             term("withdrawal", "", false, 0, 0, 0, "the reference has no withdrawal")};
  const auto a = layer_acceptance(layers, c);
  ASSERT_EQ(a.size(), 3u);
  // skin: sqrt((10 x 0.08^2 + 30 x 0.12^2) / 40) = 0.1114 > 10 %: not met; depth 1 mm <= L; force 5 %.
  EXPECT_NEAR(a[0].force_rmse.value, std::sqrt((10 * 0.0064 + 30 * 0.0144) / 40), 1e-12);
  EXPECT_EQ(a[0].rmse_samples, 40u);
  EXPECT_FALSE(a[0].force_rmse.met);
  EXPECT_TRUE(a[0].puncture_depth.met);
  EXPECT_TRUE(a[0].puncture_force.met);
  EXPECT_FALSE(a[0].accepted());
  // fat: only the cut (pressing n/a, said so); depth 3 mm > L = 2 mm.
  EXPECT_NEAR(a[1].force_rmse.value, 0.04, 1e-12);
  EXPECT_NE(a[1].force_rmse.note.find("no pressing segment"), std::string::npos);
  EXPECT_FALSE(a[1].puncture_depth.met);
  EXPECT_TRUE(a[1].puncture_force.met);
  // muscle: a puncture the model misses is not met, and says why.
  EXPECT_TRUE(a[2].force_rmse.met);
  EXPECT_FALSE(a[2].puncture_depth.available);
  EXPECT_FALSE(a[2].puncture_depth.met);
  EXPECT_NE(a[2].puncture_force.note.find("does not puncture"), std::string::npos);
  EXPECT_FALSE(a[2].accepted());

  const std::string md = acceptance_markdown(a, c);
  EXPECT_NE(md.find("**not met**"), std::string::npos);
  EXPECT_NE(md.find("| withdrawal | n/a |"), std::string::npos) << md;
  EXPECT_EQ(md.find("| withdrawal | 0"), std::string::npos);
}

TEST(LayerAcceptance, AModelWithinEveryLimitIsAccepted) {
  const std::vector<LayerGeometry> layers = {{"skin", 0.0, 1e-3, 2e-3}};
  TrajectoryComparison c;
  c.terms = {term("pressing", "skin", true, 0.09, 0.36, 3), term("after_puncture", "skin", true, 0.09, 0.36, 3),
             term("puncture_depth", "skin", true, 1.0, -2e-3, 1), term("puncture_force", "skin", true, -0.1, -0.2, 1)};
  const auto a = layer_acceptance(layers, c);
  EXPECT_TRUE(a[0].accepted());  // depth and force exactly at their limits
  AcceptanceCriteria strict;
  strict.max_rmse_relative = 0.05;
  EXPECT_FALSE(layer_acceptance(layers, c, strict)[0].accepted());
}

TEST(LayerAcceptance, SurfaceDeflectionBeforeAndAfterTheBreakIsPartOfIt) {
  // A layer within every force limit; then its surface judged too: 10 %
  // before the break (limit 15 %) and 30 % after it (limit 25 %) fails it,
  // 20 % after passes; a layer without an FEM surface is not accepted and says why.
  const std::vector<LayerGeometry> layers = {{"skin", 0.0, 1e-3, 2e-3}, {"fat", 1e-3, 8e-3, 1e-3}};
  TrajectoryComparison c;
  for (const char* l : {"skin", "fat"})
    for (const ObjectiveTerm& t : {term("pressing", l, true, 0.05, 0.1, 3), term("after_puncture", l, true, 0.05, 0.1, 3),
                                   term("puncture_depth", l, true, 0.1, 1e-4, 1), term("puncture_force", l, true, 0.02, 0.05, 1)})
      c.terms.push_back(t);
  std::vector<LayerAcceptance> a = layer_acceptance(layers, c);
  ASSERT_TRUE(a[0].accepted() && a[1].accepted());
  std::vector<LayerDeflectionErrors> errors(2);
  errors[0] = {true, true, 0.10, 0.30, ""};
  errors[1].note = "no FEM profile of this layer's top surface";
  add_deflection_acceptance(a, errors);
  EXPECT_TRUE(a[0].deflection.met);
  EXPECT_FALSE(a[0].recovery.met);
  EXPECT_FALSE(a[0].accepted());
  EXPECT_FALSE(a[1].deflection.available);
  EXPECT_FALSE(a[1].accepted());
  errors[0].after_relative = 0.20;
  add_deflection_acceptance(a, errors);
  EXPECT_TRUE(a[0].accepted());
  const std::string md = acceptance_markdown(a, c);
  EXPECT_NE(md.find("after the break (limit 25 %)"), std::string::npos) << md;
  EXPECT_NE(md.find("n/a: no FEM profile"), std::string::npos) << md;
  EXPECT_THROW(add_deflection_acceptance(a, {}), std::invalid_argument);
}
