#include "puncture/model/force_mesh_field.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace puncture {

Eigen::MatrixX3i lattice_triangles(const HexLattice& lattice) {
  const int w = lattice.rings_w;
  const int side = 2 * w - 1;
  std::vector<int> grid(static_cast<std::size_t>(side * side), -1);
  for (int i = 0; i < lattice.node_count(); ++i)
    grid[(lattice.axial[i].x() + w - 1) * side + lattice.axial[i].y() + w - 1] = i;
  auto at = [&](int q, int r) {
    if (q < -(w - 1) || q > w - 1 || r < -(w - 1) || r > w - 1) return -1;
    return grid[(q + w - 1) * side + r + w - 1];
  };
  std::vector<Eigen::Vector3i> tris;
  // Anchor (q, r) runs over the whole square of axial coordinates: a down
  // triangle can exist where its anchor is not a node.
  for (int q = -w; q <= w - 1; ++q) {
    for (int r = -w; r <= w - 1; ++r) {
      // Up triangle (q,r),(q+1,r),(q,r+1) and down triangle (q+1,r),(q+1,r+1),(q,r+1).
      const int o = at(q, r), a = at(q + 1, r), b = at(q, r + 1), c = at(q + 1, r + 1);
      if (o >= 0 && a >= 0 && b >= 0) tris.emplace_back(o, a, b);
      if (a >= 0 && b >= 0 && c >= 0) tris.emplace_back(a, c, b);
    }
  }
  Eigen::MatrixX3i out(static_cast<Eigen::Index>(tris.size()), 3);
  for (std::size_t t = 0; t < tris.size(); ++t) out.row(static_cast<Eigen::Index>(t)) = tris[t].transpose();
  return out;
}

LatticeDisplacementField::LatticeDisplacementField(const HexLattice& lattice, double spacing_m,
                                                   const Eigen::Vector3d& origin_m, const Eigen::Vector3d& e1,
                                                   const Eigen::Vector3d& e2)
    : spacing_m_(spacing_m), origin_(origin_m), e1_(e1), e2_(e2), rings_w_(lattice.rings_w) {
  const int side = 2 * rings_w_ - 1;
  grid_.assign(static_cast<std::size_t>(side * side), -1);
  for (int i = 0; i < lattice.node_count(); ++i)
    grid_[(lattice.axial[i].x() + rings_w_ - 1) * side + lattice.axial[i].y() + rings_w_ - 1] = i;
}

LatticeDisplacementField LatticeDisplacementField::of(const ForceMesh& mesh) {
  const HexLattice& lattice = mesh.lattice();
  const Eigen::Vector3d origin = mesh.rest_positions().col(0);
  const Eigen::Vector3d n = mesh.normals().col(0).normalized();
  Eigen::Vector3d e1 = n.unitOrthogonal();
  if (lattice.rings_w >= 2) {
    for (int i = 0; i < lattice.node_count(); ++i) {
      if (lattice.axial[i] == Eigen::Vector2i(1, 0)) {
        const Eigen::Vector3d d = mesh.rest_positions().col(i) - origin;
        e1 = (d - d.dot(n) * n).normalized();
      }
    }
  }
  return LatticeDisplacementField(lattice, mesh.params().spacing_L_m, origin, e1, n.cross(e1));
}

int LatticeDisplacementField::node_at(int q, int r) const {
  const int w = rings_w_;
  if (q < -(w - 1) || q > w - 1 || r < -(w - 1) || r > w - 1) return -1;
  return grid_[(q + w - 1) * (2 * w - 1) + r + w - 1];
}

Eigen::Vector3d LatticeDisplacementField::displacement_at(const Eigen::Vector3d& p_m,
                                                          const Eigen::Matrix3Xd& displacements) const {
  const Eigen::Vector3d d = p_m - origin_;
  const double x = d.dot(e1_) / spacing_m_, y = d.dot(e2_) / spacing_m_;
  // Planar position of (q, r) is (q + r / 2, sqrt(3)/2 r) in units of L.
  const double r = y / (std::sqrt(3.0) / 2.0);
  const double q = x - 0.5 * r;
  const int q0 = static_cast<int>(std::floor(q)), r0 = static_cast<int>(std::floor(r));
  const double fq = q - q0, fr = r - r0;
  int n[3];
  double wgt[3];
  if (fq + fr <= 1.0) {
    n[0] = node_at(q0, r0), n[1] = node_at(q0 + 1, r0), n[2] = node_at(q0, r0 + 1);
    wgt[0] = 1.0 - fq - fr, wgt[1] = fq, wgt[2] = fr;
  } else {
    n[0] = node_at(q0 + 1, r0 + 1), n[1] = node_at(q0, r0 + 1), n[2] = node_at(q0 + 1, r0);
    wgt[0] = fq + fr - 1.0, wgt[1] = 1.0 - fq, wgt[2] = 1.0 - fr;
  }
  if (n[0] < 0 || n[1] < 0 || n[2] < 0) return Eigen::Vector3d::Zero();
  return wgt[0] * displacements.col(n[0]) + wgt[1] * displacements.col(n[1]) + wgt[2] * displacements.col(n[2]);
}

}  // namespace puncture
