// Extruded tetrahedral mesh of the layered slab: layer and needle-column
// volumes against the closed form of the extruded polygons, a conforming
// tiling (every interior face shared by two tetrahedra, every boundary face on
// the sample's outer surface), labels against the depths and the needle
// radius, a vertex count that follows the mesh sizes (the thin skin holds
// (elements + 1) plan layers of nodes, whatever its extent), the scene's
// choice of mesher, and the linear tensor-mass model on it converging to the
// layered half-space's indentation stiffness (BEM, itself checked against
// Sneddon).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <iostream>
#include <set>

#include "puncture/comparison/model_factory.hpp"
#include "puncture/comparison/surface_models.hpp"
#include "puncture/meshing/comparison_tet_slab_mesh.hpp"
#include "puncture/meshing/extruded_tet_slab_mesh.hpp"
#include "puncture/needle.hpp"
#include "tet_mesh_checks.hpp"
#include "tet_test_scenes.hpp"

namespace puncture::meshing {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Area of the regular n-gon inscribed in the circle of radius r.
double polygon_area(int n, double r) { return 0.5 * n * r * r * std::sin(2.0 * kPi / n); }

/// Vertices of the mesh on the plane z at radius r (relative tolerance 1e-9).
int nodes_at_radius(const meshing::TetMesh& mesh, double z, double r) {
  int count = 0;
  for (int a = 0; a < mesh.node_count(); ++a) {
    const Eigen::Vector3d p = mesh.points_m.col(a);
    if (std::abs(p.z() - z) < 1e-9 && std::abs(std::hypot(p.x(), p.y()) - r) < 1e-9 * r) ++count;
  }
  return count;
}

class ExtrudedDefaultMesh : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new Scene(testing::default_scene());
    report_ = new ExtrudedSlabMeshReport;
    mesh_ = new meshing::TetMesh(
        build_extruded_tet_slab_mesh(*scene_, extruded_slab_mesh_options(*scene_), report_));
  }
  static void TearDownTestSuite() {
    delete mesh_;
    delete report_;
    delete scene_;
  }
  static Scene* scene_;
  static meshing::TetMesh* mesh_;
  static ExtrudedSlabMeshReport* report_;
};
Scene* ExtrudedDefaultMesh::scene_ = nullptr;
meshing::TetMesh* ExtrudedDefaultMesh::mesh_ = nullptr;
ExtrudedSlabMeshReport* ExtrudedDefaultMesh::report_ = nullptr;

TEST_F(ExtrudedDefaultMesh, LayerAndNeedleColumnVolumesAreThoseOfTheExtrudedPolygons) {
  const double R = 0.5 * scene_->sample.diameter_m, a = scene_->needle.radius_m;
  // The rims: the nodes on the top plane at r = R and at r = a.
  const int rim_nodes = nodes_at_radius(*mesh_, 0.0, R);
  const int needle_rim_nodes = nodes_at_radius(*mesh_, 0.0, a);
  ASSERT_GE(rim_nodes, 12);
  ASSERT_GE(needle_rim_nodes, 12);
  const std::vector<double> volume = meshing::layer_volumes_m3(*mesh_, 3);
  std::vector<double> column(3, 0.0);
  for (std::size_t t = 0; t < mesh_->tets.size(); ++t) {
    if (!mesh_->needle_column[t]) continue;
    const Eigen::Vector4i& v = mesh_->tets[t];
    column[static_cast<std::size_t>(mesh_->layer[t])] += meshing::tet_signed_volume(
        mesh_->points_m.col(v[0]), mesh_->points_m.col(v[1]), mesh_->points_m.col(v[2]), mesh_->points_m.col(v[3]));
  }
  for (std::size_t k = 0; k < 3; ++k) {
    const double t = scene_->layers[k].thickness_m;
    EXPECT_NEAR(volume[k], polygon_area(rim_nodes, R) * t, 1e-9 * volume[k]) << scene_->layers[k].name;
    EXPECT_NEAR(column[k], polygon_area(needle_rim_nodes, a) * t, 1e-9 * column[k]) << scene_->layers[k].name;
    // And within the polygonal error of the cylinders: (2 pi / n)^2 / 6, 1.1 %
    // for the 24 rim nodes of the default sizes (the rim is fixed).
    EXPECT_NEAR(volume[k], kPi * R * R * t, 0.015 * kPi * R * R * t);
    EXPECT_NEAR(column[k], kPi * a * a * t, 0.05 * kPi * a * a * t);
  }
}

TEST_F(ExtrudedDefaultMesh, TetrahedraTileTheSlabConformingly) {
  const double R = 0.5 * scene_->sample.diameter_m, H = scene_->total_thickness_m();
  const int boundary = testing::check_closed_tiling(*mesh_, R, H, 1e-12, 1e-12);
  // Top and base: two plan triangulations; the side: two triangles per rim
  // segment and element height.
  EXPECT_EQ(boundary, 2 * report_->plan_triangles + 2 * nodes_at_radius(*mesh_, 0.0, R) *
                                                         (report_->levels - 1));
}

TEST_F(ExtrudedDefaultMesh, LabelsFollowTheDepthsAndTheNeedleRadius) {
  for (std::size_t t = 0; t < mesh_->tets.size(); ++t) {
    const Eigen::Vector4i& v = mesh_->tets[t];
    const Eigen::Vector3d c = 0.25 * (mesh_->points_m.col(v[0]) + mesh_->points_m.col(v[1]) +
                                      mesh_->points_m.col(v[2]) + mesh_->points_m.col(v[3]));
    const std::size_t k = static_cast<std::size_t>(mesh_->layer[t]);
    const double top = scene_->layer_top_depth_m(k), bottom = top + scene_->layers[k].thickness_m;
    for (int i = 0; i < 4; ++i) {
      ASSERT_GE(-mesh_->points_m(2, v[i]), top - 1e-12) << "tetrahedron " << t;
      ASSERT_LE(-mesh_->points_m(2, v[i]), bottom + 1e-12) << "tetrahedron " << t;
    }
    ASSERT_EQ(mesh_->needle_column[t] != 0, std::hypot(c.x(), c.y()) <= scene_->needle.radius_m) << "tetrahedron " << t;
  }
}

TEST_F(ExtrudedDefaultMesh, HeightsAreSizeAtAxisDownToTheTargetDepthAndGradedBelow) {
  std::set<double> levels;
  for (int a = 0; a < mesh_->node_count(); ++a) levels.insert(-mesh_->points_m(2, a));
  ASSERT_EQ(static_cast<int>(levels.size()), report_->levels);
  const std::vector<double> z(levels.begin(), levels.end());  // depths, ascending
  const double h = scene_->comparison.mesh.size_at_axis_m;
  const double fine_to = scene_->insertion.target_depth_m + 2.0 * h;
  // The skin (0.8 mm) gets the minimum of 2 element heights: 3 node levels
  // in [0, 0.8 mm], whatever the disc's size.
  EXPECT_EQ(std::count_if(z.begin(), z.end(), [&](double d) { return d <= scene_->layers[0].thickness_m + 1e-12; }), 3);
  for (std::size_t i = 0; i + 1 < z.size(); ++i) {
    const double height = z[i + 1] - z[i];
    if (z[i + 1] <= fine_to + 1e-9) EXPECT_LE(height, h * (1.0 + 1e-9)) << "at depth " << z[i];
  }
  // Below the deepest tip position the heights grow.
  EXPECT_GT(z[z.size() - 1] - z[z.size() - 2], 2.0 * h);
}

TEST(ExtrudedTetSlabMesh, VertexCountFollowsTheSizesAndTheMeshIsRepeatable) {
  const Scene scene = testing::default_scene();
  ExtrudedSlabMeshOptions options = extruded_slab_mesh_options(scene);
  ExtrudedSlabMeshReport coarse, fine;
  const meshing::TetMesh a = build_extruded_tet_slab_mesh(scene, options, &coarse);
  const meshing::TetMesh b = build_extruded_tet_slab_mesh(scene, options);
  EXPECT_EQ((a.points_m - b.points_m).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_TRUE(a.tets == b.tets);
  EXPECT_EQ(coarse.vertices, coarse.plan_nodes * coarse.levels);
  EXPECT_EQ(coarse.tetrahedra, 3 * coarse.plan_triangles * (coarse.levels - 1));
  // Euler's formula for the triangulated disc: T = 2 N - 2 - (boundary nodes).
  const int rim = nodes_at_radius(a, 0.0, 0.5 * scene.sample.diameter_m);
  EXPECT_EQ(coarse.plan_triangles, 2 * coarse.plan_nodes - 2 - rim);
  // The skin's nodes: (2 + 1) plan layers, a few per cent of the mesh.
  int skin_nodes = 0;
  for (int i = 0; i < a.node_count(); ++i) skin_nodes += a.points_m(2, i) >= -scene.layers[0].thickness_m - 1e-12;
  EXPECT_EQ(skin_nodes, 3 * coarse.plan_nodes);
  EXPECT_LT(skin_nodes, a.node_count() / 10);
  options.size_at_axis_m *= 0.5;
  options.size_far_m *= 0.5;
  build_extruded_tet_slab_mesh(scene, options, &fine);
  EXPECT_GT(fine.plan_nodes, 2 * coarse.plan_nodes);
  EXPECT_GT(fine.levels, coarse.levels);
  options.size_at_axis_m = -1.0;
  EXPECT_THROW(build_extruded_tet_slab_mesh(scene, options), std::invalid_argument);
}

TEST(ComparisonTetMesh, TheSceneChoosesTheMesher) {
  Scene scene = testing::small_slab_scene();
  ComparisonTetMeshReport report;
  EXPECT_EQ(scene.comparison.mesh.kind, "extruded");
  const meshing::TetMesh extruded = build_comparison_tet_mesh(scene, &report);
  EXPECT_EQ(report.kind, "extruded");
  EXPECT_EQ(report.vertices, extruded.node_count());
  scene.comparison.mesh.kind = "delaunay";
  build_comparison_tet_mesh(scene, &report);
  EXPECT_EQ(report.kind, "delaunay");
  EXPECT_NE(report.description.find("CGAL"), std::string::npos);
  scene.comparison.mesh.kind = "octree";
  EXPECT_THROW(build_comparison_tet_mesh(scene), std::invalid_argument);
}

TEST(ExtrudedTetSlabMesh, LinearTensorMassIndentationConvergesToTheLayeredHalfSpace) {
  // As the test of the Delaunay mesh (test_volumetric_models.cpp): one
  // compressible layer (nu = 0.3) on a rigid base, indented 0.03 mm at 1 mm/s;
  // the reference is the BEM stiffness of the same layer. P1 tetrahedra are
  // stiffer than the continuum: the ratio is >= 1 and falls toward 1 as the
  // mesh at the needle is refined.
  double previous = 0.0;
  for (double size : {0.3e-3, 0.2e-3}) {
    const Scene s = testing::single_layer_scene(0.3, size);
    const auto mesh = std::make_shared<meshing::TetMesh>(build_comparison_tet_mesh(s));
    auto model = comparison::make_comparison_model("mass_tensor", s, mesh);
    const ScriptedTrajectory trajectory(s.insertion);
    const double until = s.insertion.target_depth_m / s.insertion.speed_m_per_s;
    const double dt = 1.0 / s.realtime.haptic_rate_Hz;
    double force = 0.0, depth = 0.0;
    for (long i = 0; i * dt <= until + 1e-12; ++i) {
      const NeedleState needle = trajectory.sample(i * dt);
      force = model->step(needle);
      depth = needle.depth_m();
    }
    const comparison::BoundaryElementModel bem(s);
    const double ratio = force / depth / bem.stiffness_N_per_m(0);
    std::cout << "size " << size << " m: FE / BEM stiffness " << ratio << " on " << mesh->node_count() << " nodes\n";
    EXPECT_GT(ratio, 0.98) << "FE " << force / depth << " N/m, BEM " << bem.stiffness_N_per_m(0) << " N/m";
    EXPECT_LT(ratio, 1.45) << "FE " << force / depth << " N/m";
    if (previous > 0.0) EXPECT_LT(ratio, previous - 0.03);
    previous = ratio;
  }
}

}  // namespace
}  // namespace puncture::meshing
