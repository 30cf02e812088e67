#include <puncture/meshing/hex_mesh_quality.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace puncture::meshing {

HexMeshQuality measure_quality(const HexMesh& mesh) {
  if (mesh.material_id.size() != mesh.cells.size())
    throw std::invalid_argument("measure_quality: material_id has " +
                                std::to_string(mesh.material_id.size()) + " entries for " +
                                std::to_string(mesh.cells.size()) + " cells");
  HexMeshQuality q;
  q.n_vertices = mesh.vertices.size();
  q.n_cells = mesh.cells.size();
  q.n_displacement_dofs_q1 = 3 * mesh.vertices.size();
  if (mesh.cells.empty()) return q;
  q.min_scaled_jacobian = HUGE_VAL;
  q.max_scaled_jacobian = -HUGE_VAL;
  q.min_jacobian_ratio = HUGE_VAL;
  q.max_aspect_ratio = 0.0;

  // The 12 edges of a lexicographic hex.
  static constexpr int edges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                       {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  for (std::size_t c = 0; c < mesh.cells.size(); ++c) {
    const auto& cell = mesh.cells[c];
    Eigen::Vector3d v[8];
    for (int k = 0; k < 8; ++k) {
      if (cell[k] >= mesh.vertices.size())
        throw std::invalid_argument("measure_quality: cell " + std::to_string(c) +
                                    " references missing vertex " + std::to_string(cell[k]));
      v[k] = mesh.vertices[cell[k]];
    }
    double det_min = HUGE_VAL, det_max = -HUGE_VAL;
    for (int k = 0; k < 8; ++k) {
      // Corner (i, j, l) = bits of k; the Jacobian columns of the trilinear map
      // there are the edges through the corner along local x, y, z.
      const Eigen::Vector3d ex = v[k | 1] - v[k & ~1];
      const Eigen::Vector3d ey = v[k | 2] - v[k & ~2];
      const Eigen::Vector3d ez = v[k | 4] - v[k & ~4];
      const double det = ex.dot(ey.cross(ez));
      const double scale = ex.norm() * ey.norm() * ez.norm();
      const double scaled = scale > 0.0 ? det / scale : -1.0;
      q.min_scaled_jacobian = std::min(q.min_scaled_jacobian, scaled);
      q.max_scaled_jacobian = std::max(q.max_scaled_jacobian, scaled);
      det_min = std::min(det_min, det);
      det_max = std::max(det_max, det);
    }
    q.min_jacobian_ratio = std::min(q.min_jacobian_ratio, det_max > 0.0 ? det_min / det_max : -1.0);
    double shortest = HUGE_VAL, longest = 0.0;
    for (const auto& e : edges) {
      const double len = (v[e[1]] - v[e[0]]).norm();
      shortest = std::min(shortest, len);
      longest = std::max(longest, len);
    }
    q.max_aspect_ratio = std::max(q.max_aspect_ratio, shortest > 0.0 ? longest / shortest : HUGE_VAL);
    const int m = mesh.material_id[c];
    if (m < 0) throw std::invalid_argument("measure_quality: negative material id in cell " +
                                           std::to_string(c));
    if (static_cast<std::size_t>(m) >= q.cells_per_material.size())
      q.cells_per_material.resize(static_cast<std::size_t>(m) + 1, 0);
    ++q.cells_per_material[static_cast<std::size_t>(m)];
  }
  return q;
}

std::string describe(const HexMeshQuality& q) {
  std::ostringstream out;
  out << q.n_vertices << " vertices, " << q.n_cells << " hexahedra, " << q.n_displacement_dofs_q1
      << " Q1 displacement DoFs; scaled Jacobian in [" << q.min_scaled_jacobian << ", "
      << q.max_scaled_jacobian << "], min Jacobian ratio " << q.min_jacobian_ratio
      << ", max aspect ratio " << q.max_aspect_ratio << "; cells per material:";
  for (std::size_t m = 0; m < q.cells_per_material.size(); ++m)
    out << ' ' << m << ':' << q.cells_per_material[m];
  return out.str();
}

}  // namespace puncture::meshing
