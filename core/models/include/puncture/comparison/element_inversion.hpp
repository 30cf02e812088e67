// element_inversion.hpp: how far a deformed tetrahedral mesh has turned
// inside out.
//
// Per tetrahedron J = V / V0, the signed volume at the deformed positions over
// the one at rest (for a P1 element J = det F, F its deformation gradient). A
// tetrahedron with J <= 0 is inverted: no elastic body passes through such a
// state (the FEM reference's Newton rejects it, reference_fem), so a model's
// force while its mesh holds inverted elements has no continuum meaning
// there. The comparison reports it beside the force and deflection errors.
//
// In:  mesh (rest positions, tetrahedra), x_m the deformed node positions
//      (3N, m, node-major x0 y0 z0 x1 ...), removed (M flags, 1 = no longer
//      part of the body, e.g. the needle column of a broken layer; empty =
//      none removed).
// Out: the count of remaining and of inverted tetrahedra and the smallest J.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "puncture/meshing/tet_mesh.hpp"

namespace puncture::comparison {

using meshing::TetMesh;  // the comparison models work on meshing's tetrahedral slab

struct ElementInversion {
  long elements = 0;  ///< tetrahedra counted (the remaining ones); 0: no tetrahedral mesh
  long inverted = 0;  ///< of them with J <= 0
  double min_volume_ratio = std::numeric_limits<double>::quiet_NaN();  ///< smallest J (NaN if elements == 0)

  double inverted_share() const {
    return elements > 0 ? static_cast<double>(inverted) / static_cast<double>(elements)
                        : std::numeric_limits<double>::quiet_NaN();
  }
};

/// Throws std::invalid_argument if x_m is not 3N long or removed is neither
/// empty nor M long.
ElementInversion measure_element_inversion(const TetMesh& mesh, const Eigen::Ref<const Eigen::VectorXd>& x_m,
                                           const std::vector<std::uint8_t>& removed = {});

}  // namespace puncture::comparison
