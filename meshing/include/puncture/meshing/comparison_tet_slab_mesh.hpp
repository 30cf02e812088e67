// comparison_tet_slab_mesh.hpp: the tetrahedral mesh of the slab that the
// volumetric comparison models run on, by the scene's choice
// (scene.comparison.mesh.kind):
//   "extruded"  plan triangulation extruded through the layers
//               (extruded_tet_slab_mesh.hpp; the default: its vertex count
//               follows the mesh sizes, the thin skin included)
//   "delaunay"  CGAL Mesh_3 Delaunay refinement (tet_slab_mesh.hpp)
// In: a Scene. Out: the mesh and, optionally, what was built (kind, one-line
// description, vertices, tetrahedra, quality, wall time).
// Throws std::invalid_argument for an unknown kind or bad geometry.
#pragma once

#include <string>

#include "puncture/meshing/tet_mesh.hpp"
#include "puncture/scene.hpp"

namespace puncture::meshing {

struct ComparisonTetMeshReport {
  std::string kind;         ///< "extruded" or "delaunay"
  std::string description;  ///< e.g. "extruded plan triangulation: 151 plan nodes x 40 levels"
  double wall_time_s = 0.0;
  int vertices = 0;
  int tetrahedra = 0;
  TetQuality quality;
};

TetMesh build_comparison_tet_mesh(const Scene& scene, ComparisonTetMeshReport* report = nullptr);

}  // namespace puncture::meshing
