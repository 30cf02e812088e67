// inclined_path_mesh.hpp: bends the needle column of the layered cylinder mesh
// (layered_cylinder_mesh.hpp) onto an inclined needle path, keeping the layer
// interfaces horizontal and the sample's outer wall in place. Eigen only.
//
// In:  a HexMesh of build_layered_cylinder_mesh (m; axis = z, skin top z = 0),
//      an InclinedPath: the needle's angle a to the surface normal and its
//      azimuth b (needle.hpp: d = (sin a cos b, sin a sin b, -cos a), entry at
//      the origin), the needle radius rho, the sample radius R.
// Out: the same cells and material ids; every vertex (x, y, z) moved
//      horizontally, z unchanged:
//        p' = p + w(r) [ tan a min(-z, D) + k clamp(p . e, -r_c, r_c) ] e,
//      e = (cos b, sin b, 0) the azimuth, k = 1 / cos a - 1, D the path's
//      deepest point (the target depth), r = |(x, y)| in the input mesh,
//      r_c the core radius, and w(r) = 1 for r <= r_c, falling linearly to 0
//      at R.
//      Inside r_c the map is a shift onto the path plus a stretch by 1 / cos a
//      along e, so that the column of cells within rho of the z axis becomes
//      the inclined cylinder of radius rho about the path (a horizontal section
//      of that cylinder is an ellipse with semi-axes rho / cos a and rho):
//      its vertices on the node ring r = rho lie at distance rho from the path
//      line, down to depth D; below D the column stays vertical (the needle
//      does not go there). Layer interfaces stay node planes at their depths;
//      vertices at r = R do not move, so each layer's volume is unchanged.
// The map's Jacobian determinant is 1 + d(displacement . e)/d(p . e), at least
// 1 - (D tan a + k r_c) / (R - r_c); incline_needle_path refuses a path that
// brings this bound below kMinInclinedPathJacobian (the map would fold or
// flatten cells near the outer wall).
#pragma once

#include <Eigen/Core>

#include <puncture/meshing/hex_mesh.hpp>
#include <puncture/scene.hpp>

namespace puncture::meshing {

/// Smallest lower bound of the map's Jacobian determinant incline_needle_path accepts.
constexpr double kMinInclinedPathJacobian = 0.25;

/// The inclined needle path a mesh is bent onto (SI units, radians).
struct InclinedPath {
  double angle_rad = 0.0;        ///< a: needle to the surface normal, [0, pi/2)
  double azimuth_rad = 0.0;      ///< b: the direction the needle tilts towards, from +x towards +y
  double end_depth_m = 0.0;      ///< D: the deepest point the path follows (the target depth), > 0
  double needle_radius_m = 0.0;  ///< rho: the column's radius (the mesh's node ring), > 0
  double sample_radius_m = 0.0;  ///< R: the mesh's outer radius, > core radius
  double core_radius_m = 0.0;    ///< r_c: the map is a shift and stretch inside it; 0 = 4 rho
};

/// The path of a scene's insertion: its angle and azimuth, the target depth
/// (at most the slab's thickness), the needle radius, the sample radius, the
/// default core radius.
InclinedPath inclined_path_of(const Scene& scene);

/// The unit direction d of the path (from the entry point into the tissue).
Eigen::Vector3d path_direction(const InclinedPath& path);

/// The lower bound 1 - (D tan a + k r_c) / (R - r_c) of the map's Jacobian determinant.
double inclined_path_jacobian_bound(const InclinedPath& path);

/// Moves the vertices of `mesh` as in the header; cells and material ids stay.
/// Throws std::invalid_argument naming the field ("path.angle_rad",
/// "path.end_depth_m", "path.needle_radius_m", "path.core_radius_m",
/// "path.sample_radius_m") for a value out of range, and for a path whose
/// Jacobian bound is below kMinInclinedPathJacobian (naming the bound and what
/// would bring it up: a smaller angle or target depth, or a wider sample).
void incline_needle_path(HexMesh& mesh, const InclinedPath& path);

}  // namespace puncture::meshing
