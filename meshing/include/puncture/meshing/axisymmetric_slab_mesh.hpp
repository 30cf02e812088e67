// axisymmetric_slab_mesh.hpp: quadrilateral mesh of the meridian (r-z) plane
// of the layered cylindrical sample, for the axisymmetric FEM reference
// (reference_fem/). Eigen and the scene types only.
//
// In:  a Scene (SI units: sample diameter, layer thicknesses, needle radius
//      a, tip kind; not the target depth) and its FemMeshSettings; the
//      crack radius r_c (where the needle's cutting edge runs: 2a/pi for a
//      bevel, the lumen radius for a hollow needle, a for a blunt punch);
//      a refinement level (each level halves every element).
// Out: AxisymmetricSlabMesh: vertices (R, Z) in m (R >= 0 from the axis, Z = 0
//      at the skin surface, Z = -total thickness at the base); quadrilaterals
//      as 4 vertex indices in deal.II lexicographic order (R-, Z-), (R+, Z-),
//      (R-, Z+), (R+, Z+); one material id (layer index) per cell; the crack
//      line R = r_c from the surface down to the path depth. For a blunt punch
//      its vertices exist twice (core side R < r_c and outer side R > r_c) so
//      that the two sides can separate; for a cutting tip (bevel, hollow) the
//      channel R < r_c along the path has no cells (the crack plane is a plane
//      of symmetry of the cut: reference_fem ties the channel wall to it).
//
// Layout: a tensor-product grid. Radial lines: equal elements of size
// h_tip = a / elements_per_needle_radius across the core [0, r_c] and the
// needle wall [r_c, a], then sizes growing by radial_growth up to the sample
// radius. Axial lines: every layer interface and the path depth are lines;
// along the needle path (depth <= path depth = total thickness - h_tip,
// whatever the target depth) each layer starts with h_tip at
// its top surface (where the needle meets it), grows by 1.2 per element up to
// min(path_element_size, thickness / min_elements_per_layer), the element
// reaching the path depth ending on it; below it, one element to the base. Every layer gets at least
// min_elements_per_layer elements through its thickness.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include <puncture/scene.hpp>

namespace puncture::meshing {

struct AxisymmetricSlabMesh {
  std::vector<Eigen::Vector2d> vertices;       ///< (R, Z), m
  std::vector<std::array<unsigned, 4>> cells;  ///< lexicographic vertex order, positive Jacobian
  std::vector<int> material_id;                ///< per cell: layer index, 0 = skin (top)
  /// Crack line of a blunt punch: (core-side vertex, outer-side vertex) pairs
  /// at R = crack_radius, from the surface (Z = 0) downward; the vertex at the
  /// path depth is shared (not listed): the crack cannot run below it.
  std::vector<std::pair<unsigned, unsigned>> crack_vertex_pairs;
  /// Cutting tips (bevel, hollow): the channel R < crack_radius above the path
  /// depth holds no cells; its wall (these vertices, surface first) is the
  /// crack face, held by the crack's cohesive tie to the plane R = crack_radius.
  std::vector<unsigned> crack_face_vertices;
  bool open_channel = false;
  double crack_radius_m = 0.0;
  double path_depth_m = 0.0;           ///< depth of the lowest point of the crack line
  std::vector<double> radial_lines_m;  ///< R of the grid lines, increasing
  std::vector<double> axial_lines_m;   ///< Z of the grid lines, decreasing from 0
  double tip_element_size_m = 0.0;     ///< h_tip
  /// Per layer: elements through its thickness on the needle path, and the
  /// largest element height there (m).
  std::vector<int> elements_through_layer;
  std::vector<double> largest_path_element_m;
};

/// Radius of the crack line for the scene's needle tip (m): bevel 2a/pi (the
/// perimeter of the planar crack of width 2a), hollow the lumen radius, blunt a.
double crack_radius_for_tip(const Needle& needle);

/// Depth (m) down to which the crack line runs: through the whole slab to one
/// tip element above the base, whatever the target depth (so the mesh is one
/// for every target); a target below it is rejected.
double crack_path_depth(const Scene& scene);

/// Builds the mesh (see the file comment). Throws std::invalid_argument naming
/// the offending field for an invalid geometry or setting.
AxisymmetricSlabMesh build_axisymmetric_slab_mesh(const Scene& scene, int refinement = 0);

}  // namespace puncture::meshing
