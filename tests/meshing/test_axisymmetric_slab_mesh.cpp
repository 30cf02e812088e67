#include <algorithm>
// Axisymmetric slab mesh: the layer volumes of revolution are those of the
// cylinders, cells carry the layer at their depth, every layer gets its
// minimum number of elements and starts with the tip element size on the
// needle path, the crack line is doubled exactly where the needle runs, and
// refinement halves every element.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include <puncture/meshing/axisymmetric_slab_mesh.hpp>

using namespace puncture;
using namespace puncture::meshing;

namespace {

Scene three_layers(const std::string& tip) {
  Scene s;
  s.sample.diameter_m = 0.06;
  for (auto [name, t] : {std::pair<const char*, double>{"skin", 0.8e-3}, {"fat", 8.4e-3}, {"muscle", 39e-3}}) {
    Layer l;
    l.name = name;
    l.thickness_m = t;
    s.layers.push_back(l);
  }
  s.needle.radius_m = 0.635e-3;
  s.needle.tip = tip;
  s.insertion.target_depth_m = 30e-3;
  return s;
}

double cell_area(const AxisymmetricSlabMesh& m, std::size_t c, double* centroid_r = nullptr) {
  const auto& v = m.cells[c];
  const Eigen::Vector2d p0 = m.vertices[v[0]], p3 = m.vertices[v[3]];
  if (centroid_r != nullptr) *centroid_r = 0.5 * (p0[0] + p3[0]);
  return (p3[0] - p0[0]) * (p3[1] - p0[1]);
}

}  // namespace

TEST(AxisymmetricSlabMesh, LayerVolumesOfRevolutionAreTheCylindersLessTheChannel) {
  // Cutting tips: the channel R < r_c above the path depth has no cells, so a
  // layer's volume is its cylinder less pi r_c^2 times the part of the layer
  // above the path; a blunt tip's mesh is the full cylinder.
  for (const std::string tip : {"bevel", "blunt"}) {
    const Scene s = three_layers(tip);
    const auto m = build_axisymmetric_slab_mesh(s, 0);
    EXPECT_EQ(m.open_channel, tip == "bevel") << tip;
    std::vector<double> volume(3, 0.0);
    for (std::size_t c = 0; c < m.cells.size(); ++c) {
      double rc = 0.0;
      const double area = cell_area(m, c, &rc);
      ASSERT_GT(area, 0.0) << "cell " << c << " has a non-positive orientation";
      volume[m.material_id[c]] += 2.0 * M_PI * rc * area;  // Pappus, exact for a rectangle
    }
    const double R = 0.5 * s.sample.diameter_m;
    for (int i = 0; i < 3; ++i) {
      const double top = s.layer_top_depth_m(i), bottom = top + s.layers[i].thickness_m;
      const double cut = m.open_channel ? std::clamp(m.path_depth_m, top, bottom) - top : 0.0;
      const double expected = M_PI * R * R * s.layers[i].thickness_m - M_PI * m.crack_radius_m * m.crack_radius_m * cut;
      EXPECT_NEAR(volume[i], expected, 1e-9 * volume[i]) << tip << " " << s.layers[i].name;
    }
  }
}

TEST(AxisymmetricSlabMesh, CellsCarryTheLayerAtTheirDepth) {
  const Scene s = three_layers("bevel");
  const auto m = build_axisymmetric_slab_mesh(s, 0);
  for (std::size_t c = 0; c < m.cells.size(); ++c) {
    const double depth = -0.5 * (m.vertices[m.cells[c][0]][1] + m.vertices[m.cells[c][3]][1]);
    const int layer = m.material_id[c];
    EXPECT_GT(depth, s.layer_top_depth_m(layer));
    EXPECT_LT(depth, s.layer_top_depth_m(layer) + s.layers[layer].thickness_m);
  }
}

TEST(AxisymmetricSlabMesh, ResolutionFollowsNeedleRadiusAndLayerThickness) {
  Scene s = three_layers("bevel");
  s.fem.mesh.elements_per_needle_radius = 8;
  s.fem.mesh.min_elements_per_layer = 6;
  const auto m = build_axisymmetric_slab_mesh(s, 0);
  const double h_tip = s.needle.radius_m / 8;
  EXPECT_NEAR(m.tip_element_size_m, h_tip, 1e-15);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_GE(m.elements_through_layer[i], 6) << s.layers[i].name;
    // The first element below each layer top is no larger than the tip element.
    const double top = -s.layer_top_depth_m(i);
    for (std::size_t j = 0; j + 1 < m.axial_lines_m.size(); ++j)
      if (std::abs(m.axial_lines_m[j] - top) < 1e-12)
        EXPECT_LE(m.axial_lines_m[j] - m.axial_lines_m[j + 1], h_tip * (1 + 1e-9)) << s.layers[i].name;
    EXPECT_LE(m.largest_path_element_m[i], s.fem.mesh.path_element_size_mm * 1e-3 * (1 + 1e-9));
  }
  // Across the needle radius: elements no larger than h_tip.
  for (std::size_t k = 0; k + 1 < m.radial_lines_m.size() && m.radial_lines_m[k] < s.needle.radius_m; ++k)
    EXPECT_LE(m.radial_lines_m[k + 1] - m.radial_lines_m[k], h_tip * 1.3);
  // A thin skin gets more elements when the scene asks for them.
  s.fem.mesh.min_elements_per_layer = 20;
  EXPECT_GE(build_axisymmetric_slab_mesh(s, 0).elements_through_layer[0], 20);
}

TEST(AxisymmetricSlabMesh, BluntTipCrackLineIsDoubledAlongTheNeedlePath) {
  const Scene s = three_layers("blunt");
  const auto m = build_axisymmetric_slab_mesh(s, 0);
  EXPECT_NEAR(m.crack_radius_m, s.needle.radius_m, 1e-15);
  ASSERT_FALSE(m.crack_vertex_pairs.empty());
  double deepest = 0.0;
  std::set<unsigned> core, outer;
  for (const auto& [c, o] : m.crack_vertex_pairs) {
    EXPECT_NE(c, o);
    EXPECT_EQ(m.vertices[c], m.vertices[o]);
    EXPECT_NEAR(m.vertices[c][0], m.crack_radius_m, 1e-15);
    deepest = std::max(deepest, -m.vertices[c][1]);
    core.insert(c);
    outer.insert(o);
  }
  EXPECT_NEAR(m.vertices[m.crack_vertex_pairs.front().first][1], 0.0, 1e-15) << "crack starts at the surface";
  EXPECT_GE(deepest, s.insertion.target_depth_m) << "crack line reaches the target depth";
  EXPECT_LT(deepest, m.path_depth_m) << "the vertex at the path depth is shared";
  // Cells left of the crack use the core copies only, cells right of it the outer copies only.
  for (std::size_t c = 0; c < m.cells.size(); ++c) {
    const double rc = 0.5 * (m.vertices[m.cells[c][0]][0] + m.vertices[m.cells[c][3]][0]);
    for (unsigned v : m.cells[c]) {
      if (rc < m.crack_radius_m) EXPECT_EQ(outer.count(v), 0u);
      if (rc > m.crack_radius_m) EXPECT_EQ(core.count(v), 0u);
    }
  }
}

TEST(AxisymmetricSlabMesh, CuttingTipsOpenAChannelWhoseWallIsTheCrackFace) {
  for (const std::string tip : {"bevel", "hollow"}) {
    const Scene s = three_layers(tip);
    const auto m = build_axisymmetric_slab_mesh(s, 0);
    // Crack radius: the bevel's slit of width 2a has the perimeter of a ring of
    // radius 2a/pi; a hollow needle cores at its inner radius.
    const double expected = tip == "bevel" ? 2 * s.needle.radius_m / M_PI : s.needle.inner_radius_m;
    EXPECT_NEAR(m.crack_radius_m, expected, 1e-15) << tip;
    ASSERT_TRUE(m.open_channel);
    EXPECT_TRUE(m.crack_vertex_pairs.empty()) << tip;
    ASSERT_FALSE(m.crack_face_vertices.empty());
    double deepest = 0.0, shallowest = 1.0;
    for (unsigned v : m.crack_face_vertices) {
      EXPECT_NEAR(m.vertices[v][0], m.crack_radius_m, 1e-15) << tip;
      deepest = std::max(deepest, -m.vertices[v][1]);
      shallowest = std::min(shallowest, -m.vertices[v][1]);
    }
    EXPECT_NEAR(shallowest, 0.0, 1e-15) << "the face starts at the surface";
    EXPECT_GE(deepest, s.insertion.target_depth_m) << "the face reaches the target depth";
    EXPECT_LE(deepest, m.path_depth_m + 1e-15);
    // No cell inside the channel; below the path the axis is material again.
    bool below = false;
    for (std::size_t c = 0; c < m.cells.size(); ++c) {
      const double rc = 0.5 * (m.vertices[m.cells[c][0]][0] + m.vertices[m.cells[c][3]][0]);
      const double zc = 0.5 * (m.vertices[m.cells[c][0]][1] + m.vertices[m.cells[c][3]][1]);
      if (rc < m.crack_radius_m) {
        EXPECT_GT(-zc, m.path_depth_m) << tip << ": cell " << c << " inside the channel";
        below = true;
      }
    }
    EXPECT_TRUE(below) << tip;
  }
}

TEST(AxisymmetricSlabMesh, RefinementHalvesEveryElement) {
  const Scene s = three_layers("bevel");
  const auto m0 = build_axisymmetric_slab_mesh(s, 0), m1 = build_axisymmetric_slab_mesh(s, 1);
  EXPECT_EQ(m1.radial_lines_m.size() - 1, 2 * (m0.radial_lines_m.size() - 1));
  EXPECT_EQ(m1.axial_lines_m.size() - 1, 2 * (m0.axial_lines_m.size() - 1));
  EXPECT_EQ(m1.cells.size(), 4 * m0.cells.size());
  EXPECT_NEAR(m1.tip_element_size_m, 0.5 * m0.tip_element_size_m, 1e-15);
}

TEST(AxisymmetricSlabMesh, RejectsInvalidGeometryNamingTheField) {
  Scene s = three_layers("bevel");
  s.layers[1].thickness_m = -1e-3;
  try {
    build_axisymmetric_slab_mesh(s, 0);
    FAIL() << "negative thickness accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("layers[1].thickness_m"), std::string::npos) << e.what();
  }
  s = three_layers("bevel");
  s.needle.radius_m = 0.02;
  EXPECT_THROW(build_axisymmetric_slab_mesh(s, 0), std::invalid_argument);
  s = three_layers("bevel");
  EXPECT_THROW(build_axisymmetric_slab_mesh(s, 5), std::invalid_argument);
}

TEST(AxisymmetricSlabMesh, MeshIsTheSameWhateverTheTargetDepth) {
  // The mesh is a property of the layers, not of where the insertion stops:
  // the needle path (fine lines and crack line) runs through the whole slab,
  // ending one tip element (h_tip = a / 4 here) above the base, so meshes for
  // 30, 20 and 12.3 mm are one mesh.
  Scene s = three_layers("bevel");
  s.fem.mesh.elements_per_needle_radius = 4;
  s.fem.mesh.path_element_size_mm = 0.4;
  const double H = s.total_thickness_m(), h_tip = s.needle.radius_m / 4;
  std::vector<AxisymmetricSlabMesh> meshes;
  for (double target : {30e-3, 20e-3, 12.3e-3}) {
    s.insertion.target_depth_m = target;
    meshes.push_back(build_axisymmetric_slab_mesh(s, 0));
    EXPECT_NEAR(meshes.back().path_depth_m, H - h_tip, 1e-15);
    EXPECT_NEAR(meshes.back().axial_lines_m.end()[-2], -(H - h_tip), 1e-15) << "the path depth is a line";
  }
  for (std::size_t m = 1; m < meshes.size(); ++m) {
    EXPECT_EQ(meshes[m].path_depth_m, meshes[0].path_depth_m);
    EXPECT_EQ(meshes[m].radial_lines_m, meshes[0].radial_lines_m);
    EXPECT_EQ(meshes[m].axial_lines_m, meshes[0].axial_lines_m);
    EXPECT_EQ(meshes[m].cells, meshes[0].cells);
    EXPECT_EQ(meshes[m].crack_face_vertices, meshes[0].crack_face_vertices);
  }
}
