// run_comparison_model's record of a volumetric model's inverted tetrahedra
// (ModelRun::inverted_elements_max and the rest): a scripted model whose
// inverted count rises and falls with the step index is sampled every
// kInversionSampleSteps steps and at the last; the run keeps the most, the
// needle depth of the first inverted sample and the smallest volume ratio,
// only when asked, and nothing for a model without a tetrahedral mesh.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "puncture/comparison/comparison_model.hpp"
#include "puncture/needle.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/model_comparison.hpp"

using namespace puncture;

namespace {

/// A model that pushes nothing and reports, at step i, 1000 tetrahedra of
/// which inverted(i) are inside out (none without a mesh).
class ScriptedInversionModel final : public comparison::ComparisonModel {
 public:
  explicit ScriptedInversionModel(bool has_mesh) : has_mesh_(has_mesh) {}
  std::string name() const override { return "scripted"; }
  std::string description() const override { return "scripted inversion"; }
  double step(const NeedleState&) override {
    ++steps_;
    return 0.0;
  }
  LayerState layer_state(std::size_t) const override { return LayerState::Untouched; }
  double break_force_N(std::size_t) const override { return std::nan(""); }
  std::vector<double> surface_deflection_m(std::size_t, const std::vector<double>& r_m) const override {
    return std::vector<double>(r_m.size(), 0.0);
  }
  comparison::ModelSize model_size() const override { return {}; }
  comparison::ElementInversion element_inversion() const override {
    if (!has_mesh_) return {};
    const long i = steps_ - 1;  // the step just taken
    comparison::ElementInversion e;
    e.elements = 1000;
    // Steps 0..199: none; 200..599: i / 20 - 9 (1 .. 20), the most (20) at
    // steps 580..599; then 3 to the end. J falls to -2.5 at step 590 and
    // recovers.
    e.inverted = i < 200 ? 0 : (i < 600 ? i / 20 - 9 : 3);
    e.min_volume_ratio = i < 200 ? 0.5 : (i == 590 ? -2.5 : -1.0);
    return e;
  }

 private:
  bool has_mesh_;
  long steps_ = 0;
};

Scene scene() { return load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json"); }

TEST(ModelRunInversion, TheRunKeepsTheMostInvertedSampleTheFirstDepthAndTheSmallestRatio) {
  const Scene s = scene();
  ScriptedInversionModel model(true);
  validation::ModelRunOptions options;
  options.measure_inversion = true;
  const validation::ModelRun run = validation::run_comparison_model(model, s, options);
  ASSERT_FALSE(run.failed()) << run.failure;
  ASSERT_GT(run.steps(), 600u);
  ASSERT_EQ(validation::kInversionSampleSteps, 10) << "the script's steps assume samples every 10 steps";
  EXPECT_EQ(run.inverted_elements_max, 20);
  EXPECT_DOUBLE_EQ(run.inverted_share_max, 0.02);
  EXPECT_DOUBLE_EQ(run.first_inversion_depth_m, run.depth_m[200]) << "the first inverted sample is step 200";
  EXPECT_DOUBLE_EQ(run.min_volume_ratio, -2.5) << "step 590 is sampled";
}

TEST(ModelRunInversion, NothingIsRecordedUnlessAskedOrWithoutAMesh) {
  const Scene s = scene();
  ScriptedInversionModel with_mesh(true);
  const validation::ModelRun not_asked = validation::run_comparison_model(with_mesh, s);
  EXPECT_EQ(not_asked.inverted_elements_max, -1);
  EXPECT_TRUE(std::isnan(not_asked.min_volume_ratio));

  ScriptedInversionModel without_mesh(false);
  validation::ModelRunOptions options;
  options.measure_inversion = true;
  const validation::ModelRun run = validation::run_comparison_model(without_mesh, s, options);
  EXPECT_EQ(run.inverted_elements_max, -1);
  EXPECT_TRUE(std::isnan(run.first_inversion_depth_m));
}

TEST(ModelRunInversion, TheMetricsCarryTheRunsRecord) {
  const Scene s = scene();
  validation::ModelRun run;  // no steps: only the size and inversion fields are read
  run.model = "scripted";
  const validation::ModelMetrics unmeasured = validation::metrics_against_reference(s, run, {}, 10);
  EXPECT_TRUE(std::isnan(unmeasured.inverted_share_max));
  run.inverted_elements_max = 7;
  run.inverted_share_max = 0.07;
  run.first_inversion_depth_m = 3e-3;
  run.min_volume_ratio = -0.4;
  const validation::ModelMetrics m = validation::metrics_against_reference(s, run, {}, 10);
  EXPECT_DOUBLE_EQ(m.inverted_share_max, 0.07);
  EXPECT_DOUBLE_EQ(m.first_inversion_depth_m, 3e-3);
  EXPECT_DOUBLE_EQ(m.min_volume_ratio, -0.4);
}

}  // namespace
