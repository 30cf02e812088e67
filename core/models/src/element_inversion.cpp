// Inverted tetrahedra of a deformed mesh (element_inversion.hpp).
#include "puncture/comparison/element_inversion.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace puncture::comparison {

ElementInversion measure_element_inversion(const TetMesh& mesh, const Eigen::Ref<const Eigen::VectorXd>& x_m,
                                           const std::vector<std::uint8_t>& removed) {
  if (x_m.size() != 3 * static_cast<Eigen::Index>(mesh.node_count()))
    throw std::invalid_argument("measure_element_inversion: " + std::to_string(x_m.size()) +
                                " coordinates for a mesh of " + std::to_string(mesh.node_count()) + " nodes");
  if (!removed.empty() && removed.size() != mesh.tets.size())
    throw std::invalid_argument("measure_element_inversion: " + std::to_string(removed.size()) +
                                " removal flags for " + std::to_string(mesh.tets.size()) + " tetrahedra");
  ElementInversion result;
  double min_ratio = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    if (!removed.empty() && removed[t]) continue;
    const Eigen::Vector4i& v = mesh.tets[t];
    const double rest = meshing::tet_signed_volume(mesh.points_m.col(v[0]), mesh.points_m.col(v[1]), mesh.points_m.col(v[2]),
                                          mesh.points_m.col(v[3]));
    const double now = meshing::tet_signed_volume(x_m.segment<3>(3 * v[0]), x_m.segment<3>(3 * v[1]),
                                         x_m.segment<3>(3 * v[2]), x_m.segment<3>(3 * v[3]));
    const double ratio = now / rest;
    ++result.elements;
    if (!(ratio > 0.0)) ++result.inverted;  // a NaN position counts as inverted
    min_ratio = std::min(min_ratio, ratio);
  }
  if (result.elements > 0) result.min_volume_ratio = min_ratio;
  return result;
}

}  // namespace puncture::comparison
