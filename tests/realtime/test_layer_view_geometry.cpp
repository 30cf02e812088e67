// The view's layer meshes: the top face lies on the layer's SH surface (which
// is flat to the fit error), the cut is at y = 0, and the force-mesh
// deformation moves the top-face vertex under the needle by the contact
// node's deflection and leaves the far rim alone.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "puncture/model/realtime_model.hpp"
#include "puncture/realtime/layer_view_geometry.hpp"
#include "realtime_test_scenes.hpp"

namespace puncture::realtime {
namespace {

TEST(LayerViewGeometry, TopFaceOnTheShSurfaceAndCutAtYZero) {
  const Scene scene = testing::default_scene();
  const RealtimeModel model = build_realtime_model(scene);
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const LayerDisc disc = layer_disc(scene, k);
    const LayerViewMesh m = build_layer_view_mesh(*model.surfaces[k], disc.bottom_z_m);
    const double tol = 2.0 * model.surfaces[k]->top_face_max_error_m() + 1e-3 * scene.layers[k].thickness_m;
    double max_r = 0.0;
    for (int id : m.top_face) {
      const Eigen::Vector3d p = m.rest_vertices.row(id).transpose();
      if (std::hypot(p.x(), p.y()) < 0.9 * disc.radius_m) EXPECT_NEAR(p.z(), disc.top_z_m, tol) << k;
      max_r = std::max(max_r, std::hypot(p.x(), p.y()));
    }
    EXPECT_NEAR(max_r, disc.radius_m, 1e-3 * disc.radius_m);
    EXPECT_GE(m.rest_vertices.col(1).minCoeff(), -1e-9);  // back half only
    EXPECT_GT(m.cap_triangles.rows(), 0);
    for (Eigen::Index t = 0; t < m.cap_triangles.rows(); ++t)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.rest_vertices(m.cap_triangles(t, c), 1), 0.0, 1e-9);
    EXPECT_LE(m.top_triangles.maxCoeff(), m.rest_vertices.rows() - 1);
    EXPECT_LE(m.side_triangles.maxCoeff(), m.rest_vertices.rows() - 1);
    // Orientation (backface culling relies on it): top triangles face +z,
    // side triangles face away from the axis, cap triangles face -y.
    auto normal = [&](const Eigen::MatrixX3i& t, Eigen::Index i) {
      const Eigen::Vector3d a = m.rest_vertices.row(t(i, 0)), b = m.rest_vertices.row(t(i, 1)),
                            c = m.rest_vertices.row(t(i, 2));
      return Eigen::Vector3d((b - a).cross(c - a));
    };
    for (Eigen::Index t = 0; t < m.top_triangles.rows(); ++t) ASSERT_GT(normal(m.top_triangles, t).z(), 0.0) << t;
    for (Eigen::Index t = 0; t < m.side_triangles.rows(); ++t) {
      const Eigen::Vector3d centre = (m.rest_vertices.row(m.side_triangles(t, 0)) +
                                      m.rest_vertices.row(m.side_triangles(t, 1)) +
                                      m.rest_vertices.row(m.side_triangles(t, 2))).transpose() / 3.0;
      const Eigen::Vector3d n = normal(m.side_triangles, t);
      if (n.norm() > 1e-18) ASSERT_GT(n.dot(Eigen::Vector3d(centre.x(), centre.y(), 0.0)), 0.0) << t;
    }
    for (Eigen::Index t = 0; t < m.cap_triangles.rows(); ++t) {
      const Eigen::Vector3d n = normal(m.cap_triangles, t);
      if (n.norm() > 1e-18) ASSERT_LT(n.y(), 0.0) << t;
    }
  }
}

TEST(LayerViewGeometry, DeformationFollowsTheForceMesh) {
  const Scene scene = testing::default_scene();
  RealtimeModel model = build_realtime_model(scene);
  PunctureSimulator& sim = *model.simulator;
  // Press the skin 1 mm and let the mesh settle (no puncture at this depth).
  NeedleState needle;
  for (int n = 0; n < 300; ++n) {
    needle.tip_position_m = Eigen::Vector3d(0, 0, -std::min(1e-3, n * 1e-5));
    needle.time_s = n * 1e-3;
    sim.tick(needle);
  }
  ASSERT_EQ(sim.layer_state(0), LayerState::Pressed);
  ViewSnapshot snap;
  init_snapshot(snap, sim);
  fill_snapshot(snap, sim, sim.last_result());
  const LayerDisc disc = layer_disc(scene, 0);
  const LayerViewMesh m = build_layer_view_mesh(*model.surfaces[0], disc.bottom_z_m);
  const LayerDeformer deformer(sim.force_mesh(0)->lattice(), scene.layers[0].force_mesh.spacing_L_m);
  Eigen::MatrixX3d v;
  const double largest = deformer.apply(snap.layers[0], m, v);
  const double contact_deflection = sim.force_mesh(0)->deflections_m()[0];
  EXPECT_NEAR(contact_deflection, 1e-3, 1e-4);
  // Vertex 0 is the centre of the top face, exactly over the contact node.
  EXPECT_NEAR(m.rest_vertices(0, 2) - v(0, 2), contact_deflection, 1e-9);
  EXPECT_NEAR(largest, contact_deflection, 1e-9);
  // The rim, outside the force mesh, does not move.
  const int rim = m.top_face.back();
  EXPECT_EQ(v.row(rim), m.rest_vertices.row(rim));
  // A layer that was never touched is not deformed.
  const LayerDeformer fat(sim.force_mesh(1)->lattice(), scene.layers[1].force_mesh.spacing_L_m);
  const LayerViewMesh mf = build_layer_view_mesh(*model.surfaces[1], layer_disc(scene, 1).bottom_z_m);
  EXPECT_EQ(fat.apply(snap.layers[1], mf, v), 0.0);
}

}  // namespace
}  // namespace puncture::realtime
