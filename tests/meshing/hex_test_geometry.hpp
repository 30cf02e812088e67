// hex_test_geometry.hpp: what the hexahedral mesh tests share: the paper's
// Table 2 slab as a Scene, and a trilinear hex's Jacobian and volume computed
// here, independently of hex_mesh_quality.
#pragma once

#include <puncture/meshing/hex_mesh.hpp>
#include <puncture/scene.hpp>

#include <Eigen/LU>

#include <cmath>
#include <cstddef>

namespace puncture::meshing::test {

/// Skin 0.8 mm, fat 8.4 mm, muscle 39 mm (the paper's Table 2), 18 G needle
/// (radius 0.635 mm), a sample `diameter_m` wide.
inline Scene table2_slab(double diameter_m = 0.06) {
  Scene s;
  s.sample.diameter_m = diameter_m;
  s.needle.radius_m = 0.635e-3;
  const char* names[] = {"skin", "fat", "muscle"};
  const double thickness[] = {0.8e-3, 8.4e-3, 39e-3};
  for (int i = 0; i < 3; ++i) {
    Layer l;
    l.name = names[i];
    l.thickness_m = thickness[i];
    s.layers.push_back(l);
  }
  return s;
}

/// det J of cell c (trilinear, deal.II vertex order) at reference point (x, y, z) in [0, 1]^3.
inline double hex_jacobian(const HexMesh& mesh, std::size_t c, double x, double y, double z) {
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  for (int k = 0; k < 8; ++k) {
    const int i = k & 1, j = (k >> 1) & 1, l = (k >> 2) & 1;
    const double wx = i ? x : 1 - x, wy = j ? y : 1 - y, wz = l ? z : 1 - z;
    const double dx = i ? 1 : -1, dy = j ? 1 : -1, dz = l ? 1 : -1;
    const Eigen::Vector3d& v = mesh.vertices[mesh.cells[c][k]];
    J.col(0) += v * dx * wy * wz;
    J.col(1) += v * wx * dy * wz;
    J.col(2) += v * wx * wy * dz;
  }
  return J.determinant();
}

/// The two Gauss points of [0, 1] (2x2x2 quadrature of det J is exact for a
/// trilinear hex: det J is at most quadratic in each reference coordinate).
inline const double* gauss_points_01() {
  static const double g[2] = {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)};
  return g;
}

/// Volume of cell c by 2x2x2 Gauss quadrature of det J.
inline double hex_volume(const HexMesh& mesh, std::size_t c) {
  const double* g = gauss_points_01();
  double volume = 0.0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int e = 0; e < 2; ++e) volume += hex_jacobian(mesh, c, g[a], g[b], g[e]) / 8.0;
  return volume;
}

}  // namespace puncture::meshing::test
