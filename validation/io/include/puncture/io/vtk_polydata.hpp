// vtk_polydata.hpp: a triangulated surface with point data as a VTK XML
// PolyData file (.vtp), written through an OutputSession.
//
// In:  vertices n x 3 (m), triangles t x 3 (0-based vertex indices),
//      point_scalars: (name, values of size n), point_vectors: (name, n x 3).
//      The first scalar and the first vector array become the active ones.
// Out: the staged file <relative_name> in the session (visible after commit).
// Encoding: whatever vtkXMLPolyDataWriter does by default (appended,
// compressed, base64); points and arrays are stored as Float64 so values read
// back bit-exact.
// Throws std::invalid_argument (naming the array / index) for non-finite
// coordinates or values, an index out of range, an array of the wrong size,
// an empty or duplicate array name; std::runtime_error if VTK fails to write.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace puncture::io {

class OutputSession;

void write_polydata(OutputSession& session, const std::string& relative_name,
                    const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles,
                    const std::vector<std::pair<std::string, Eigen::VectorXd>>& point_scalars = {},
                    const std::vector<std::pair<std::string, Eigen::MatrixX3d>>& point_vectors = {});

}  // namespace puncture::io
