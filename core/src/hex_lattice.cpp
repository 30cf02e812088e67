#include "puncture/hex_lattice.hpp"

#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

namespace puncture {

Eigen::Vector2d HexLattice::planar_position(int node, double spacing_m) const {
  const Eigen::Vector2i& a = axial[node];
  return spacing_m * Eigen::Vector2d(a.x() + 0.5 * a.y(), 0.5 * std::sqrt(3.0) * a.y());
}

int hex_lattice_node_count(int rings_w) { return 1 + 3 * rings_w * (rings_w - 1); }

HexLattice make_hex_lattice(int rings_w) {
  if (rings_w < 1)
    throw std::invalid_argument("force mesh: rings_w must be >= 1 (got " + std::to_string(rings_w) + ")");
  // The six axial directions, in walking order around a ring.
  static const int dir[6][2] = {{1, 0}, {1, -1}, {0, -1}, {-1, 0}, {-1, 1}, {0, 1}};

  HexLattice lat;
  lat.rings_w = rings_w;
  const int n = hex_lattice_node_count(rings_w);
  lat.axial.reserve(n);
  lat.ring.reserve(n);
  lat.axial.emplace_back(0, 0);
  lat.ring.push_back(1);
  for (int d = 1; d < rings_w; ++d) {
    // Start at d * direction 4 and walk d steps along each of the six sides.
    int q = dir[4][0] * d, r = dir[4][1] * d;
    for (int side = 0; side < 6; ++side)
      for (int step = 0; step < d; ++step) {
        lat.axial.emplace_back(q, r);
        lat.ring.push_back(d + 1);
        q += dir[side][0];
        r += dir[side][1];
      }
  }

  std::map<std::pair<int, int>, int> index;
  for (int i = 0; i < n; ++i) index[{lat.axial[i].x(), lat.axial[i].y()}] = i;
  lat.neighbour_offsets.assign(1, 0);
  for (int i = 0; i < n; ++i) {
    for (const auto& dd : dir) {
      auto it = index.find({lat.axial[i].x() + dd[0], lat.axial[i].y() + dd[1]});
      if (it != index.end()) lat.neighbours.push_back(it->second);
    }
    lat.neighbour_offsets.push_back(static_cast<int>(lat.neighbours.size()));
  }
  return lat;
}

}  // namespace puncture
