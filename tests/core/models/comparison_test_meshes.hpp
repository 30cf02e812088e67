// comparison_test_meshes.hpp: small structured tetrahedral meshes for the
// comparison-model tests: a box of n x n x n cubes, each cut into the six
// Kuhn (Freudenthal) tetrahedra 0 -> e_i -> e_i + e_j -> (1,1,1).
#pragma once

#include <array>
#include <cmath>

#include "puncture/meshing/tet_mesh.hpp"

namespace puncture::comparison::testing {

inline meshing::TetMesh kuhn_box(int n, double h, int layers = 1) {
  meshing::TetMesh mesh;
  const int m = n + 1;
  mesh.points_m.resize(3, m * m * m);
  auto id = [m](int i, int j, int k) { return i + m * (j + m * k); };
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) mesh.points_m.col(id(i, j, k)) = Eigen::Vector3d(i * h, j * h, k * h);
  const std::array<std::array<int, 3>, 6> orders{{{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& order : orders) {
          int c[3] = {i, j, k};
          Eigen::Vector4i tet;
          tet[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[order[static_cast<std::size_t>(s)]];
            tet[s + 1] = id(c[0], c[1], c[2]);
          }
          const double v = meshing::tet_signed_volume(mesh.points_m.col(tet[0]), mesh.points_m.col(tet[1]),
                                             mesh.points_m.col(tet[2]), mesh.points_m.col(tet[3]));
          if (v < 0) std::swap(tet[2], tet[3]);
          mesh.tets.push_back(tet);
          mesh.layer.push_back(std::min(layers - 1, k * layers / n));
          mesh.needle_column.push_back(0);
        }
  return mesh;
}

}  // namespace puncture::comparison::testing
