// Tests of incline_needle_path against closed-form geometry: the distance of
// the needle column's vertices from the inclined path line, the layer
// interfaces' depths, the outer wall, each layer's volume (the map moves no
// boundary, so the inscribed polygonal prism's volumes stay), positive
// Jacobians at the Gauss points, and the refusals.
#include <puncture/meshing/hex_mesh_quality.hpp>
#include <puncture/meshing/inclined_path_mesh.hpp>
#include <puncture/meshing/layered_cylinder_mesh.hpp>

#include "hex_test_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using puncture::Scene;
using puncture::meshing::HexMesh;
using puncture::meshing::InclinedPath;
using puncture::meshing::build_layered_cylinder_mesh;
using puncture::meshing::incline_needle_path;

constexpr double kDeg = 3.14159265358979323846 / 180.0;

using puncture::meshing::test::hex_jacobian;
using puncture::meshing::test::table2_slab;

struct Case {
  double angle_deg, azimuth_deg, end_depth_mm, diameter_mm;
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.angle_deg << " deg, azimuth " << c.azimuth_deg << " deg, to " << c.end_depth_mm << " mm, sample "
      << c.diameter_mm << " mm";
}

InclinedPath path_of(const Case& c) {
  InclinedPath p;
  p.angle_rad = c.angle_deg * kDeg;
  p.azimuth_rad = c.azimuth_deg * kDeg;
  p.end_depth_m = c.end_depth_mm * 1e-3;
  p.needle_radius_m = 0.635e-3;
  p.sample_radius_m = 0.5e-3 * c.diameter_mm;
  return p;
}

/// Per layer: volume by 2x2x2 Gauss quadrature of det J (exact for trilinear
/// hexes) and the smallest det J at those points over the mesh.
std::vector<double> layer_volumes(const HexMesh& mesh, double& min_det) {
  const double* g = puncture::meshing::test::gauss_points_01();
  std::vector<double> volume(3, 0.0);
  min_det = INFINITY;
  for (std::size_t c = 0; c < mesh.cells.size(); ++c)
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int k = 0; k < 2; ++k) {
          const double det = hex_jacobian(mesh, c, g[i], g[j], g[k]);
          min_det = std::min(min_det, det);
          volume[mesh.material_id[c]] += det / 8.0;
        }
  return volume;
}

/// Distance of p from the line through the origin along unit d.
double distance_from_line(const Eigen::Vector3d& p, const Eigen::Vector3d& d) { return (p - p.dot(d) * d).norm(); }

}  // namespace

TEST(InclinedPathMesh, LeavesTheMeshAsItIsAlongTheNormal) {
  const HexMesh original = build_layered_cylinder_mesh(table2_slab(0.06), {});
  HexMesh mesh = original;
  incline_needle_path(mesh, path_of({0.0, 30.0, 20.0, 60.0}));
  ASSERT_EQ(mesh.vertices.size(), original.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) EXPECT_EQ(mesh.vertices[i], original.vertices[i]);
}

class InclinedPathMeshCases : public ::testing::TestWithParam<Case> {};

TEST_P(InclinedPathMeshCases, KeepsTheLayersAndTheWallAndPutsTheColumnOnThePath) {
  const Case c = GetParam();
  const InclinedPath path = path_of(c);
  const Scene scene = table2_slab(c.diameter_mm * 1e-3);
  const HexMesh original = build_layered_cylinder_mesh(scene, {});
  HexMesh mesh = original;
  incline_needle_path(mesh, path);
  ASSERT_EQ(mesh.cells, original.cells);
  ASSERT_EQ(mesh.material_id, original.material_id);

  const Eigen::Vector3d d = puncture::meshing::path_direction(path);
  EXPECT_NEAR(d.x(), std::sin(c.angle_deg * kDeg) * std::cos(c.azimuth_deg * kDeg), 1e-15);
  EXPECT_NEAR(d.y(), std::sin(c.angle_deg * kDeg) * std::sin(c.azimuth_deg * kDeg), 1e-15);
  const double rho = path.needle_radius_m, R = path.sample_radius_m, D = path.end_depth_m;
  int ring = 0, axis = 0;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d &p = original.vertices[i], &q = mesh.vertices[i];
    ASSERT_EQ(q.z(), p.z()) << "vertex " << i;  // every node plane, layer interfaces too, stays at its depth
    const double r = std::hypot(p.x(), p.y());
    if (r >= R * (1.0 - 1e-12)) EXPECT_EQ(q, p) << "the outer wall moved at vertex " << i;
    if (-p.z() > D + 1e-12) continue;
    // Down to the path's end the column is the needle's cylinder about the inclined line.
    if (r < 1e-12) {
      EXPECT_NEAR(distance_from_line(q, d), 0.0, 1e-15) << "axis vertex " << i;
      ++axis;
    } else if (std::abs(r - rho) < 1e-12) {
      EXPECT_NEAR(distance_from_line(q, d), rho, 1e-12 * rho) << "ring vertex " << i;
      ++ring;
    } else if (r < rho) {
      EXPECT_LT(distance_from_line(q, d), rho) << "column vertex " << i;
    } else {
      EXPECT_GT(distance_from_line(q, d), rho * (1.0 - 1e-12)) << "vertex " << i << " outside the column";
    }
  }
  EXPECT_GT(ring, 16 * 10);  // the ring's 16 nodes on at least ten node planes
  EXPECT_GT(axis, 10);
  // Below the path's end the column goes on vertically from where the path ends.
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d &p = original.vertices[i], &q = mesh.vertices[i];
    if (std::hypot(p.x(), p.y()) < 1e-12 && -p.z() > D) {
      const Eigen::Vector3d end = D / std::cos(c.angle_deg * kDeg) * d;
      EXPECT_NEAR(q.x(), end.x(), 1e-15);
      EXPECT_NEAR(q.y(), end.y(), 1e-15);
    }
  }
  // Nothing on the boundary moved out of its plane or wall, so each layer keeps its volume.
  double min_det_original = 0.0, min_det = 0.0;
  const std::vector<double> v0 = layer_volumes(original, min_det_original);
  const std::vector<double> v1 = layer_volumes(mesh, min_det);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(v1[k], v0[k], 1e-12 * v0[k]) << "layer " << k;
  EXPECT_GT(min_det, 0.0);
  const puncture::meshing::HexMeshQuality quality = puncture::meshing::measure_quality(mesh);
  EXPECT_GT(quality.min_scaled_jacobian, 0.2) << puncture::meshing::describe(quality);
  RecordProperty("min_scaled_jacobian", testing::PrintToString(quality.min_scaled_jacobian));
  RecordProperty("jacobian_bound", testing::PrintToString(puncture::meshing::inclined_path_jacobian_bound(path)));
}

// The angles and azimuths at the target depths a 3D reference would
// use, on the default 60 mm sample and on a 100 mm one for the steeper paths.
INSTANTIATE_TEST_SUITE_P(Paths, InclinedPathMeshCases,
                         ::testing::Values(Case{15.0, 0.0, 20.0, 60.0}, Case{30.0, 0.0, 20.0, 60.0},
                                           Case{30.0, 135.0, 15.0, 60.0}, Case{45.0, 0.0, 20.0, 100.0},
                                           Case{45.0, 250.0, 12.0, 100.0}, Case{60.0, 90.0, 10.0, 100.0}));

TEST(InclinedPathMesh, RefusesAPathThatWouldFoldTheMeshNamingWhatToChange) {
  HexMesh mesh = build_layered_cylinder_mesh(table2_slab(0.06), {});
  const InclinedPath steep = path_of({45.0, 0.0, 25.0, 60.0});
  EXPECT_LT(puncture::meshing::inclined_path_jacobian_bound(steep), puncture::meshing::kMinInclinedPathJacobian);
  try {
    incline_needle_path(mesh, steep);
    FAIL() << "a path 25 mm deep at 45 deg in a 60 mm sample was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("path.angle_rad"), std::string::npos) << what;
    EXPECT_NE(what.find("widen the sample"), std::string::npos) << what;
  }
  struct Bad {
    const char* field;
    void (*edit)(InclinedPath&);
  };
  const Bad bad[] = {
      {"path.angle_rad", [](InclinedPath& p) { p.angle_rad = 2.0; }},
      {"path.angle_rad", [](InclinedPath& p) { p.angle_rad = NAN; }},
      {"path.azimuth_rad", [](InclinedPath& p) { p.azimuth_rad = INFINITY; }},
      {"path.end_depth_m", [](InclinedPath& p) { p.end_depth_m = 0.0; }},
      {"path.needle_radius_m", [](InclinedPath& p) { p.needle_radius_m = -1e-3; }},
      {"path.core_radius_m", [](InclinedPath& p) { p.core_radius_m = 0.1e-3; }},
      {"path.sample_radius_m", [](InclinedPath& p) { p.sample_radius_m = 2e-3; }},
  };
  for (const Bad& b : bad) {
    InclinedPath p = path_of({30.0, 0.0, 10.0, 60.0});
    b.edit(p);
    try {
      incline_needle_path(mesh, p);
      ADD_FAILURE() << b.field << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(b.field), std::string::npos) << e.what();
    }
  }
}
