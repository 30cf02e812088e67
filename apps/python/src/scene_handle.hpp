// scene_handle.hpp: what a puncture.Scene holds: a validated Scene and the
// name its messages give (the file it came from, or "<dict>").
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "puncture/scene.hpp"
#include "puncture/scene_io.hpp"

namespace puncture::python {

struct SceneHandle {
  Scene scene;
  std::string source;

  /// The scene as its file holds it (scene_to_json_text: mm where the schema says so).
  nlohmann::json document() const { return nlohmann::json::parse(scene_to_json_text(scene)); }
};

}  // namespace puncture::python
