// vtk_polydata.hpp: a triangulated surface with point data as a VTK XML
// PolyData file (.vtp), written through an OutputSession.
//
// In:  vertices n x 3 (m), triangles t x 3 (0-based vertex indices),
//      point_scalars: (name, values of size n), point_vectors: (name, n x 3).
//      The first scalar and the first vector array become the active ones.
//      provenance (optional): stored as field data, one string array per
//      field (provenance_command, provenance_program_version,
//      provenance_git_revision, provenance_date_utc, provenance_machine) plus
//      coordinate_unit = "m" (vtk_xml_field_data.hpp names them).
// Out: the staged file <relative_name> in the session (visible after commit).
// Units: point coordinates are in metres (the scene frame); arrays carry
// their unit in their name (deflection_mm is in mm).
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

#include "puncture/io/provenance.hpp"

namespace puncture::io {

class OutputSession;

void write_polydata(OutputSession& session, const std::string& relative_name,
                    const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles,
                    const std::vector<std::pair<std::string, Eigen::VectorXd>>& point_scalars = {},
                    const std::vector<std::pair<std::string, Eigen::MatrixX3d>>& point_vectors = {},
                    const Provenance* provenance = nullptr);

}  // namespace puncture::io
