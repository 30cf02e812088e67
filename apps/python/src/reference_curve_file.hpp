// reference_curve_file.hpp: a reference curve given to puncture.calibrate as
// columns ({name: array}) written as the CSV the command reads
// (validation/harness curve_reader.cpp: depth_mm and force_N required;
// time_s, velocity_mm_per_s, phase, the force's parts and <layer>_state
// optional).
#pragma once

#include <filesystem>

#include <pybind11/pybind11.h>

namespace puncture::python {

/// Writes `columns` (a mapping of equal-length sequences; numbers written
/// exactly, anything else as text) to `path`. Raises puncture.InputError on
/// columns of different lengths or a non-finite number (naming the column).
void write_reference_curve(const pybind11::handle& columns, const std::filesystem::path& path);

}  // namespace puncture::python
