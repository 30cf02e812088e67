// CGAL tetrahedral mesh of the layered slab: layer volumes against the
// analytic cylinder volumes, labels against the layer depths and the needle
// radius, a closed tiling (every interior face shared by two tetrahedra, every
// boundary face on the sample's outer surface), quality bounds, determinism
// within one process (across processes: test_tet_slab_mesh_determinism.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "puncture/meshing/tet_slab_mesh.hpp"
#include "tet_mesh_checks.hpp"
#include "tet_test_scenes.hpp"

namespace puncture::meshing {
namespace {

constexpr double kPi = 3.14159265358979323846;

class DefaultSceneMesh : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new Scene(testing::default_scene());
    TetSlabMeshOptions options = tet_slab_mesh_options(*scene_);
    options.size_at_axis_m = 1e-3;
    options.size_far_m = 8e-3;
    options.grading = 0.5;
    report_ = new TetSlabMeshReport;
    mesh_ = new meshing::TetMesh(build_tet_slab_mesh(*scene_, options, report_));
  }
  static void TearDownTestSuite() {
    delete mesh_;
    delete report_;
    delete scene_;
  }
  static Scene* scene_;
  static meshing::TetMesh* mesh_;
  static TetSlabMeshReport* report_;
};
Scene* DefaultSceneMesh::scene_ = nullptr;
meshing::TetMesh* DefaultSceneMesh::mesh_ = nullptr;
TetSlabMeshReport* DefaultSceneMesh::report_ = nullptr;

TEST_F(DefaultSceneMesh, LayerVolumesWithinOnePercentOfTheCylinders) {
  const double R = 0.5 * scene_->sample.diameter_m;
  const std::vector<double> volume = meshing::layer_volumes_m3(*mesh_, 3);
  for (std::size_t k = 0; k < 3; ++k) {
    const double exact = kPi * R * R * scene_->layers[k].thickness_m;
    EXPECT_NEAR(volume[k], exact, 0.01 * exact) << scene_->layers[k].name;
  }
  // The needle column of every layer: pi a^2 t within the polygonal error of
  // its side (10 or more facets around: up to 6 % of a small cylinder).
  const double a = scene_->needle.radius_m;
  std::vector<double> column(3, 0.0);
  for (std::size_t t = 0; t < mesh_->tets.size(); ++t) {
    if (!mesh_->needle_column[t]) continue;
    const Eigen::Vector4i& v = mesh_->tets[t];
    column[static_cast<std::size_t>(mesh_->layer[t])] += meshing::tet_signed_volume(
        mesh_->points_m.col(v[0]), mesh_->points_m.col(v[1]), mesh_->points_m.col(v[2]), mesh_->points_m.col(v[3]));
  }
  for (std::size_t k = 0; k < 3; ++k) {
    const double exact = kPi * a * a * scene_->layers[k].thickness_m;
    EXPECT_NEAR(column[k], exact, 0.08 * exact) << scene_->layers[k].name;
  }
}

TEST_F(DefaultSceneMesh, LabelsMatchLayerDepthsAndTheNeedleRadius) {
  for (std::size_t t = 0; t < mesh_->tets.size(); ++t) {
    const Eigen::Vector4i& v = mesh_->tets[t];
    const Eigen::Vector3d c = 0.25 * (mesh_->points_m.col(v[0]) + mesh_->points_m.col(v[1]) +
                                      mesh_->points_m.col(v[2]) + mesh_->points_m.col(v[3]));
    const std::size_t k = static_cast<std::size_t>(mesh_->layer[t]);
    const double top = scene_->layer_top_depth_m(k), bottom = top + scene_->layers[k].thickness_m;
    ASSERT_GE(-c.z(), top - 1e-9) << "tetrahedron " << t;
    ASSERT_LE(-c.z(), bottom + 1e-9) << "tetrahedron " << t;
    // Every vertex within the layer's depth range too (interfaces are conforming).
    for (int i = 0; i < 4; ++i) {
      ASSERT_GE(-mesh_->points_m(2, v[i]), top - 1e-6) << "tetrahedron " << t;
      ASSERT_LE(-mesh_->points_m(2, v[i]), bottom + 1e-6) << "tetrahedron " << t;
    }
    ASSERT_EQ(mesh_->needle_column[t] != 0, std::hypot(c.x(), c.y()) <= scene_->needle.radius_m) << "tetrahedron " << t;
  }
}

TEST_F(DefaultSceneMesh, TetrahedraTileTheSlabWithoutHoles) {
  // Rim vertices lie on the feature polyline, inside the circle by up to 0.05 mm.
  const double R = 0.5 * scene_->sample.diameter_m, H = scene_->total_thickness_m();
  EXPECT_GT(testing::check_closed_tiling(*mesh_, R - 0.025e-3, H, 0.026e-3, 1e-6), 0);
}

TEST_F(DefaultSceneMesh, QualityBoundsHold) {
  const meshing::TetQuality& q = report_->quality;
  EXPECT_GT(q.min_dihedral_deg, 1.0) << meshing::describe(q);
  EXPECT_LT(q.max_dihedral_deg, 178.0);
  EXPECT_LT(q.max_radius_edge_ratio, 20.0);
  EXPECT_LT(q.mean_radius_edge_ratio, 1.5);
  EXPECT_LT(q.tets_below_10_deg, static_cast<int>(0.03 * mesh_->tets.size()));  // about 2 %
  // Graded toward the needle: the shortest edges are near the axis.
  EXPECT_LT(q.min_edge_m, 0.5e-3);
  EXPECT_GT(q.max_edge_m, 4e-3);
  // The independent recomputation of one element's angles: the regular tetrahedron.
  const std::vector<double> regular = meshing::tet_dihedral_angles_deg(
      Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, -1, -1), Eigen::Vector3d(-1, 1, -1), Eigen::Vector3d(-1, -1, 1));
  for (double angle : regular) EXPECT_NEAR(angle, std::acos(1.0 / 3.0) * 180.0 / kPi, 1e-9);
  EXPECT_NEAR(meshing::tet_radius_edge_ratio(Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, -1, -1),
                                                Eigen::Vector3d(-1, 1, -1), Eigen::Vector3d(-1, -1, 1)),
              std::sqrt(6.0) / 4.0, 1e-12);
}

TEST_F(DefaultSceneMesh, NodesOnEveryInterfaceInsideTheNeedleDisc) {
  for (std::size_t k = 0; k < 3; ++k) {
    const double z = -scene_->layer_top_depth_m(k);
    int inside = 0;
    for (int a = 0; a < mesh_->node_count(); ++a) {
      const Eigen::Vector3d p = mesh_->points_m.col(a);
      if (std::abs(p.z() - z) < 1e-6 && std::hypot(p.x(), p.y()) <= scene_->needle.radius_m + 1e-6) ++inside;
    }
    EXPECT_GE(inside, 6) << scene_->layers[k].name;
  }
}

TEST(TetSlabMesh, RepeatableAndFinerWithSmallerSizes) {
  // With the production options (sliver exudation on, run to completion) two
  // meshes in one process are identical; across processes see
  // test_tet_slab_mesh_determinism.cpp. Exudation only reconnects cells near
  // slivers, so the layer volumes stay those of the unexuded mesh.
  const Scene scene = testing::small_slab_scene();
  TetSlabMeshOptions options = tet_slab_mesh_options(scene);
  ASSERT_TRUE(options.exude_slivers);
  const meshing::TetMesh a = build_tet_slab_mesh(scene, options);
  const meshing::TetMesh b = build_tet_slab_mesh(scene, options);
  ASSERT_EQ(a.node_count(), b.node_count());
  ASSERT_EQ(a.tets.size(), b.tets.size());
  EXPECT_EQ((a.points_m - b.points_m).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_TRUE(a.tets == b.tets);
  options.exude_slivers = false;
  const meshing::TetMesh c = build_tet_slab_mesh(scene, options);
  const std::vector<double> va = meshing::layer_volumes_m3(a, 3), vc = meshing::layer_volumes_m3(c, 3);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(vc[k], va[k], 1e-3 * va[k]);
  // Exudation raises the smallest dihedral angle and removes slivers.
  const meshing::TetQuality qa = meshing::measure_tet_quality(a), qc = meshing::measure_tet_quality(c);
  EXPECT_GT(qa.min_dihedral_deg, qc.min_dihedral_deg);
  EXPECT_LT(qa.tets_below_10_deg, qc.tets_below_10_deg);
  options.size_at_axis_m *= 0.6;
  options.size_far_m *= 0.6;
  EXPECT_GT(build_tet_slab_mesh(scene, options).node_count(), a.node_count());
  options.size_at_axis_m = -1.0;
  EXPECT_THROW(build_tet_slab_mesh(scene, options), std::invalid_argument);
}

}  // namespace
}  // namespace puncture::meshing
