// Scenes for the real-time app tests: the default scene, or the default slab
// with a short insertion so a whole cycle is a few hundred ticks. Built from
// scene text (as the app loads them), so a recording's scene text reproduces
// the very same Scene.
#pragma once

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "puncture/scene_io.hpp"

namespace puncture::realtime::testing {

inline std::string default_scene_path() { return std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json"; }

inline Scene default_scene() { return load_scene(default_scene_path()); }

/// Default slab, needle to 12 mm (through skin and fat into muscle) at 40 mm/s,
/// no dwell: about 0.65 s (650 ticks) per insertion cycle.
inline std::string short_insertion_scene_text() {
  std::ifstream in(default_scene_path());
  nlohmann::json j = nlohmann::json::parse(in);
  j["name"] = "short_insertion";
  j["insertion"]["speed_mm_per_s"] = 40.0;
  j["insertion"]["withdrawal_speed_mm_per_s"] = 40.0;
  j["insertion"]["target_depth_mm"] = 12.0;
  j["insertion"]["dwell_s"] = 0.0;
  return j.dump(2);
}

inline Scene short_insertion_scene() { return parse_scene(short_insertion_scene_text(), "short_insertion.json"); }

}  // namespace puncture::realtime::testing
