// Scene files: the default scene loads with the paper's Table 2 values, and
// every kind of bad input is rejected with the file and the JSON path named.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "puncture/scene_io.hpp"

namespace puncture {
namespace {

using nlohmann::json;

const std::string kDefaultScene = std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json";

json default_json() {
  std::ifstream in(kDefaultScene);
  return json::parse(in);
}

/// Parses `j` and returns the SceneError message; fails the test if it parses.
std::string error_of(const json& j) {
  try {
    parse_scene(j.dump(), "bad.json");
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "scene was accepted: " << j.dump();
  return {};
}

TEST(SceneIo, DefaultSceneHasTable2Values) {
  const Scene s = load_scene(kDefaultScene);
  ASSERT_EQ(s.layers.size(), 3u);
  EXPECT_EQ(s.layers[0].name, "skin");
  EXPECT_EQ(s.layers[1].name, "fat");
  EXPECT_EQ(s.layers[2].name, "muscle");
  // Table 2: thickness in cm, K in N/mm, L in mm.
  EXPECT_NEAR(s.layers[0].thickness_m, 0.08e-2, 1e-12);
  EXPECT_NEAR(s.layers[1].thickness_m, 0.84e-2, 1e-12);
  EXPECT_NEAR(s.layers[2].thickness_m, 3.9e-2, 1e-12);
  EXPECT_NEAR(s.layers[0].force_mesh.virtual_stiffness_N_per_m, 0.16e3, 1e-9);
  EXPECT_NEAR(s.layers[1].force_mesh.virtual_stiffness_N_per_m, 0.08e3, 1e-9);
  EXPECT_NEAR(s.layers[2].force_mesh.virtual_stiffness_N_per_m, 0.23e3, 1e-9);
  EXPECT_EQ(s.layers[0].force_mesh.rings_w, 8);
  EXPECT_EQ(s.layers[1].force_mesh.rings_w, 4);
  EXPECT_EQ(s.layers[2].force_mesh.rings_w, 10);
  EXPECT_NEAR(s.layers[0].force_mesh.spacing_L_m, 2e-3, 1e-15);
  EXPECT_NEAR(s.layers[1].force_mesh.spacing_L_m, 1e-3, 1e-15);
  EXPECT_NEAR(s.layers[2].force_mesh.spacing_L_m, 2.5e-3, 1e-15);
  EXPECT_NEAR(s.total_thickness_m(), 48.2e-3, 1e-12);
  EXPECT_NEAR(s.layer_top_depth_m(2), 9.2e-3, 1e-12);
  EXPECT_GT(s.insertion.target_depth_m, s.layer_top_depth_m(2));
  EXPECT_TRUE(s.effects.surface_force && s.effects.damping && s.effects.resumption);
}

TEST(SceneIo, RoundTripThroughJsonText) {
  const Scene a = load_scene(kDefaultScene);
  const Scene b = parse_scene(scene_to_json_text(a), "roundtrip");
  ASSERT_EQ(a.layers.size(), b.layers.size());
  for (std::size_t i = 0; i < a.layers.size(); ++i) {
    EXPECT_DOUBLE_EQ(a.layers[i].thickness_m, b.layers[i].thickness_m);
    EXPECT_DOUBLE_EQ(a.layers[i].force_mesh.virtual_stiffness_N_per_m, b.layers[i].force_mesh.virtual_stiffness_N_per_m);
    EXPECT_DOUBLE_EQ(a.layers[i].force_mesh.surface_stiffness_N_per_m, b.layers[i].force_mesh.surface_stiffness_N_per_m);
    EXPECT_DOUBLE_EQ(a.layers[i].damping_N_s_per_m2, b.layers[i].damping_N_s_per_m2);
    EXPECT_DOUBLE_EQ(a.layers[i].material.youngs_modulus_Pa, b.layers[i].material.youngs_modulus_Pa);
    EXPECT_EQ(a.layers[i].material.source, b.layers[i].material.source);
  }
  EXPECT_DOUBLE_EQ(a.insertion.speed_m_per_s, b.insertion.speed_m_per_s);
  EXPECT_EQ(a.realtime.integrator, b.realtime.integrator);
}

TEST(SceneIo, InclinationAndAzimuthRoundTripAndDefaultToTheNormal) {
  Scene a = load_scene(kDefaultScene);
  EXPECT_EQ(a.insertion.azimuth_deg, 0.0);  // the default scene names no azimuth
  a.insertion.angle_deg = 20.0;
  a.insertion.azimuth_deg = 247.5;
  const Scene b = parse_scene(scene_to_json_text(a), "roundtrip");
  EXPECT_EQ(b.insertion.angle_deg, 20.0);
  EXPECT_EQ(b.insertion.azimuth_deg, 247.5);
}

TEST(SceneIo, MalformedJsonNamesTheFile) {
  try {
    parse_scene("{ \"schema_version\": 1, ", "broken.json");
    FAIL() << "accepted malformed JSON";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.json"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("malformed JSON"), std::string::npos);
  }
}

TEST(SceneIo, NanOrInfiniteNumberIsRejected) {
  const std::string text = default_json().dump();
  const std::string field = "\"thickness_mm\":0.8";
  const auto pos = text.find(field);
  ASSERT_NE(pos, std::string::npos);
  for (const std::string bad : {"NaN", "nan", "1e999", "-1e999"}) {
    std::string t = text;
    t.replace(pos, field.size(), "\"thickness_mm\":" + bad);
    try {
      parse_scene(t, "nan.json");
      ADD_FAILURE() << "accepted thickness " << bad;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("nan.json"), std::string::npos) << e.what();
    }
  }
}

TEST(SceneIo, MissingFileIsAnError) {
  EXPECT_THROW(load_scene("/nonexistent/scene.json"), SceneError);
}

struct BadCase {
  const char* name;
  void (*mutate)(json&);
  const char* expected_path;
};

const BadCase kBadCases[] = {
    {"negative_thickness", [](json& j) { j["layers"][1]["thickness_mm"] = -2.0; }, "/layers/1/thickness_mm"},
    {"zero_rings", [](json& j) { j["layers"][0]["force_mesh"]["w"] = 0; }, "/layers/0/force_mesh/w"},
    {"fractional_rings", [](json& j) { j["layers"][0]["force_mesh"]["w"] = 2.5; }, "/layers/0/force_mesh/w"},
    {"zero_spacing", [](json& j) { j["layers"][2]["force_mesh"]["L_mm"] = 0.0; }, "/layers/2/force_mesh/L_mm"},
    {"negative_spacing", [](json& j) { j["layers"][2]["force_mesh"]["L_mm"] = -1.0; }, "/layers/2/force_mesh/L_mm"},
    {"unknown_key", [](json& j) { j["layers"][0]["thicknes_mm"] = 1.0; }, "/layers/0/thicknes_mm"},
    {"unknown_top_key", [](json& j) { j["colour"] = "red"; }, "/colour"},
    {"unknown_effect", [](json& j) { j["effects"].push_back("bleeding"); }, "/effects/6"},
    {"removed_models_field", [](json& j) { j["models"] = {"realtime"}; }, "/models"},
    {"missing_thickness", [](json& j) { j["layers"][0].erase("thickness_mm"); }, "/layers/0/thickness_mm"},
    {"missing_needle", [](json& j) { j.erase("needle"); }, "/needle"},
    {"string_for_number", [](json& j) { j["needle"]["radius_mm"] = "thin"; }, "/needle/radius_mm"},
    {"no_layers", [](json& j) { j["layers"] = json::array(); }, "/layers"},
    {"duplicate_layer_name", [](json& j) { j["layers"][1]["name"] = "skin"; }, "/layers/1/name"},
    {"depth_beyond_tissue", [](json& j) { j["insertion"]["target_depth_mm"] = 60.0; }, "/insertion/target_depth_mm"},
    {"angle_beyond_limit", [](json& j) { j["insertion"]["angle_deg"] = 61.0; }, "/insertion/angle_deg"},
    {"negative_angle", [](json& j) { j["insertion"]["angle_deg"] = -5.0; }, "/insertion/angle_deg"},
    {"azimuth_full_turn", [](json& j) { j["insertion"]["azimuth_deg"] = 360.0; }, "/insertion/azimuth_deg"},
    {"negative_azimuth", [](json& j) { j["insertion"]["azimuth_deg"] = -90.0; }, "/insertion/azimuth_deg"},
    {"azimuth_not_a_number", [](json& j) { j["insertion"]["azimuth_deg"] = "north"; }, "/insertion/azimuth_deg"},
    // 30 mm deep at 45 deg the needle lies 30.6 mm off the axis of a 60 mm sample.
    {"inclined_path_leaves_the_sample", [](json& j) { j["insertion"]["angle_deg"] = 45.0; }, "/insertion/angle_deg"},
    {"unknown_integrator", [](json& j) { j["realtime"]["integrator"] = "rk4"; }, "/realtime/integrator"},
    {"unknown_spring_kind", [](json& j) { j["comparison"]["mass_spring_springs"] = "hooke"; },
     "/comparison/mass_spring_springs"},
    {"poisson_half", [](json& j) { j["layers"][2]["material"]["poisson_ratio"] = 0.5; }, "/layers/2/material/poisson_ratio"},
    {"wrong_schema_version", [](json& j) { j["schema_version"] = 7; }, "/schema_version"},
    {"huge_force_mesh", [](json& j) { j["layers"][2]["force_mesh"]["w"] = 40; }, "/layers/2/force_mesh/L_mm"},
};

class SceneIoBadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(SceneIoBadInput, ErrorNamesFileAndJsonPath) {
  json j = default_json();
  GetParam().mutate(j);
  const std::string msg = error_of(j);
  EXPECT_NE(msg.find("bad.json: "), std::string::npos) << msg;
  EXPECT_NE(msg.find(std::string(GetParam().expected_path) + ":"), std::string::npos) << msg;
}

INSTANTIATE_TEST_SUITE_P(AllCases, SceneIoBadInput, ::testing::ValuesIn(kBadCases),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace puncture
