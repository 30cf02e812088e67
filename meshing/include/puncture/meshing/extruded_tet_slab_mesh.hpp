// extruded_tet_slab_mesh.hpp: a tetrahedral mesh of the layered cylindrical
// slab built as a plan triangulation of the disc extruded through the layers
// (every prism split into three tetrahedra), for the comparison models of
// core/models. No CGAL: the mesh is a pure function of the scene and the
// options (the same numbers in every run and on every machine), and its
// vertex count follows the mesh sizes, also in the thin skin (the Delaunay
// mesher of tet_slab_mesh.hpp fills a 0.8 mm skin across a 60 mm disc with
// small cells, whatever the sizes say).
//
// In:  a Scene (SI units, frame of scene.hpp: cylinder of radius
//      sample.diameter_m / 2 on the z axis, skin top at z = 0, layers stacked
//      downward), ExtrudedSlabMeshOptions.
// Out: meshing::TetMesh (points 3 x N in m, positively oriented
//      tetrahedra, layer index and needle_column flag per tetrahedron).
//
// Plan (the disc r <= R): a centre node and rings of nodes. Inside the needle
// radius a: ceil(a / size_at_axis) evenly spaced rings, the last at r = a
// exactly (the needle disc's rim, so the needle column r <= a is a union of
// prisms). Outside: rings at r_{i+1} = r_i + h(r_i) with
//     h(r) = min(size_far, size_at_axis + grading (r - a)),
// stretched so the last ring lies at R. Ring i has
// max(12, round(2 pi r_i / h(r_i))) nodes, every other ring turned by half a
// node spacing; neighbouring rings are joined by a zipper (the next triangle
// advances on the ring whose next node comes first in angle), the centre by a
// fan.
// Levels (z): every layer interface is a level. Down to the deepest tip depth
// of the scene's insertion plus 2 size_at_axis, a layer part of thickness t
// gets max(min_elements_per_layer, ceil(t / size_at_axis)) equal element
// heights; below it the heights grow geometrically by (1 + grading) from
// size_at_axis (graded_divisions.hpp), at least min_elements_per_layer per
// layer part.
// Tetrahedra: the prism over plan triangle (v0 < v1 < v2, plan indices) between
// two levels is split into (b0, b1, b2, t2), (b0, b1, t1, t2), (b0, t0, t1, t2)
// (b: bottom, t: top nodes): each vertical quad face is cut along the
// diagonal from its lower plan index's bottom node to its higher plan
// index's top node, the same from both sides, so the mesh is conforming.
// Throws std::invalid_argument for bad options or scene geometry.
#pragma once

#include "puncture/meshing/tet_mesh.hpp"
#include "puncture/scene.hpp"

namespace puncture::meshing {

struct ExtrudedSlabMeshOptions {
  double size_at_axis_m = 1.0e-3;   ///< element size at the needle radius (plan and height)
  double size_far_m = 8e-3;         ///< largest plan size, far from the axis
  double grading = 0.5;             ///< growth of the plan size per metre of distance from the needle radius
  double deepest_tip_depth_m = 0.03;  ///< heights are size_at_axis down to here (+ 2 size_at_axis), graded below
  int min_elements_per_layer = 2;   ///< element heights in every layer (part)
};

/// The options of scene.comparison.mesh and the insertion's target depth.
ExtrudedSlabMeshOptions extruded_slab_mesh_options(const Scene& scene);

struct ExtrudedSlabMeshReport {
  double wall_time_s = 0.0;
  int plan_nodes = 0;       ///< nodes of the plan triangulation
  int plan_triangles = 0;
  int levels = 0;           ///< node levels in z
  int vertices = 0;
  int tetrahedra = 0;
  TetQuality quality;
};

TetMesh build_extruded_tet_slab_mesh(const Scene& scene, const ExtrudedSlabMeshOptions& options,
                                                 ExtrudedSlabMeshReport* report = nullptr);

}  // namespace puncture::meshing
