// The optional "haptics" object of a scene (limits of the real-time app's
// stability guard): defaults when absent, values in the file's units when
// present, round trip through scene_to_json_text, bad values rejected with
// the JSON path.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "puncture/scene_io.hpp"

namespace puncture {
namespace {

using nlohmann::json;

json default_json() {
  std::ifstream in(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  return json::parse(in);
}

TEST(SceneHaptics, DefaultsWhenAbsent) {
  json j = default_json();
  j.erase("haptics");
  const Scene s = parse_scene(j.dump(), "no_haptics.json");
  // Geomagic Touch data sheet: 3.3 N peak force, 1.02 N/mm (weakest axis).
  EXPECT_DOUBLE_EQ(s.haptics.max_force_N, 3.3);
  EXPECT_DOUBLE_EQ(s.haptics.device_max_stiffness_N_per_m, 1020.0);
  // b = K T / 2 at 1 kHz for that stiffness.
  EXPECT_NEAR(s.haptics.device_damping_N_s_per_m, 1020.0 * 1e-3 / 2.0, 1e-12);
  EXPECT_GT(s.haptics.max_force_rate_N_per_s, 0.0);
}

TEST(SceneHaptics, ReadsValuesAndRoundTrips) {
  json j = default_json();
  j["haptics"] = {{"max_force_N", 2.0},
                  {"max_force_rate_N_per_s", 250.0},
                  {"device_damping_N_s_per_m", 1.5},
                  {"device_max_stiffness_N_per_mm", 2.5}};
  const Scene a = parse_scene(j.dump(), "haptics.json");
  EXPECT_DOUBLE_EQ(a.haptics.max_force_N, 2.0);
  EXPECT_DOUBLE_EQ(a.haptics.max_force_rate_N_per_s, 250.0);
  EXPECT_DOUBLE_EQ(a.haptics.device_damping_N_s_per_m, 1.5);
  EXPECT_DOUBLE_EQ(a.haptics.device_max_stiffness_N_per_m, 2500.0);  // N/mm in the file, N/m inside
  const Scene b = parse_scene(scene_to_json_text(a), "roundtrip");
  EXPECT_DOUBLE_EQ(b.haptics.max_force_N, a.haptics.max_force_N);
  EXPECT_DOUBLE_EQ(b.haptics.max_force_rate_N_per_s, a.haptics.max_force_rate_N_per_s);
  EXPECT_DOUBLE_EQ(b.haptics.device_damping_N_s_per_m, a.haptics.device_damping_N_s_per_m);
  EXPECT_DOUBLE_EQ(b.haptics.device_max_stiffness_N_per_m, a.haptics.device_max_stiffness_N_per_m);
}

TEST(SceneHaptics, BadValuesNameTheJsonPath) {
  const std::pair<const char*, json> cases[] = {
      {"/haptics/max_force_N", {{"max_force_N", 0.0}}},
      {"/haptics/max_force_rate_N_per_s", {{"max_force_rate_N_per_s", -1.0}}},
      {"/haptics/device_damping_N_s_per_m", {{"device_damping_N_s_per_m", -0.1}}},
      {"/haptics/device_max_stiffness_N_per_mm", {{"device_max_stiffness_N_per_mm", 0.0}}},
      {"/haptics/max_force", {{"max_force", 1.0}}},  // unknown key (typo)
      {"/haptics/max_force_N", {{"max_force_N", "strong"}}},
  };
  for (const auto& [path, haptics] : cases) {
    json j = default_json();
    j["haptics"] = haptics;
    try {
      parse_scene(j.dump(), "bad_haptics.json");
      ADD_FAILURE() << "accepted " << haptics.dump();
    } catch (const SceneError& e) {
      EXPECT_EQ(e.json_path(), path) << e.what();
      EXPECT_EQ(e.file(), "bad_haptics.json");
    }
  }
}

}  // namespace
}  // namespace puncture
