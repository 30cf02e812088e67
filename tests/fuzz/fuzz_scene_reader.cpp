// libFuzzer target: any bytes through the scene reader.
//
// Properties checked for every input:
//   * parse_scene either returns a Scene or throws SceneError; any other
//     exception, a crash, a sanitizer report or a hang is a finding;
//   * a scene that loads serialises (scene_to_json_text) to a text that loads
//     again (a tuned preset written by calibrate must be runnable), and that
//     second scene serialises to the same text (stable after one round).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "puncture/scene_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  puncture::Scene scene;
  try {
    scene = puncture::parse_scene(text, "fuzz.json");
  } catch (const puncture::SceneError&) {
    return 0;  // rejected with a message naming file and path: fine
  }
  const std::string once = puncture::scene_to_json_text(scene);
  try {
    const puncture::Scene again = puncture::parse_scene(once, "roundtrip.json");
    const std::string twice = puncture::scene_to_json_text(again);
    const puncture::Scene third = puncture::parse_scene(twice, "roundtrip2.json");
    if (puncture::scene_to_json_text(third) != twice) {
      std::fprintf(stderr, "scene text not stable after a round trip:\n%s\n", twice.c_str());
      std::abort();
    }
  } catch (const puncture::SceneError& e) {
    std::fprintf(stderr, "a loaded scene does not load after serialisation: %s\n%s\n", e.what(), once.c_str());
    std::abort();
  }
  return 0;
}
