// The force mesh as a surface field: lattice triangulation and linear
// interpolation of node displacements (checked against closed forms).
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include <Eigen/Geometry>

#include "puncture/model/force_mesh_field.hpp"

namespace puncture {
namespace {

TEST(LatticeTriangles, CountAndEdgesAreLatticeNeighbours) {
  for (int w : {1, 2, 3, 8}) {
    const HexLattice lattice = make_hex_lattice(w);
    const Eigen::MatrixX3i tris = lattice_triangles(lattice);
    // A hexagon of side (w - 1) holds 6 (w - 1)^2 unit triangles.
    EXPECT_EQ(tris.rows(), 6 * (w - 1) * (w - 1)) << "w = " << w;
    for (Eigen::Index t = 0; t < tris.rows(); ++t) {
      for (int e = 0; e < 3; ++e) {
        const int a = tris(t, e), b = tris(t, (e + 1) % 3);
        const Eigen::Vector2d d = lattice.planar_position(a, 1.0) - lattice.planar_position(b, 1.0);
        EXPECT_NEAR(d.norm(), 1.0, 1e-12);  // every edge joins lattice neighbours
      }
      // Counter-clockwise in the plane (positive signed area sqrt(3)/4).
      const Eigen::Vector2d p0 = lattice.planar_position(tris(t, 0), 1.0);
      const Eigen::Vector2d p1 = lattice.planar_position(tris(t, 1), 1.0);
      const Eigen::Vector2d p2 = lattice.planar_position(tris(t, 2), 1.0);
      const double area = 0.5 * ((p1 - p0).x() * (p2 - p0).y() - (p1 - p0).y() * (p2 - p0).x());
      EXPECT_NEAR(area, std::sqrt(3.0) / 4.0, 1e-12);
    }
  }
}

TEST(LatticeDisplacementField, ReproducesLinearFieldsExactly) {
  const int w = 4;
  const double L = 2e-3;
  const HexLattice lattice = make_hex_lattice(w);
  const Eigen::Vector3d origin(0.01, -0.02, -0.003);
  const Eigen::Vector3d e1 = Eigen::Vector3d(1, 1, 0).normalized();
  const Eigen::Vector3d e2 = Eigen::Vector3d(-1, 1, 0).normalized();
  const LatticeDisplacementField field(lattice, L, origin, e1, e2);
  // Node displacement = A * (in-plane position) + c: linear interpolation is exact.
  Eigen::Matrix<double, 3, 2> A;
  A << 0.1, -0.3, 0.2, 0.05, -0.7, 0.4;
  const Eigen::Vector3d c(1e-4, -2e-4, 3e-4);
  Eigen::Matrix3Xd disp(3, lattice.node_count());
  for (int i = 0; i < lattice.node_count(); ++i) disp.col(i) = A * lattice.planar_position(i, L) + c;
  for (double x : {-3.1e-3, -1e-3, 0.0, 0.7e-3, 2.9e-3}) {
    for (double y : {-2.5e-3, -0.4e-3, 0.0, 1.3e-3, 3.0e-3}) {
      const Eigen::Vector3d p = origin + x * e1 + y * e2 + 5e-4 * e1.cross(e2);  // off-plane offset ignored
      EXPECT_NEAR((field.displacement_at(p, disp) - (A * Eigen::Vector2d(x, y) + c)).norm(), 0.0, 1e-15)
          << x << ", " << y;
    }
  }
  // At a node the field is the node's value.
  const int node = 5;
  const Eigen::Vector2d pn = lattice.planar_position(node, L);
  EXPECT_NEAR((field.displacement_at(origin + pn.x() * e1 + pn.y() * e2, disp) - disp.col(node)).norm(), 0.0, 1e-15);
  // Outside the mesh: zero.
  EXPECT_EQ(field.displacement_at(origin + 10 * w * L * e1, disp), Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace puncture
