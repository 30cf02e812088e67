// force_mesh_field.hpp: the force mesh as a surface field, for output and for
// comparing with the FEM deflection.
//
// lattice_triangles(lattice):
//   In:  a HexLattice (w rings). Out: (T x 3) node indices of the triangles of
//        the triangular lattice, counter-clockwise seen from +normal
//        (T = 6 (w - 1)^2).
// LatticeDisplacementField:
//   Built from a lattice, its spacing L (m) and the contact point/tangent frame
//   in which the lattice was laid out (origin = contact node rest position,
//   e1/e2 = in-plane axes used for planar_position). displacement_at(p)
//   linearly interpolates the node displacements (current - rest, m) over the
//   lattice triangle that contains the in-plane projection of p; zero outside
//   the mesh.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "puncture/force_mesh.hpp"
#include "puncture/hex_lattice.hpp"

namespace puncture {

Eigen::MatrixX3i lattice_triangles(const HexLattice& lattice);

class LatticeDisplacementField {
 public:
  LatticeDisplacementField(const HexLattice& lattice, double spacing_m, const Eigen::Vector3d& origin_m,
                           const Eigen::Vector3d& e1, const Eigen::Vector3d& e2);

  /// The field of a force mesh: origin at its contact node, in-plane axes
  /// recovered from the rest positions of the lattice nodes (1, 0) and (0, 1).
  static LatticeDisplacementField of(const ForceMesh& mesh);

  /// displacements: 3 x N (m), node order of the lattice.
  Eigen::Vector3d displacement_at(const Eigen::Vector3d& p_m, const Eigen::Matrix3Xd& displacements) const;

 private:
  int node_at(int q, int r) const;  ///< -1 if (q, r) is not a node
  double spacing_m_;
  Eigen::Vector3d origin_, e1_, e2_;
  int rings_w_;
  std::vector<int> grid_;  ///< (2w-1)^2 map from axial (q, r) to node index
};

}  // namespace puncture
