// The comparison models' breakthrough rule is the real-time model's: fed the
// force mesh's own node deflections, RingBreakthroughCriterion counts the
// same deformed rings as ForceMesh::deformed_rings.
#include <gtest/gtest.h>

#include "puncture/comparison/ring_criterion.hpp"
#include "puncture/contact_surface.hpp"
#include "puncture/force_mesh.hpp"

namespace puncture::comparison {
namespace {

TEST(RingBreakthroughCriterion, CountsTheSameRingsAsTheForceMesh) {
  ForceMeshParams params;
  params.rings_w = 6;
  params.spacing_L_m = 1e-3;
  params.virtual_stiffness_N_per_m = 100.0;
  params.surface_stiffness_N_per_m = 300.0;
  params.deformed_threshold_m = 2e-6;
  const PlaneSurface plane(0.0);
  MeshIntegrationSettings settings;
  settings.integrator = MeshIntegrator::QuasiStatic;
  ForceMesh mesh(plane, SurfacePoint{}, params, 1e-3, 1000.0, settings);
  const RingBreakthroughCriterion criterion(params);
  ASSERT_EQ(criterion.points_m().size(), static_cast<std::size_t>(mesh.node_count()));
  for (int i = 0; i < mesh.node_count(); ++i) {
    EXPECT_NEAR(criterion.points_m()[static_cast<std::size_t>(i)].x(), mesh.rest_positions()(0, i), 1e-15);
    EXPECT_NEAR(criterion.points_m()[static_cast<std::size_t>(i)].y(), mesh.rest_positions()(1, i), 1e-15);
  }
  int broke_at_step = -1;
  for (int step = 1; step <= 400; ++step) {
    mesh.advance(step * 5e-6);
    const Eigen::VectorXd& z = mesh.deflections_m();
    const std::vector<double> d(z.data(), z.data() + z.size());
    EXPECT_EQ(criterion.deformed_rings(d), mesh.deformed_rings()) << "step " << step;
    EXPECT_EQ(criterion.broken(d), mesh.broken());
    if (mesh.broken() && broke_at_step < 0) broke_at_step = step;
  }
  EXPECT_GT(broke_at_step, 1);
}

TEST(RingBreakthroughCriterion, RingsMustAllExceedTheThreshold) {
  ForceMeshParams params;
  params.rings_w = 3;
  params.spacing_L_m = 2e-3;
  params.deformed_threshold_m = 1e-5;
  const RingBreakthroughCriterion c(params);
  ASSERT_EQ(c.points_m().size(), 19u);
  std::vector<double> d(19, 2e-5);
  EXPECT_EQ(c.deformed_rings(d), 3);
  for (std::size_t i = 1; i < 7; ++i) d[i] = 0.0;  // ring 2 flat: only ring 1 counts
  EXPECT_EQ(c.deformed_rings(d), 1);
  EXPECT_FALSE(c.broken(d));
  EXPECT_THROW(c.deformed_rings(std::vector<double>(5, 0.0)), std::invalid_argument);
}

}  // namespace
}  // namespace puncture::comparison
