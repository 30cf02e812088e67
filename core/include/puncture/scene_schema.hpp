// scene_schema.hpp: every field a scene file may hold, declared once.
//
// One row per leaf of the scene JSON: its path ("*" for any array index),
// its JSON type, its unit, whether a file must give it (within its block),
// the simple range the reader enforces (in the file's unit; bounds that
// depend on other fields, e.g. a needle radius below a quarter of the sample
// radius, are the reader's alone), whether the FEM reads it (then it is part
// of the FEM reference's cache key) and whether the writer writes it (two
// older spellings are read only).
//
// The table is what the other places that name scene fields are checked
// against (tests/core/scene_io/test_scene_schema_docs.cpp and
// tests/validation/fem_cache/test_fem_reference_key.cpp): the reader rejects a
// value beyond each range naming the field's JSON path and a missing required
// field likewise; the writer writes exactly the written fields; scenes/README's
// schema table and the fuzz dictionary name every key; the FEM key's list of
// real-time-only fields agrees with the `fem` column. A new field is added
// here first; those tests then say which other place still lacks it.
#pragma once

#include <limits>
#include <string>
#include <vector>

namespace puncture {

enum class SceneFieldType { Number, Integer, String, NumberList, StringList };

/// A closed or open interval; an infinite bound is no bound.
struct SceneFieldRange {
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  bool lower_open = false;  ///< lower itself is rejected
  bool upper_open = false;  ///< upper itself is rejected
  bool bounded() const { return lower > -std::numeric_limits<double>::infinity() || upper < std::numeric_limits<double>::infinity(); }
};

struct SceneField {
  std::string path;       ///< JSON pointer, "*" for any array index: "/layers/*/thickness_mm"
  SceneFieldType type;
  std::string unit;       ///< of the value in the file ("" for none)
  bool required;          ///< must be given when its block is
  SceneFieldRange range;  ///< what the reader enforces on its own (file units)
  bool fem;               ///< read by the FEM reference (part of its cache key)
  bool written;           ///< written by scene_to_json_text (false: an older spelling, read only)
  /// The last token of the path: the key as it stands in the file.
  std::string key() const { return path.substr(path.rfind('/') + 1); }
};

/// Every field of the scene format (schema_version 1), in file order.
const std::vector<SceneField>& scene_schema();

}  // namespace puncture
