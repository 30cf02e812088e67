// command_outputs.hpp: what a command wrote, read back for Python, and the
// FEM reference's files copied where the user asked.
#pragma once

#include <filesystem>

#include <pybind11/pybind11.h>

namespace puncture::python {

/// Every file the command wrote in `dir` (not below it) as a dict keyed by
/// the file's stem: .json as dicts, .csv as {column: NumPy array}, .md as
/// text; "files" lists every file below `dir` (relative paths, sorted),
/// images and VTK files included.
pybind11::dict read_outputs(const std::filesystem::path& dir);

/// Copies every file below `from` into `to` through an io::OutputSession
/// (staged, renamed when all are written: nothing half-copied).
void copy_outputs(const std::filesystem::path& from, const std::filesystem::path& to);

}  // namespace puncture::python
