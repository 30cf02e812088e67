// layered_cylinder_mesh.hpp: hexahedral mesh of the layered cylindrical tissue
// sample of a Scene, for the deal.II reference (reference_fem/). Eigen only.
//
// In:  a Scene (core/include/puncture/scene.hpp; SI units): sample diameter,
//      layer thicknesses (top = skin first), needle radius; SlabMeshOptions.
// Out: HexMesh: vertices in m (scene frame: axis = z, skin top at z = 0, base at
//      z = -total thickness), hexahedra as 8 vertex indices in deal.II
//      lexicographic order, one material id (layer index) per cell.
//
// Layout of the cross-section (every node plane has the same 2D layout):
//   * an O-grid inside the needle disc: a central block of (sectors/4) x
//     (sectors/4) cells (rounded squares, a blend of square and circle) and a
//     transition ring of `sectors` cells whose outer nodes lie exactly on the
//     circle r = needle radius. These cells, and only these, have their centre
//     inside the needle radius: they form a column on the axis (the needle
//     path). Scaled Jacobian >= 0.7 for every `sectors`;
//   * annuli of `sectors` cells from r = needle radius to r = sample radius,
//     radial size starting near the needle radius and growing geometrically
//     by `radial_grading`. The outer boundary is the polygon of `sectors`
//     straight edges inscribed in the circle of the sample radius.
// Through the thickness: every layer interface is a node plane; the element
// height at a layer top is h0 = min(skin thickness / elements_through_skin,
// needle radius). The skin (layer 0) gets `elements_through_skin` equal
// elements when they are no taller than the needle radius, else (a thick
// first layer, e.g. a one-layer block) it is graded from h0 like the others;
// every other layer starts with elements of about h0 at its top surface
// (where the needle meets it) and grows them geometrically by
// `thickness_grading` downward (thin layers end up uniform).
#pragma once

#include <puncture/meshing/hex_mesh.hpp>
#include <puncture/scene.hpp>

namespace puncture::meshing {

/// Resolution knobs of build_layered_cylinder_mesh.
struct SlabMeshOptions {
  int elements_through_skin = 2;  ///< equal elements through layer 0 (>= 1)
  double radial_grading = 1.25;   ///< ratio of neighbouring annulus widths, outward (>= 1)
  int sectors = 16;               ///< cells around the circumference (multiple of 4, >= 4)
  double thickness_grading = 1.15;  ///< ratio of neighbouring element heights, downward inside a layer (>= 1)
};

/// Builds the mesh. Throws std::invalid_argument naming the offending field
/// (e.g. "layers[1].thickness_m", "needle.radius_m", "options.sectors") for
/// no layers, non-positive sizes, a needle radius >= the sample radius, or
/// options out of range.
HexMesh build_layered_cylinder_mesh(const Scene& scene, const SlabMeshOptions& options);

}  // namespace puncture::meshing
