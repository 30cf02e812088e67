// tet_mesh.hpp: a tetrahedral mesh of the layered slab as plain arrays, the
// form in which the slab meshers (tet_slab_mesh.hpp with CGAL,
// extruded_tet_slab_mesh.hpp) hand it to the comparison models (core/models),
// so those need no CGAL. Library puncture_tet_mesh, Eigen only.
//
// In/out (SI units, scene frame of scene.hpp: axis = z, skin top z = 0):
//   points_m       3 x N vertex positions (m)
//   tets           M tetrahedra, 4 vertex indices each, positively oriented
//                  (det[x1-x0, x2-x0, x3-x0] > 0)
//   layer          M layer indices (0 = top layer, the skin)
//   needle_column  M flags: 1 when the tetrahedron lies inside the needle
//                  radius (the needle path; removed when its layer breaks)
//
// Quality (measure_tet_quality): the six dihedral angles of each tetrahedron
// and the radius-edge ratio (circumradius / shortest edge; 0.612 for the
// regular tetrahedron). Volumes per layer (layer_volumes_m3).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace puncture::meshing {

struct TetMesh {
  Eigen::Matrix3Xd points_m;
  std::vector<Eigen::Vector4i> tets;
  std::vector<int> layer;
  std::vector<std::uint8_t> needle_column;

  int node_count() const { return static_cast<int>(points_m.cols()); }
  int tet_count() const { return static_cast<int>(tets.size()); }
};

/// Signed volume (m^3) of the tetrahedron (a, b, c, d): det[b-a, c-a, d-a] / 6.
double tet_signed_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                         const Eigen::Vector3d& d);

/// Checks sizes, index ranges, finite coordinates, positive volumes and layer
/// indices in [0, layer_count). Throws std::invalid_argument naming the first
/// offending tetrahedron or array.
void check_tet_mesh(const TetMesh& mesh, int layer_count);

/// Sum of the tetrahedron volumes per layer (m^3), size layer_count.
std::vector<double> layer_volumes_m3(const TetMesh& mesh, int layer_count);

struct TetQuality {
  double min_dihedral_deg = 0.0;
  double max_dihedral_deg = 0.0;
  double max_radius_edge_ratio = 0.0;
  double mean_radius_edge_ratio = 0.0;
  double min_volume_m3 = 0.0;
  double min_edge_m = 0.0;
  double max_edge_m = 0.0;
  int tets_below_10_deg = 0;  ///< tetrahedra with a dihedral angle below 10 degrees
};
TetQuality measure_tet_quality(const TetMesh& mesh);

/// The six dihedral angles (degrees) of one tetrahedron.
std::vector<double> tet_dihedral_angles_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                            const Eigen::Vector3d& c, const Eigen::Vector3d& d);
/// Circumradius / shortest edge of one tetrahedron.
double tet_radius_edge_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                             const Eigen::Vector3d& d);

/// One line per quantity, for reports.
std::string describe(const TetQuality& quality);

}  // namespace puncture::meshing
