// hex_lattice.hpp: topology of the hexagonal ring lattice of the force mesh
// (seed paper Fig. 1).
//
// In:  rings_w >= 1, the number of concentric rings (ring 1 = the contact node,
//      ring j >= 2 has 6 (j - 1) nodes).
// Out: HexLattice with N = 1 + 3 w (w - 1) nodes numbered ring by ring
//      (node 0 is the contact node), their axial hex coordinates (q, r), the
//      1-based ring index of every node and a CSR neighbour list (up to 6
//      neighbours; nodes of the outer ring have fewer).
// The planar position of node (q, r) for spacing L (m) is
//      L * (q + r / 2, sqrt(3) / 2 * r),
// so every pair of neighbours is exactly L apart (triangular lattice).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace puncture {

struct HexLattice {
  int rings_w = 1;
  std::vector<Eigen::Vector2i> axial;    ///< (q, r) per node
  std::vector<int> ring;                 ///< 1-based ring index per node
  std::vector<int> neighbour_offsets;    ///< CSR offsets, size N + 1
  std::vector<int> neighbours;           ///< CSR neighbour indices

  int node_count() const { return static_cast<int>(axial.size()); }
  int neighbour_count(int node) const { return neighbour_offsets[node + 1] - neighbour_offsets[node]; }
  /// Position of a node in the tangent plane, m, for spacing_m between neighbours.
  Eigen::Vector2d planar_position(int node, double spacing_m) const;
};

/// N = 1 + 3 w (w - 1): nodes in w rings.
int hex_lattice_node_count(int rings_w);

/// Builds the lattice; throws std::invalid_argument for rings_w < 1.
HexLattice make_hex_lattice(int rings_w);

}  // namespace puncture
