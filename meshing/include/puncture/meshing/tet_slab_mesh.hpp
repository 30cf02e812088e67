// tet_slab_mesh.hpp: tetrahedral mesh of the layered cylindrical slab of a
// Scene, made with CGAL Mesh_3 (Delaunay refinement of a labelled implicit
// domain with protected circular features), for the comparison models of
// core/models. The only CGAL translation unit of the project.
//
// In:  a Scene (SI units; geometry of scene.hpp: cylinder of radius
//      sample.diameter_m / 2 on the z axis, skin top at z = 0, layers stacked
//      downward), TetSlabMeshOptions.
// Out: meshing::TetMesh (plain arrays: points 3 x N in m, positively
//      oriented tetrahedra, layer index per tetrahedron, needle_column flag).
//
// Domain: every layer is split into two subdomains, the needle column
// r <= needle radius (the path the needle cuts; flagged needle_column) and the
// annulus around it, so the mesh conforms to the interfaces z = -depth_k, to
// the cylinder r = needle radius and to the sample side r = R. The circles
// r = needle radius and r = R on every interface plane are protected 1D
// features (their vertices lie exactly on them), which keeps the sharp rims
// and the needle disc exact.
// Size field (edge size, facet size and cell size): h(r) = min(size_far,
// size_at_axis + grading * max(0, r - needle radius)), graded toward the axis.
// Facet distance (surface approximation): min(0.1 h, 0.005 R), so the side of
// the sample loses well under 1 % of the volume.
// Criteria: facet angle >= 25 deg, cell radius-edge ratio <= 3; then CGAL's
// sliver exudation, run until it cannot improve any more (no time limit).
// Deterministic: the same scene and options give the same mesh (vertex
// coordinates bit for bit, the same tetrahedra in the same order) in every
// run and every process. Random choices use a fixed seed; CGAL's queues break
// ties by the creation time stamps of cells and vertices, not by address; the
// vertex numbering follows the cell order. (make_mesh_3's own exudation,
// used before, stopped at a wall-clock limit equal to the refinement time,
// so a few cells depended on the machine's load.)
// Throws std::invalid_argument for bad options or scene geometry,
// std::runtime_error if CGAL returns an empty mesh, and std::logic_error if the
// exudation reports that it stopped at a time limit (none is set).
#pragma once

#include <string>

#include "puncture/meshing/tet_mesh.hpp"
#include "puncture/scene.hpp"

namespace puncture::meshing {

struct TetSlabMeshOptions {
  double size_at_axis_m = 1.0e-3;
  double size_far_m = 8e-3;
  double grading = 0.5;
  bool exude_slivers = true;  ///< CGAL sliver exudation after refinement, run to completion
  unsigned random_seed = 0;
};

/// The options of scene.comparison.mesh.
TetSlabMeshOptions tet_slab_mesh_options(const Scene& scene);

struct TetSlabMeshReport {
  double wall_time_s = 0.0;        ///< whole call, s
  double refinement_time_s = 0.0;  ///< Delaunay refinement (make_mesh_3), s
  double exudation_time_s = 0.0;   ///< sliver exudation (0 when exude_slivers is off), s
  int vertices = 0;
  int tetrahedra = 0;
  TetQuality quality;
};

TetMesh build_tet_slab_mesh(const Scene& scene, const TetSlabMeshOptions& options,
                                        TetSlabMeshReport* report = nullptr);

}  // namespace puncture::meshing
