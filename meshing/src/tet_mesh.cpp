// tet_mesh.cpp: checks, volumes and quality of a tetrahedral mesh; see tet_mesh.hpp.
#include "puncture/meshing/tet_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>

namespace puncture::meshing {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

double tet_signed_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                         const Eigen::Vector3d& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

void check_tet_mesh(const TetMesh& mesh, int layer_count) {
  const int n = mesh.node_count();
  const std::size_t m = mesh.tets.size();
  if (mesh.layer.size() != m || mesh.needle_column.size() != m)
    throw std::invalid_argument("TetMesh: layer (" + std::to_string(mesh.layer.size()) + ") and needle_column (" +
                                std::to_string(mesh.needle_column.size()) + ") must have one entry per tetrahedron (" +
                                std::to_string(m) + ")");
  if (!mesh.points_m.allFinite()) throw std::invalid_argument("TetMesh: non-finite point coordinate");
  for (std::size_t t = 0; t < m; ++t) {
    const Eigen::Vector4i& v = mesh.tets[t];
    for (int i = 0; i < 4; ++i)
      if (v[i] < 0 || v[i] >= n)
        throw std::invalid_argument("TetMesh: tetrahedron " + std::to_string(t) + " has vertex index " +
                                    std::to_string(v[i]) + " outside [0, " + std::to_string(n) + ")");
    if (mesh.layer[t] < 0 || mesh.layer[t] >= layer_count)
      throw std::invalid_argument("TetMesh: tetrahedron " + std::to_string(t) + " has layer " +
                                  std::to_string(mesh.layer[t]) + " outside [0, " + std::to_string(layer_count) + ")");
    const double vol = tet_signed_volume(mesh.points_m.col(v[0]), mesh.points_m.col(v[1]), mesh.points_m.col(v[2]),
                                         mesh.points_m.col(v[3]));
    if (!(vol > 0.0))
      throw std::invalid_argument("TetMesh: tetrahedron " + std::to_string(t) +
                                  " is not positively oriented (volume " + std::to_string(vol) + " m^3)");
  }
}

std::vector<double> layer_volumes_m3(const TetMesh& mesh, int layer_count) {
  std::vector<double> volume(static_cast<std::size_t>(std::max(0, layer_count)), 0.0);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const int k = mesh.layer[t];
    if (k < 0 || k >= layer_count) continue;
    const Eigen::Vector4i& v = mesh.tets[t];
    volume[static_cast<std::size_t>(k)] += std::abs(tet_signed_volume(
        mesh.points_m.col(v[0]), mesh.points_m.col(v[1]), mesh.points_m.col(v[2]), mesh.points_m.col(v[3])));
  }
  return volume;
}

std::vector<double> tet_dihedral_angles_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                            const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  // Face i is opposite vertex i; its outward normal n_i. The dihedral angle at
  // the edge shared by faces i and j is pi - angle(n_i, n_j).
  const Eigen::Vector3d p[4] = {a, b, c, d};
  Eigen::Vector3d normal[4];
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d& q0 = p[(i + 1) % 4];
    const Eigen::Vector3d& q1 = p[(i + 2) % 4];
    const Eigen::Vector3d& q2 = p[(i + 3) % 4];
    Eigen::Vector3d nrm = (q1 - q0).cross(q2 - q0);
    if (nrm.dot(p[i] - q0) > 0.0) nrm = -nrm;  // point away from the opposite vertex
    const double len = nrm.norm();
    normal[i] = len > 0.0 ? Eigen::Vector3d(nrm / len) : Eigen::Vector3d::Zero();
  }
  std::vector<double> angles;
  angles.reserve(6);
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      const double c_ij = std::clamp(normal[i].dot(normal[j]), -1.0, 1.0);
      angles.push_back((kPi - std::acos(c_ij)) * 180.0 / kPi);
    }
  return angles;
}

double tet_radius_edge_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                             const Eigen::Vector3d& d) {
  // Circumcentre x solves 2 (p_i - a) . x' = |p_i - a|^2 for x' = x - a.
  Eigen::Matrix3d A;
  A.row(0) = 2.0 * (b - a).transpose();
  A.row(1) = 2.0 * (c - a).transpose();
  A.row(2) = 2.0 * (d - a).transpose();
  const Eigen::Vector3d rhs((b - a).squaredNorm(), (c - a).squaredNorm(), (d - a).squaredNorm());
  const Eigen::Vector3d centre = A.fullPivLu().solve(rhs);
  const double radius = centre.norm();
  const Eigen::Vector3d p[4] = {a, b, c, d};
  double shortest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) shortest = std::min(shortest, (p[i] - p[j]).norm());
  return radius / shortest;
}

TetQuality measure_tet_quality(const TetMesh& mesh) {
  TetQuality q;
  if (mesh.tets.empty()) return q;
  q.min_dihedral_deg = 180.0;
  q.min_volume_m3 = std::numeric_limits<double>::infinity();
  q.min_edge_m = std::numeric_limits<double>::infinity();
  double sum_ratio = 0.0;
  for (const Eigen::Vector4i& v : mesh.tets) {
    const Eigen::Vector3d a = mesh.points_m.col(v[0]), b = mesh.points_m.col(v[1]), c = mesh.points_m.col(v[2]),
                          d = mesh.points_m.col(v[3]);
    const std::vector<double> angles = tet_dihedral_angles_deg(a, b, c, d);
    const double lo = *std::min_element(angles.begin(), angles.end());
    const double hi = *std::max_element(angles.begin(), angles.end());
    q.min_dihedral_deg = std::min(q.min_dihedral_deg, lo);
    q.max_dihedral_deg = std::max(q.max_dihedral_deg, hi);
    if (lo < 10.0) ++q.tets_below_10_deg;
    const double ratio = tet_radius_edge_ratio(a, b, c, d);
    q.max_radius_edge_ratio = std::max(q.max_radius_edge_ratio, ratio);
    sum_ratio += ratio;
    q.min_volume_m3 = std::min(q.min_volume_m3, tet_signed_volume(a, b, c, d));
    const Eigen::Vector3d p[4] = {a, b, c, d};
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const double e = (p[i] - p[j]).norm();
        q.min_edge_m = std::min(q.min_edge_m, e);
        q.max_edge_m = std::max(q.max_edge_m, e);
      }
  }
  q.mean_radius_edge_ratio = sum_ratio / static_cast<double>(mesh.tets.size());
  return q;
}

std::string describe(const TetQuality& q) {
  std::ostringstream s;
  s << "dihedral angles " << q.min_dihedral_deg << " .. " << q.max_dihedral_deg << " deg ("
    << q.tets_below_10_deg << " tetrahedra below 10 deg), radius-edge ratio max " << q.max_radius_edge_ratio
    << " mean " << q.mean_radius_edge_ratio << ", edges " << q.min_edge_m * 1e3 << " .. " << q.max_edge_m * 1e3
    << " mm, smallest volume " << q.min_volume_m3 * 1e9 << " mm^3";
  return s.str();
}

}  // namespace puncture::meshing
