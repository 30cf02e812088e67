// The comparison models' identification (model_identification.hpp) on a
// volumetric model, where a layer's factor shapes the force while other layers
// are pressed (the skin rests on the fat): the joint fit after the bottom-up
// pass runs there and lowers the windows' summed cost. (On the BEM, whose
// windows are uncoupled, it stops at its start: tests/validation.)
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "puncture/comparison/model_factory.hpp"
#include "puncture/meshing/tet_slab_mesh.hpp"
#include "puncture/validation/model_comparison.hpp"
#include "puncture/validation/model_identification.hpp"
#include "tet_test_scenes.hpp"

namespace puncture::validation {
namespace {

/// The two sums of squared residuals in a joint-fit note ("... A -> B ...").
std::pair<double, double> joint_costs(const std::string& note) {
  const std::size_t arrow = note.find(" -> ");
  const std::size_t colon = note.rfind("residuals ", arrow);
  if (arrow == std::string::npos || colon == std::string::npos) return {-1.0, -1.0};
  return {std::stod(note.substr(colon + 10, arrow - colon - 10)), std::stod(note.substr(arrow + 4))};
}

TEST(ModelIdentificationVolumetric, TheJointFitRunsWhereTheLayersShareTheForce) {
  // Reference: the linear mass-spring model itself with the skin x 2 and the
  // fat x 0.5 on a coarse mesh of the small slab, breaking by the ring rule.
  // Bottom up, the fat's factor is fitted with the skin at 1 (the skin's
  // rim still carries part of the fat's pressing), then the skin's with that
  // fat: the windows together cost more than each in its own fit, so the
  // joint fit runs, and never to a higher cost.
  Scene scene = testing::small_slab_scene();
  scene.insertion.target_depth_m = 3.5e-3;  // into the fat, the muscle pressed
  scene.comparison.mesh.size_at_axis_m = 0.8e-3;
  scene.comparison.mesh.size_far_m = 3e-3;
  const auto mesh =
      std::make_shared<meshing::TetMesh>(meshing::build_tet_slab_mesh(scene, meshing::tet_slab_mesh_options(scene)));
  Scene truth = scene;
  truth.comparison.stiffness_scale = {2.0, 0.5, 1.0};
  auto model = comparison::make_comparison_model("msm", truth, mesh);
  const ModelRun run = run_comparison_model(*model, truth);
  ASSERT_FALSE(run.failed()) << run.failure;
  ReferenceData reference;
  reference.curve = curve_from_model_run(truth, run, false);

  const ModelIdentification id = identify_comparison_model("msm", scene, mesh, reference, true);
  ASSERT_GE(id.layers.size(), 2u);
  EXPECT_TRUE(std::isfinite(id.layers[0].window_rmse_after_N)) << "the skin's factor was fitted";
  EXPECT_TRUE(std::isfinite(id.layers[1].window_rmse_after_N)) << "the fat's factor was fitted";
  EXPECT_EQ(id.joint_note.find("not needed"), std::string::npos) << id.joint_note;
  const auto [before, after] = joint_costs(id.joint_note);
  ASSERT_GT(before, 0.0) << id.joint_note;
  EXPECT_LE(after, before) << id.joint_note;
}

}  // namespace
}  // namespace puncture::validation
