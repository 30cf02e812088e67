// vtk_unstructured.hpp: a tetrahedral mesh with point and cell data as a VTK
// XML UnstructuredGrid file (.vtu), written through an OutputSession.
//
// In:  points n x 3 (m), tetrahedra t x 4 (0-based point indices),
//      point_scalars / point_vectors (name, n values / n x 3),
//      cell_scalars (name, t values). The first array of each kind is active.
// Out: the staged file <relative_name> in the session (visible after commit).
// Encoding: vtkXMLUnstructuredGridWriter's defaults; Float64 points and arrays.
// Throws std::invalid_argument (naming the array / index) for non-finite
// values, an index out of range, an array of the wrong size, an empty or
// duplicate name; std::runtime_error if VTK fails to write.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace puncture::io {

class OutputSession;

void write_tetrahedra(OutputSession& session, const std::string& relative_name, const Eigen::MatrixX3d& points,
                      const Eigen::MatrixX4i& tetrahedra,
                      const std::vector<std::pair<std::string, Eigen::VectorXd>>& point_scalars = {},
                      const std::vector<std::pair<std::string, Eigen::MatrixX3d>>& point_vectors = {},
                      const std::vector<std::pair<std::string, Eigen::VectorXd>>& cell_scalars = {});

}  // namespace puncture::io
