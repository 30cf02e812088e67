// Scene files that would hurt the machine or mislead: limits with the JSON
// path, duplicate keys, a byte-order mark, numbers out of range, a directory
// or a missing file given as the scene.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "puncture/scene_io.hpp"
#include "puncture/scene_limits.hpp"

namespace puncture {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

const std::string kDefaultScene = std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json";

std::string default_text() {
  std::ifstream in(kDefaultScene);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

json default_json() { return json::parse(default_text()); }

/// The SceneError message of parsing `text`; fails the test if it parses.
std::string error_of_text(const std::string& text) {
  try {
    parse_scene(text, "bad.json");
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "scene was accepted";
  return {};
}
std::string error_of(const json& j) { return error_of_text(j.dump()); }

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(SceneLimits, RatesDurationsSizesAndOutputVolumeNameTheJsonPath) {
  struct Case {
    const char* pointer;
    json value;
    const char* message_part;
  };
  const Case cases[] = {
      {"/realtime/haptic_rate_Hz", 1e6, "bad.json: /realtime/haptic_rate_Hz: must be <= 100000 Hz"},
      {"/realtime/haptic_rate_Hz", 1e9, "bad.json: /realtime/haptic_rate_Hz: must be <= 100000 Hz"},
      {"/insertion/dwell_s", 1e12, "bad.json: /insertion/dwell_s: must be <= 3600 s"},
      {"/insertion/start_height_mm", 1e9, "bad.json: /insertion/start_height_mm: must be <= 1000 mm"},
      {"/insertion/speed_mm_per_s", 0.0, "bad.json: /insertion/speed_mm_per_s: must be > 0"},
      {"/insertion/speed_mm_per_s", 1e-4, "bad.json: /insertion/speed_mm_per_s: the scripted insertion"},
      {"/insertion/withdrawal_speed_mm_per_s", 1e-4,
       "bad.json: /insertion/withdrawal_speed_mm_per_s: the scripted insertion"},
      {"/sample/diameter_mm", 5000.0, "bad.json: /sample/diameter_mm: must be <= 1000 mm"},
      {"/description", std::string(5000, 'x'), "bad.json: /description: too long (5000 characters"},
      {"/name", "../../etc", "bad.json: /name: must be a plain folder name"},
      {"/name", ".hidden", "bad.json: /name: must be a plain folder name"},
  };
  for (const Case& c : cases) {
    json j = default_json();
    j[json::json_pointer(c.pointer)] = c.value;
    const std::string message = error_of(j);
    EXPECT_NE(message.find(c.message_part), std::string::npos) << c.pointer << ": " << message;
  }
}

TEST(SceneLimits, TicksTimesLayersAndFrameFilesAreBounded) {
  // 100 kHz is allowed, but not for a 1 h insertion: too many ticks.
  json j = default_json();
  j["realtime"]["haptic_rate_Hz"] = 1e5;
  j["insertion"]["dwell_s"] = 3000;
  std::string message = error_of(j);
  EXPECT_NE(message.find("/realtime/haptic_rate_Hz: the scripted insertion"), std::string::npos) << message;
  EXPECT_NE(message.find("ticks x (layers + 2)"), std::string::npos) << message;

  j = default_json();
  j["realtime"]["frame_rate_Hz"] = 1000;  // ~7000 frames x 3 layers x 2 files
  message = error_of(j);
  EXPECT_NE(message.find("/realtime/frame_rate_Hz: the surface output would write"), std::string::npos) << message;
  // Without surface output the same frame rate writes nothing: accepted.
  j["effects"] = {"surface_force", "damping", "resumption"};
  EXPECT_NO_THROW(parse_scene(j.dump(), "ok.json"));

  j = default_json();
  for (int i = 0; i < 17; ++i) {
    json layer = j["layers"][2];
    layer["name"] = "extra" + std::to_string(i);
    layer["thickness_mm"] = 1.0;
    j["layers"].push_back(layer);
  }
  message = error_of(j);
  EXPECT_NE(message.find("bad.json: /layers: at most 16 layers"), std::string::npos) << message;

  // The default scene is far inside every limit.
  const Scene s = load_scene(kDefaultScene);
  EXPECT_LT(scene_limits::scripted_ticks(s) * 5, scene_limits::kMaxTickLayerProduct / 100);
  EXPECT_NEAR(scene_limits::scripted_duration_s(s.insertion), 0.032 / 0.01 + 5.0 + 0.032 / 0.01, 1e-12);
}

TEST(SceneJson, DuplicateKeysAreRejectedWithThePathOfTheSecond) {
  std::string message = error_of_text(replaced(default_text(), "\"speed_mm_per_s\": 10.0",
                                               "\"speed_mm_per_s\": 10.0, \"speed_mm_per_s\": 5"));
  EXPECT_NE(message.find("bad.json: /insertion/speed_mm_per_s: duplicate key 'speed_mm_per_s'"), std::string::npos)
      << message;
  message = error_of_text(replaced(default_text(), "\"name\": \"skin\",", "\"name\": \"skin\", \"name\": \"fat\","));
  EXPECT_NE(message.find("bad.json: /layers/0/name: duplicate key"), std::string::npos) << message;
}

TEST(SceneJson, NumbersOutOfRangeAndSyntaxErrorsNameThePath) {
  std::string message =
      error_of_text(replaced(default_text(), "\"speed_mm_per_s\": 10.0", "\"speed_mm_per_s\": 1e309"));
  EXPECT_NE(message.find("bad.json: /insertion/speed_mm_per_s: number out of range: '1e309'"), std::string::npos)
      << message;
  message = error_of_text(replaced(default_text(), "\"w\": 4,", "\"w\": 4294967300,"));
  EXPECT_NE(message.find("bad.json: /layers/1/force_mesh/w: integer out of range"), std::string::npos) << message;
  message = error_of_text(replaced(default_text(), "\"dwell_s\": 5.0,", "\"dwell_s\": 5.0x,"));
  EXPECT_NE(message.find("bad.json: /insertion/dwell_s: malformed JSON"), std::string::npos) << message;
  message = error_of_text(std::string(100, '[') + std::string(100, ']'));
  EXPECT_NE(message.find("nested deeper than"), std::string::npos) << message;
}

TEST(SceneJson, Utf8ByteOrderMarkIsAcceptedOnlyAtTheStart) {
  const std::string bom = "\xEF\xBB\xBF";
  const Scene with_bom = parse_scene(bom + default_text(), "bom.json");
  EXPECT_EQ(with_bom.name, "default");
  const std::string message = error_of_text(" " + bom + default_text());
  EXPECT_NE(message.find("malformed JSON"), std::string::npos) << message;
}

TEST(SceneFile, DirectoryMissingFileAndHugeFileGiveTheRealCause) {
  try {
    load_scene(PUNCTURE_SOURCE_DIR);
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), std::string(PUNCTURE_SOURCE_DIR) + ": is a directory, not a scene file");
  }
  try {
    load_scene("/nonexistent/scene.json");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/scene.json: cannot open scene file: No such file or directory");
  }
  const fs::path big = fs::temp_directory_path() / ("puncture_big_scene_" + std::to_string(::getpid()) + ".json");
  {
    std::ofstream out(big);
    out << std::string(scene_limits::kMaxSceneFileBytes + 1, ' ');
  }
  try {
    load_scene(big);
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("a scene file is at most"), std::string::npos) << e.what();
  }
  fs::remove(big);
}

}  // namespace
}  // namespace puncture
