// scene_io.hpp: reading and writing scene files (JSON).
//
// In:  a JSON file following the schema documented in scenes/README.md
//      (lengths in mm where the key ends in _mm, everything else SI).
// Out: a validated puncture::Scene in SI units.
//
// Every problem (malformed JSON, unknown key, missing field, wrong type, NaN or
// infinite number, value out of range, unknown effect or model) throws
// SceneError whose message names the file and the JSON path of the offending
// field, e.g.
//   scenes/bad.json: /layers/1/thickness_mm: must be > 0 (got -2)
// Problems of the file itself (missing, a directory, too large) have no JSON
// path: "scenes/x.json: cannot open scene file: No such file or directory".
// A UTF-8 byte-order mark at the start is accepted; a key repeated within one
// object is an error; limits in puncture/scene_limits.hpp.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "puncture/scene.hpp"

namespace puncture {

class SceneError : public std::runtime_error {
 public:
  SceneError(const std::string& file, const std::string& json_path, const std::string& what)
      : std::runtime_error(file + ": " + (json_path.empty() ? std::string() : json_path + ": ") + what),
        file_(file),
        json_path_(json_path) {}
  const std::string& file() const { return file_; }
  const std::string& json_path() const { return json_path_; }

 private:
  std::string file_;
  std::string json_path_;
};

/// The effect names a scene's "effects" list may hold (the soak turns them all on).
const std::vector<std::string>& known_effects();

/// Loads and validates a scene file.
Scene load_scene(const std::filesystem::path& path);

/// Parses and validates scene JSON text; `source_name` is used in messages.
Scene parse_scene(const std::string& json_text, const std::string& source_name);

/// Serialises a scene back to the file schema (mm where the schema says so).
/// parse_scene(scene_to_json_text(s)) reproduces s.
std::string scene_to_json_text(const Scene& scene);

/// Checks the cross-field rules (thickness > 0, w >= 1, L > 0, force mesh
/// inside the sample, target depth inside the tissue, ...). Throws SceneError
/// naming `source_name` and the JSON path. load_scene/parse_scene call it.
void validate_scene(const Scene& scene, const std::string& source_name);

}  // namespace puncture
