// Tests of build_layered_cylinder_mesh against closed-form geometry: volumes
// of the inscribed polygonal prism, node rings at the needle radius,
// conformity (every interior face shared by two cells), positive Jacobians
// computed here independently of measure_quality.
#include <puncture/meshing/layered_cylinder_mesh.hpp>
#include <puncture/meshing/hex_mesh_quality.hpp>
#include <puncture/scene_io.hpp>

#include "hex_test_geometry.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>

namespace {

using puncture::Scene;
using puncture::meshing::HexMesh;
using puncture::meshing::SlabMeshOptions;
using puncture::meshing::build_layered_cylinder_mesh;

constexpr double kPi = 3.14159265358979323846;

/// The paper's default sample (Table 2: skin 0.8 mm, fat 8.4 mm, muscle 39 mm),
/// 60 mm diameter, 18 G needle.
Scene default_scene() { return puncture::meshing::test::table2_slab(0.06); }

using puncture::meshing::test::hex_volume;

Eigen::Vector3d cell_centre(const HexMesh& mesh, std::size_t c) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (unsigned v : mesh.cells[c]) centre += mesh.vertices[v];
  return centre / 8.0;
}

double polygon_area(int sectors, double radius) {
  return 0.5 * sectors * radius * radius * std::sin(2.0 * kPi / sectors);
}

TEST(LayeredCylinderMesh, JacobianPositiveAtEveryCorner) {
  for (int sectors : {4, 8, 16, 24}) {
    SlabMeshOptions opt;
    opt.sectors = sectors;
    const HexMesh mesh = build_layered_cylinder_mesh(default_scene(), opt);
    for (std::size_t c = 0; c < mesh.cells.size(); ++c) {
      const auto& cell = mesh.cells[c];
      for (int k = 0; k < 8; ++k) {
        const auto& v = mesh.vertices;
        const Eigen::Vector3d ex = v[cell[k | 1]] - v[cell[k & ~1]];
        const Eigen::Vector3d ey = v[cell[k | 2]] - v[cell[k & ~2]];
        const Eigen::Vector3d ez = v[cell[k | 4]] - v[cell[k & ~4]];
        ASSERT_GT(ex.dot(ey.cross(ez)), 0.0) << "sectors " << sectors << " cell " << c << " corner " << k;
      }
    }
  }
}

TEST(LayeredCylinderMesh, TotalAndLayerVolumesMatchInscribedPrism) {
  const Scene scene = default_scene();
  for (int sectors : {8, 16, 32}) {
    SlabMeshOptions opt;
    opt.sectors = sectors;
    const HexMesh mesh = build_layered_cylinder_mesh(scene, opt);
    const double area = polygon_area(sectors, 0.5 * scene.sample.diameter_m);
    std::vector<double> layer_volume(scene.layers.size(), 0.0);
    double total = 0.0;
    for (std::size_t c = 0; c < mesh.cells.size(); ++c) {
      const double v = hex_volume(mesh, c);
      layer_volume.at(static_cast<std::size_t>(mesh.material_id[c])) += v;
      total += v;
    }
    EXPECT_NEAR(total, area * scene.total_thickness_m(), 1e-12 * area * scene.total_thickness_m());
    for (std::size_t l = 0; l < scene.layers.size(); ++l) {
      const double expected = area * scene.layers[l].thickness_m;
      EXPECT_NEAR(layer_volume[l], expected, 1e-12 * expected) << "layer " << l;
    }
    // The polygon converges to the circle: relative deficit ~ (2 pi / n)^2 / 6.
    const double circle = kPi * std::pow(0.5 * scene.sample.diameter_m, 2) * scene.total_thickness_m();
    EXPECT_LT(std::abs(total - circle) / circle, std::pow(2 * kPi / sectors, 2) / 6.0 * 1.01);
  }
}

TEST(LayeredCylinderMesh, MaterialIdIsTheLayerContainingTheCellCentre) {
  const Scene scene = default_scene();
  const HexMesh mesh = build_layered_cylinder_mesh(scene, SlabMeshOptions{});
  ASSERT_EQ(mesh.material_id.size(), mesh.cells.size());
  for (std::size_t c = 0; c < mesh.cells.size(); ++c) {
    const double depth = -cell_centre(mesh, c).z();
    int layer = -1;
    for (std::size_t l = 0; l < scene.layers.size(); ++l)
      if (depth > scene.layer_top_depth_m(l) && depth < scene.layer_top_depth_m(l + 1)) layer = static_cast<int>(l);
    ASSERT_EQ(mesh.material_id[c], layer) << "cell " << c << " at depth " << depth;
  }
}

TEST(LayeredCylinderMesh, OneThickLayerIsGradedFromTheNeedleRadiusNotSplitInTwo) {
  // A one-layer block 20 mm thick: two 10 mm elements through it would make
  // the indentation force far too stiff. The top element is no taller than the
  // needle radius (to within the grading) and the heights grow by the thickness grading, so the count
  // follows the thickness: about log(1 + (g - 1) t / a) / log(g) elements.
  Scene scene = default_scene();
  scene.layers.resize(1);
  scene.layers[0].thickness_m = 20e-3;
  const SlabMeshOptions opt;
  const HexMesh mesh = build_layered_cylinder_mesh(scene, opt);
  std::set<double> planes;
  for (const auto& v : mesh.vertices) planes.insert(v.z());
  std::vector<double> z(planes.rbegin(), planes.rend());
  const double a = scene.needle.radius_m, g = opt.thickness_grading, t = 20e-3;
  const double expected = std::log(1 + (g - 1) * t / a) / std::log(g);
  EXPECT_NEAR(static_cast<double>(z.size() - 1), expected, 1.0);
  EXPECT_LE(z[0] - z[1], a * g);  // the count whose first size is closest to a
  for (std::size_t k = 2; k < z.size(); ++k) EXPECT_GE(z[k - 1] - z[k], (z[k - 2] - z[k - 1]) * (1 - 1e-12));
}

TEST(LayeredCylinderMesh, SkinHasAtLeastTheRequestedElementsAndHeightsGrowDownward) {
  const Scene scene = default_scene();
  for (int n_skin : {1, 2, 3}) {
    SlabMeshOptions opt;
    opt.elements_through_skin = n_skin;
    const HexMesh mesh = build_layered_cylinder_mesh(scene, opt);
    // Distinct node-plane heights inside each layer, from the vertices.
    std::set<double> planes;
    for (const auto& v : mesh.vertices) planes.insert(v.z());
    std::vector<double> z(planes.rbegin(), planes.rend());  // top to base
    ASSERT_DOUBLE_EQ(z.front(), 0.0);
    ASSERT_DOUBLE_EQ(z.back(), -scene.total_thickness_m());
    for (std::size_t l = 0; l < scene.layers.size(); ++l) {
      const double top = -scene.layer_top_depth_m(l), bottom = -scene.layer_top_depth_m(l + 1);
      std::vector<double> heights;
      for (std::size_t k = 0; k + 1 < z.size(); ++k)
        if (z[k] <= top + 1e-15 && z[k + 1] >= bottom - 1e-15) heights.push_back(z[k] - z[k + 1]);
      ASSERT_FALSE(heights.empty()) << "layer " << l;
      double sum = 0.0;
      for (double h : heights) sum += h;
      EXPECT_NEAR(sum, scene.layers[l].thickness_m, 1e-15) << "layer " << l;
      if (l == 0) EXPECT_GE(static_cast<int>(heights.size()), n_skin);
      for (std::size_t k = 1; k < heights.size(); ++k)
        EXPECT_GE(heights[k], heights[k - 1] * (1 - 1e-12)) << "layer " << l << " element " << k;
    }
  }
}

TEST(LayeredCylinderMesh, NodeRingAtExactlyTheNeedleRadiusOnEveryInterface) {
  const Scene scene = default_scene();
  const SlabMeshOptions opt;
  const HexMesh mesh = build_layered_cylinder_mesh(scene, opt);
  const double a = scene.needle.radius_m;
  for (std::size_t l = 0; l <= scene.layers.size(); ++l) {
    const double z = -scene.layer_top_depth_m(l);
    int on_plane = 0, on_ring = 0;
    std::set<long> ring_angles;
    for (const auto& v : mesh.vertices) {
      if (v.z() != z) continue;
      ++on_plane;
      if (std::abs(std::hypot(v.x(), v.y()) - a) < 1e-14 * a) {
        ++on_ring;
        ring_angles.insert(std::lround(std::atan2(v.y(), v.x()) / (2 * kPi / opt.sectors) + 0.25 * opt.sectors));
      }
    }
    EXPECT_GT(on_plane, 0) << "interface " << l << " is not a node plane";
    EXPECT_EQ(on_ring, opt.sectors) << "interface " << l;
    EXPECT_EQ(static_cast<int>(ring_angles.size()), opt.sectors) << "ring nodes not evenly spread";
  }
}

TEST(LayeredCylinderMesh, NeedlePathCellsFormAColumnCoveringTheNeedleDisc) {
  const Scene scene = default_scene();
  const SlabMeshOptions opt;
  const HexMesh mesh = build_layered_cylinder_mesh(scene, opt);
  const double a = scene.needle.radius_m;
  // Group needle-path cells (centre inside the needle radius) by element layer
  // (centre z) and compare their xy footprints and volumes.
  std::map<double, std::set<std::pair<long, long>>> footprints;
  std::map<double, double> volume;
  std::map<double, double> height;
  for (std::size_t c = 0; c < mesh.cells.size(); ++c) {
    const Eigen::Vector3d centre = cell_centre(mesh, c);
    if (std::hypot(centre.x(), centre.y()) >= a) {
      // Outside cells must lie entirely outside the needle disc.
      for (unsigned v : mesh.cells[c])
        ASSERT_GE(std::hypot(mesh.vertices[v].x(), mesh.vertices[v].y()), a * (1 - 1e-14));
      continue;
    }
    for (unsigned v : mesh.cells[c])
      ASSERT_LE(std::hypot(mesh.vertices[v].x(), mesh.vertices[v].y()), a * (1 + 1e-14));
    footprints[centre.z()].insert({std::lround(centre.x() / a * 1e9), std::lround(centre.y() / a * 1e9)});
    volume[centre.z()] += hex_volume(mesh, c);
    height[centre.z()] = mesh.vertices[mesh.cells[c][4]].z() - mesh.vertices[mesh.cells[c][0]].z();
  }
  ASSERT_FALSE(footprints.empty());
  const auto& first = footprints.begin()->second;
  const double disc = polygon_area(opt.sectors, a);
  for (const auto& [z, fp] : footprints) {
    EXPECT_EQ(fp, first) << "needle-path cells at z = " << z << " are not above/below each other";
    EXPECT_NEAR(volume[z], disc * height[z], 1e-12 * disc * height[z]) << "z = " << z;
  }
}

TEST(LayeredCylinderMesh, VerticesUniqueAndInteriorFacesSharedByTwoCells) {
  const Scene scene = default_scene();
  const SlabMeshOptions opt;
  const HexMesh mesh = build_layered_cylinder_mesh(scene, opt);
  const double R = 0.5 * scene.sample.diameter_m, H = scene.total_thickness_m();
  // No two vertices closer than a tiny fraction of the needle radius.
  std::set<std::tuple<long, long, long>> keys;
  const double tol = 1e-6 * scene.needle.radius_m;
  for (const auto& v : mesh.vertices)
    keys.insert({std::lround(v.x() / tol), std::lround(v.y() / tol), std::lround(v.z() / tol)});
  EXPECT_EQ(keys.size(), mesh.vertices.size());
  // Every vertex is used.
  std::vector<int> used(mesh.vertices.size(), 0);
  for (const auto& cell : mesh.cells)
    for (unsigned v : cell) used.at(v) = 1;
  EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0);

  static constexpr int faces[6][4] = {{0, 2, 4, 6}, {1, 3, 5, 7}, {0, 1, 4, 5},
                                      {2, 3, 6, 7}, {0, 1, 2, 3}, {4, 5, 6, 7}};
  std::map<std::array<unsigned, 4>, int> count;
  for (const auto& cell : mesh.cells)
    for (const auto& f : faces) {
      std::array<unsigned, 4> key{cell[f[0]], cell[f[1]], cell[f[2]], cell[f[3]]};
      std::sort(key.begin(), key.end());
      ++count[key];
    }
  std::size_t boundary_faces = 0;
  for (const auto& [key, n] : count) {
    ASSERT_LE(n, 2);
    if (n == 2) continue;
    ++boundary_faces;
    // A face seen once must lie on the top, the base or the outer polygon.
    bool top = true, base = true, outer = true;
    for (unsigned v : key) {
      const auto& p = mesh.vertices[v];
      top = top && p.z() == 0.0;
      base = base && std::abs(p.z() + H) < 1e-15;
      outer = outer && std::abs(std::hypot(p.x(), p.y()) - R) < 1e-12 * R;
    }
    EXPECT_TRUE(top || base || outer) << "open interior face";
  }
  // Closed count: two caps of (cells per plane) faces plus sectors x element layers sides.
  const auto q = puncture::meshing::measure_quality(mesh);
  std::set<double> planes;
  for (const auto& v : mesh.vertices) planes.insert(v.z());
  const std::size_t element_layers = planes.size() - 1;
  const std::size_t cells_per_plane = mesh.cells.size() / element_layers;
  EXPECT_EQ(boundary_faces, 2 * cells_per_plane + static_cast<std::size_t>(opt.sectors) * element_layers);
  EXPECT_EQ(q.n_cells, mesh.cells.size());
}

TEST(LayeredCylinderMesh, DefaultSceneIsNearTheDofBudgetWithGoodShapes) {
  const HexMesh mesh = build_layered_cylinder_mesh(default_scene(), SlabMeshOptions{});
  const auto q = puncture::meshing::measure_quality(mesh);
  // Design target: about 20k Q1 displacement DoFs for the default scene.
  EXPECT_GT(q.n_displacement_dofs_q1, 14000u);
  EXPECT_LT(q.n_displacement_dofs_q1, 28000u);
  EXPECT_GT(q.min_scaled_jacobian, 0.5) << puncture::meshing::describe(q);
  EXPECT_LE(q.max_scaled_jacobian, 1.0 + 1e-12);
  ASSERT_EQ(q.cells_per_material.size(), 3u);
}

TEST(LayeredCylinderMesh, RadialAnnuliGrowGeometrically) {
  const Scene scene = default_scene();
  SlabMeshOptions opt;
  const HexMesh mesh = build_layered_cylinder_mesh(scene, opt);
  // Ring radii on the top plane outside the needle radius.
  std::set<double> radii;
  const double a = scene.needle.radius_m;
  for (const auto& v : mesh.vertices)
    if (v.z() == 0.0) {
      const double r = std::hypot(v.x(), v.y());
      if (r >= a * (1 - 1e-12)) radii.insert(std::round(r / a * 1e9) / 1e9 * a);
    }
  std::vector<double> r(radii.begin(), radii.end());
  ASSERT_GE(r.size(), 3u);
  EXPECT_NEAR(r.front(), a, 1e-12 * a);
  EXPECT_NEAR(r.back(), 0.5 * scene.sample.diameter_m, 1e-9 * a);
  for (std::size_t k = 2; k < r.size(); ++k)
    EXPECT_NEAR((r[k] - r[k - 1]) / (r[k - 1] - r[k - 2]), opt.radial_grading, 1e-6);
  // First annulus within a factor of the grading of the needle radius.
  EXPECT_GT(r[1] - r[0], a / opt.radial_grading);
  EXPECT_LT(r[1] - r[0], a * opt.radial_grading);
}

TEST(LayeredCylinderMesh, InvalidInputNamesTheField) {
  auto message_of = [](const Scene& s, const SlabMeshOptions& o) -> std::string {
    try {
      build_layered_cylinder_mesh(s, o);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no exception";
  };
  const SlabMeshOptions ok;
  Scene s = default_scene();
  s.layers[1].thickness_m = 0.0;
  EXPECT_NE(message_of(s, ok).find("layers[1].thickness_m"), std::string::npos);
  s = default_scene();
  s.layers[2].thickness_m = std::nan("");
  EXPECT_NE(message_of(s, ok).find("layers[2].thickness_m"), std::string::npos);
  s = default_scene();
  s.layers.clear();
  EXPECT_NE(message_of(s, ok).find("layers"), std::string::npos);
  s = default_scene();
  s.sample.diameter_m = -1.0;
  EXPECT_NE(message_of(s, ok).find("sample.diameter_m"), std::string::npos);
  s = default_scene();
  s.needle.radius_m = 0.0;
  EXPECT_NE(message_of(s, ok).find("needle.radius_m"), std::string::npos);
  s = default_scene();
  s.needle.radius_m = 0.5 * s.sample.diameter_m;
  EXPECT_NE(message_of(s, ok).find("needle.radius_m"), std::string::npos);
  s = default_scene();
  SlabMeshOptions bad = ok;
  bad.sectors = 10;
  EXPECT_NE(message_of(s, bad).find("options.sectors"), std::string::npos);
  bad = ok;
  bad.elements_through_skin = 0;
  EXPECT_NE(message_of(s, bad).find("options.elements_through_skin"), std::string::npos);
  bad = ok;
  bad.radial_grading = 0.9;
  EXPECT_NE(message_of(s, bad).find("options.radial_grading"), std::string::npos);
  bad = ok;
  bad.thickness_grading = 0.0;
  EXPECT_NE(message_of(s, bad).find("options.thickness_grading"), std::string::npos);
}

}  // namespace

namespace {

TEST(LayeredCylinderMesh, MeshesTheShippedDefaultSceneFile) {
  const puncture::Scene scene =
      puncture::load_scene(std::filesystem::path(PUNCTURE_SOURCE_DIR) / "scenes" / "default.json");
  const HexMesh mesh = build_layered_cylinder_mesh(scene, SlabMeshOptions{});
  const auto q = puncture::meshing::measure_quality(mesh);
  ASSERT_EQ(q.cells_per_material.size(), scene.layers.size());
  double total = 0.0;
  for (std::size_t c = 0; c < mesh.cells.size(); ++c) total += hex_volume(mesh, c);
  const double expected = polygon_area(16, 0.5 * scene.sample.diameter_m) * scene.total_thickness_m();
  EXPECT_NEAR(total, expected, 1e-12 * expected);
  EXPECT_GT(q.min_scaled_jacobian, 0.7);
}

TEST(LayeredCylinderMesh, ScaledJacobianStaysAboveSeventyPercentForAllSectorCounts) {
  // The header promises >= 0.7 for every sector count (worst case: sectors = 4,
  // a single central cell whose corners are 90 + 45 degrees).
  for (int sectors = 4; sectors <= 48; sectors += 4) {
    SlabMeshOptions opt;
    opt.sectors = sectors;
    const auto q = puncture::meshing::measure_quality(build_layered_cylinder_mesh(default_scene(), opt));
    EXPECT_GE(q.min_scaled_jacobian, std::sqrt(0.5) - 1e-12) << "sectors " << sectors;
  }
}

TEST(LayeredCylinderMesh, ThickLayersStartNearTheSkinElementHeight) {
  // The needle meets every layer's top surface: the first element below each
  // interface is within the grading factor of the skin element height.
  const Scene scene = default_scene();
  SlabMeshOptions opt;
  const HexMesh mesh = build_layered_cylinder_mesh(scene, opt);
  std::set<double> planes;
  for (const auto& v : mesh.vertices) planes.insert(v.z());
  const double h_skin = scene.layers[0].thickness_m / opt.elements_through_skin;
  for (std::size_t l = 1; l < scene.layers.size(); ++l) {
    const double top = -scene.layer_top_depth_m(l);
    auto it = planes.find(top);
    ASSERT_NE(it, planes.end()) << "interface " << l << " is not a node plane";
    ASSERT_NE(it, planes.begin());
    const double first_height = top - *std::prev(it);
    EXPECT_GT(first_height, h_skin / opt.thickness_grading) << "layer " << l;
    EXPECT_LT(first_height, h_skin * opt.thickness_grading) << "layer " << l;
  }
}

TEST(LayeredCylinderMesh, ThinLayersAndANarrowSampleStayValid) {
  // Four layers, one thinner than the skin elements; sample radius only 1.5
  // needle radii (one annulus).
  Scene s = default_scene();
  puncture::Layer thin;
  thin.thickness_m = 0.05e-3;
  s.layers.insert(s.layers.begin() + 1, thin);
  s.sample.diameter_m = 3.0 * s.needle.radius_m;
  const HexMesh mesh = build_layered_cylinder_mesh(s, SlabMeshOptions{});
  const auto q = puncture::meshing::measure_quality(mesh);
  ASSERT_EQ(q.cells_per_material.size(), 4u);
  EXPECT_GT(q.cells_per_material[1], 0u);
  EXPECT_GT(q.min_scaled_jacobian, 0.7);
  double layer_volume = 0.0;
  for (std::size_t c = 0; c < mesh.cells.size(); ++c)
    if (mesh.material_id[c] == 1) layer_volume += hex_volume(mesh, c);
  const double expected = polygon_area(16, 0.5 * s.sample.diameter_m) * thin.thickness_m;
  EXPECT_NEAR(layer_volume, expected, 1e-12 * expected);
}

}  // namespace
