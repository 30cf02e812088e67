// scene_fields.hpp (internal to puncture_scene_io): what the reader
// (scene_reader.cpp), the checks (scene_validation.cpp) and the writer
// (scene_writer.cpp) share: the schema version, the mm factor of the *_mm
// keys and the effect names.
#pragma once

#include <set>
#include <string>

namespace puncture::detail {

constexpr double kMm = 1e-3;  ///< m per mm: keys ending in _mm are in mm
constexpr int kSchemaVersion = 1;

/// The names a scene's "effects" list may hold.
const std::set<std::string>& effect_names();

}  // namespace puncture::detail
