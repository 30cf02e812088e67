// layer_surface_probe.cpp: a layer's top-face deflection at given points of
// the plan, interpolated on the tetrahedral mesh; see LayerSurfaceProbe in
// volumetric_model.hpp.
#include <cmath>

#include "puncture/comparison/volumetric_model.hpp"

namespace puncture::comparison {

namespace {

constexpr double kGeometryTolerance_m = 1e-6;

/// Triangles of the layer's top face: faces of its tetrahedra on z = top.
std::vector<Eigen::Vector3i> top_triangles(const TetMesh& mesh, int layer, double top_z_m) {
  static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  std::vector<Eigen::Vector3i> triangles;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    if (mesh.layer[t] != layer) continue;
    for (const auto& face : kFaces) {
      bool on_top = true;
      Eigen::Vector3i tri;
      for (int i = 0; i < 3; ++i) {
        tri[i] = mesh.tets[t][face[i]];
        on_top = on_top && std::abs(mesh.points_m(2, tri[i]) - top_z_m) < kGeometryTolerance_m;
      }
      if (on_top) triangles.push_back(tri);
    }
  }
  return triangles;
}

bool barycentric(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                 Eigen::Vector3d& w) {
  const double det = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  if (std::abs(det) < 1e-30) return false;
  const double l1 = ((p - a).x() * (c - a).y() - (p - a).y() * (c - a).x()) / det;
  const double l2 = ((b - a).x() * (p - a).y() - (b - a).y() * (p - a).x()) / det;
  w = Eigen::Vector3d(1.0 - l1 - l2, l1, l2);
  return w.minCoeff() >= -1e-9;
}

}  // namespace

LayerSurfaceProbe::LayerSurfaceProbe(const TetMesh& mesh, int layer, double top_z_m,
                                     const std::vector<Eigen::Vector2d>& points) {
  const std::vector<Eigen::Vector3i> triangles = top_triangles(mesh, layer, top_z_m);
  nodes_.assign(points.size(), Eigen::Vector3i::Zero());
  weights_.assign(points.size(), Eigen::Vector3d::Zero());
  found_.assign(points.size(), 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (const Eigen::Vector3i& tri : triangles) {
      const Eigen::Vector2d a = mesh.points_m.col(tri[0]).head<2>(), b = mesh.points_m.col(tri[1]).head<2>(),
                            c = mesh.points_m.col(tri[2]).head<2>();
      const Eigen::Vector2d lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
      if ((points[i].array() < lo.array() - 1e-12).any() || (points[i].array() > hi.array() + 1e-12).any()) continue;
      Eigen::Vector3d w;
      if (barycentric(points[i], a, b, c, w)) {
        nodes_[i] = tri;
        weights_[i] = w;
        found_[i] = 1;
        break;
      }
    }
  }
}

std::vector<double> LayerSurfaceProbe::deflection_m(const Eigen::VectorXd& x, const Eigen::Matrix3Xd& rest) const {
  std::vector<double> out(weights_.size(), 0.0);
  for (std::size_t i = 0; i < weights_.size(); ++i) {
    if (!found_[i]) continue;
    double uz = 0.0;
    for (int k = 0; k < 3; ++k) uz += weights_[i][k] * (x[3 * nodes_[i][k] + 2] - rest(2, nodes_[i][k]));
    out[i] = -uz;
  }
  return out;
}

}  // namespace puncture::comparison
