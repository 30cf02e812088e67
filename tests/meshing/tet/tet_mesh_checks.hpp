// tet_mesh_checks.hpp: checks shared by the tests of the tetrahedral slab
// meshes (Delaunay and extruded).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "puncture/meshing/tet_mesh.hpp"

namespace puncture::testing {

/// Every face of the tetrahedra shared by at most two of them, and every face
/// of one only on the slab's outer surface: the top z = 0, the base z = -H or
/// the side r = R (within side_tolerance_m). Returns the boundary faces.
inline int check_closed_tiling(const meshing::TetMesh& mesh, double R, double H, double side_tolerance_m,
                               double plane_tolerance_m) {
  std::map<std::array<int, 3>, int> faces;
  static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (const Eigen::Vector4i& t : mesh.tets)
    for (const auto& f : kFaces) {
      std::array<int, 3> key{t[f[0]], t[f[1]], t[f[2]]};
      std::sort(key.begin(), key.end());
      ++faces[key];
    }
  int boundary = 0;
  for (const auto& [key, count] : faces) {
    EXPECT_LE(count, 2);
    if (count != 1) continue;
    ++boundary;
    bool on_top = true, on_base = true, on_side = true;
    for (int v : key) {
      const Eigen::Vector3d p = mesh.points_m.col(v);
      on_top = on_top && std::abs(p.z()) < plane_tolerance_m;
      on_base = on_base && std::abs(p.z() + H) < plane_tolerance_m;
      on_side = on_side && std::abs(std::hypot(p.x(), p.y()) - R) < side_tolerance_m;
    }
    EXPECT_TRUE(on_top || on_base || on_side) << "a boundary face inside the slab (a hole or a non-conforming face)";
  }
  return boundary;
}

}  // namespace puncture::testing
