// The FEM physics keys of a layer (material law, fracture-energy puncture,
// shaft friction) and of the needle and the fem object: bad values are scene
// errors that name the file and the JSON path.
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

std::string error_of(const json& j) {
  try {
    parse_scene(j.dump(), "bad.json");
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "scene was accepted";
  return {};
}

void expect_error(json j, const std::string& path) {
  const std::string e = error_of(j);
  EXPECT_NE(e.find("bad.json"), std::string::npos) << e;
  EXPECT_NE(e.find(path), std::string::npos) << "expected " << path << " in: " << e;
}

}  // namespace

TEST(SceneIoFemPhysics, DefaultSceneHasStiffeningLayersFractureEnergyAndFriction) {
  const Scene s = parse_scene(default_json().dump(), "default.json");
  ASSERT_EQ(s.layers.size(), 3u);
  for (const Layer& l : s.layers) {
    EXPECT_EQ(l.material.model, "ogden") << l.name;
    ASSERT_EQ(l.material.ogden_terms.size(), 1u) << l.name;
    EXPECT_GT(l.material.ogden_terms[0].alpha, 2.0) << l.name << ": stiffens faster than neo-Hookean";
    EXPECT_EQ(l.puncture.kind, PunctureCriterion::Kind::FractureEnergy) << l.name;
    EXPECT_GT(l.puncture.toughness_J_per_m2, 0.0) << l.name;
    EXPECT_FALSE(l.puncture.source.empty()) << l.name;
    EXPECT_FALSE(l.material.source.empty()) << l.name;
    EXPECT_GT(l.shaft_friction.dynamic_coefficient, 0.0) << l.name;
    EXPECT_GE(l.shaft_friction.static_coefficient, l.shaft_friction.dynamic_coefficient) << l.name;
  }
  EXPECT_EQ(s.needle.tip, "bevel");
}

TEST(SceneIoFemPhysics, OutOfRangeMaterialPunctureAndFrictionNameTheJsonPath) {
  {
    json j = default_json();
    j["layers"][0]["material"]["ogden_alpha"] = 0.0;
    expect_error(j, "/layers/0/material/ogden_alpha");
  }
  {
    json j = default_json();
    j["layers"][1]["puncture"]["toughness_J_per_m2"] = -5.0;
    expect_error(j, "/layers/1/puncture/toughness_J_per_m2");
  }
  {
    json j = default_json();
    j["layers"][2]["puncture"]["cohesive_strength_kPa"] = 0.0;
    expect_error(j, "/layers/2/puncture/cohesive_strength_kPa");
  }
  {
    json j = default_json();
    j["layers"][0]["shaft_friction"]["coefficient"] = -0.1;
    j["layers"][0]["shaft_friction"]["static_coefficient"] = 0.0;
    expect_error(j, "/layers/0/shaft_friction/coefficient");
  }
  {
    json j = default_json();
    j["layers"][1]["shaft_friction"]["static_coefficient"] = 0.05;  // below the dynamic 0.1
    expect_error(j, "/layers/1/shaft_friction/static_coefficient");
  }
  {
    json j = default_json();
    j["layers"][0]["material"]["poisson_ratio"] = 0.5;
    expect_error(j, "/layers/0/material/poisson_ratio");
  }
  {
    json j = default_json();
    j["fem"]["stabilization_time_s"] = -1e-3;
    expect_error(j, "/fem/stabilization_time_s");
  }
  {
    json j = default_json();
    j["layers"][0]["material"]["ogden_alpha"] = std::nan("");
    EXPECT_FALSE(error_of(j).empty());
  }
}

}  // namespace puncture

namespace puncture {
namespace {

json with_prony(json j, int layer, json prony, const std::string& modulus = "instantaneous") {
  j["layers"][layer]["material"]["viscoelastic"] = {{"prony", prony}, {"modulus", modulus}, {"source", "test"}};
  return j;
}

}  // namespace

TEST(SceneIoFemPhysics, ViscoelasticTermsAreReadAndWrittenBack) {
  json j = with_prony(default_json(), 2, json::array({{{"g", 0.3}, {"tau_s", 0.5}}, {{"g", 0.2}, {"tau_s", 10.0}}}),
                      "long_term");
  const Scene s = parse_scene(j.dump(), "visco.json");
  const Viscoelasticity& v = s.layers[2].material.viscoelastic;
  ASSERT_EQ(v.terms.size(), 2u);
  EXPECT_DOUBLE_EQ(v.terms[1].g, 0.2);
  EXPECT_DOUBLE_EQ(v.terms[1].tau_s, 10.0);
  EXPECT_EQ(v.modulus_basis, Viscoelasticity::ModulusBasis::LongTerm);
  EXPECT_NEAR(v.relaxed_fraction(), 0.5, 1e-15);
  const Scene back = parse_scene(scene_to_json_text(s), "roundtrip");
  const Viscoelasticity& w = back.layers[2].material.viscoelastic;
  ASSERT_EQ(w.terms.size(), 2u);
  EXPECT_DOUBLE_EQ(w.terms[0].g, 0.3);
  EXPECT_DOUBLE_EQ(w.terms[0].tau_s, 0.5);
  EXPECT_EQ(w.modulus_basis, Viscoelasticity::ModulusBasis::LongTerm);
  EXPECT_EQ(w.source, "test");
}

TEST(SceneIoFemPhysics, BadPronyTermsNameTheJsonPath) {
  const json good = {{"g", 0.3}, {"tau_s", 0.5}};
  expect_error(with_prony(default_json(), 1, json::array({good, {{"g", 1.2}, {"tau_s", 1.0}}})),
               "/layers/1/material/viscoelastic/prony/1/g");
  expect_error(with_prony(default_json(), 1, json::array({good, {{"g", 0.1}, {"tau_s", -1.0}}})),
               "/layers/1/material/viscoelastic/prony/1/tau_s");
  expect_error(with_prony(default_json(), 0, json::array({good, {{"g", 0.1}}})),
               "/layers/0/material/viscoelastic/prony/1/tau_s");
  expect_error(with_prony(default_json(), 0, json::array({good, {{"g", 0.1}, {"tau_s", 1.0}, {"beta", 2}}})),
               "/layers/0/material/viscoelastic/prony/1/beta");
  expect_error(with_prony(default_json(), 2, json::array({{{"g", 0.6}, {"tau_s", 1.0}}, {{"g", 0.5}, {"tau_s", 9.0}}})),
               "/layers/2/material/viscoelastic/prony");
  expect_error(with_prony(default_json(), 2, json::array()), "/layers/2/material/viscoelastic/prony");
  expect_error(with_prony(default_json(), 2, json::array({good}), "relaxed"),
               "/layers/2/material/viscoelastic/modulus");
  json j = default_json();
  j["layers"][0]["material"]["viscoelastic"] = {{"prony", json::array({good})}};
  expect_error(j, "/layers/0/material/viscoelastic/modulus");
}

}  // namespace puncture
