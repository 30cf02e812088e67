// hex_mesh_quality.hpp: shape-quality figures of a hexahedral mesh (scaled
// Jacobian at the corners, Jacobian ratio, edge aspect ratio) and counts.
//
// In: a HexMesh (m). Out: HexMeshQuality (dimensionless figures and counts).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <puncture/meshing/hex_mesh.hpp>

namespace puncture::meshing {

/// Quality and size figures of a hex mesh.
struct HexMeshQuality {
  std::size_t n_vertices = 0;
  std::size_t n_cells = 0;
  std::size_t n_displacement_dofs_q1 = 0;  ///< 3 x n_vertices
  /// Scaled Jacobian at a corner: det[e_x, e_y, e_z] / (|e_x| |e_y| |e_z|) of the
  /// three cell edges at that corner (1 for a right-angled corner, <= 0 for an
  /// inverted cell). Min and max over all 8 corners of all cells.
  double min_scaled_jacobian = 0.0;
  double max_scaled_jacobian = 0.0;
  /// Per cell: min over corners of det J / max over corners of det J; the
  /// smallest value over the mesh (1 for a parallelepiped).
  double min_jacobian_ratio = 0.0;
  /// Per cell: longest edge / shortest edge; the largest value over the mesh.
  double max_aspect_ratio = 0.0;
  std::vector<std::size_t> cells_per_material;  ///< index = material id
};

/// Measures a mesh. Throws std::invalid_argument if a cell references a
/// vertex that does not exist or material_id has the wrong size.
HexMeshQuality measure_quality(const HexMesh& mesh);

/// One-paragraph human-readable summary of a quality report.
std::string describe(const HexMeshQuality& quality);

}  // namespace puncture::meshing
