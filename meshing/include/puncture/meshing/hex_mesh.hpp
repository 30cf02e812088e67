// hex_mesh.hpp: the plain hexahedral mesh exchanged between meshing/ and the
// deal.II reference (which turns it into a Triangulation with CellData).
//
// Shapes: vertices n x 3 (m); cells c x 8 vertex indices; material_id c.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

namespace puncture::meshing {

/// Unstructured hexahedral mesh (trilinear cells).
struct HexMesh {
  std::vector<Eigen::Vector3d> vertices;  ///< vertex positions, m
  /// 8 vertex indices per cell in deal.II lexicographic order
  /// (0,0,0),(1,0,0),(0,1,0),(1,1,0),(0,0,1),(1,0,1),(0,1,1),(1,1,1);
  /// right-handed (positive Jacobian).
  std::vector<std::array<unsigned, 8>> cells;
  std::vector<int> material_id;  ///< per cell: layer index, 0 = skin (top)
};

}  // namespace puncture::meshing
