// The scene schema as the writer produces it against what documents it: every
// key a scene file can hold (written back by scene_to_json_text, every
// optional block switched on) is named in scenes/README.md's schema table and
// in the fuzz dictionary (tests/fuzz/scene.dict), and so is every effect name.
// A field added to the reader and writer but not to the docs fails here.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "puncture/scene_io.hpp"

namespace puncture {
namespace {

using nlohmann::json;

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void collect_keys(const json& j, std::set<std::string>& keys) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      keys.insert(it.key());
      collect_keys(it.value(), keys);
    }
  } else if (j.is_array()) {
    for (const json& e : j) collect_keys(e, keys);
  }
}

/// A scene with every optional block of the schema in use.
Scene scene_with_every_block() {
  Scene s = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default_force_law.json");
  Layer& l = s.layers[0];
  l.force_mesh.surface_axial_stiffness_N_per_m = 100.0;
  l.force_mesh.virtual_stiffening_m = 2e-3;
  l.material.model = "ogden";
  l.material.ogden_terms = {{0.5, 10.0}, {0.5, 2.0}};
  l.material.viscoelastic.terms = {{0.3, 1.0}};
  l.force_law.breakthrough.rate_exponent = 0.1;
  s.comparison.mass_spring_stiffness_scale.assign(s.layers.size(), 1.0);
  s.comparison.stiffness_scale.assign(s.layers.size(), 1.0);
  s.comparison.prescribed_puncture_depths_m = {1e-3};
  s.comparison.prony_g = {0.2};
  s.comparison.prony_tau_s = {1.0};
  return s;
}

/// Every key of the written schema, with the criteria and laws that write other keys.
std::set<std::string> written_keys() {
  std::set<std::string> keys;
  Scene s = scene_with_every_block();
  collect_keys(json::parse(scene_to_json_text(s)), keys);
  // The other breakthrough criteria, stiffening law and FEM puncture criteria.
  ForceLaw& law = s.layers[0].force_law;
  law.breakthrough.kind = BreakthroughCriterion::Kind::CriticalEnergy;
  law.breakthrough.critical_energy_J = 1e-3;
  law.stiffening.kind = StiffeningLaw::Kind::Exponential;
  s.layers[0].puncture.kind = PunctureCriterion::Kind::CriticalForce;
  s.layers[1].puncture.kind = PunctureCriterion::Kind::CriticalStretch;
  s.needle.tip = "blunt";
  collect_keys(json::parse(scene_to_json_text(s)), keys);
  law.breakthrough.kind = BreakthroughCriterion::Kind::Rings;
  collect_keys(json::parse(scene_to_json_text(s)), keys);
  return keys;
}

/// The "Schema" section of scenes/README.md (up to the next heading).
std::string schema_section() {
  const std::string text = read_text(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/README.md");
  const auto start = text.find("## Schema");
  EXPECT_NE(start, std::string::npos) << "scenes/README.md has no Schema section";
  const auto end = text.find("\n## ", start + 1);
  return text.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

/// True if `word` stands in `text` as a whole identifier (not inside a longer one).
bool names(const std::string& text, const std::string& word) {
  const std::regex re("(^|[^A-Za-z0-9_])" + word + "([^A-Za-z0-9_]|$)");
  return std::regex_search(text, re);
}

TEST(SceneSchemaDocs, EveryWrittenKeyIsInTheSchemaTableAndTheFuzzDictionary) {
  const std::set<std::string> keys = written_keys();
  ASSERT_GT(keys.size(), 80u) << "the scene with every block writes fewer keys than expected";
  const std::string docs = schema_section();
  const std::string dict = read_text(std::string(PUNCTURE_SOURCE_DIR) + "/tests/fuzz/scene.dict");
  for (const std::string& key : keys) {
    EXPECT_TRUE(names(docs, key)) << "scenes/README.md's schema table does not name the key '" << key << "'";
    EXPECT_NE(dict.find("\"\\\"" + key + "\\\"\""), std::string::npos)
        << "tests/fuzz/scene.dict has no entry for the key '" << key << "'";
  }
}

TEST(SceneSchemaDocs, EveryEffectIsInTheSchemaTableAndTheFuzzDictionary) {
  const std::string docs = schema_section();
  const std::string dict = read_text(std::string(PUNCTURE_SOURCE_DIR) + "/tests/fuzz/scene.dict");
  for (const std::string& effect : known_effects()) {
    EXPECT_NE(docs.find("`" + effect + "`"), std::string::npos) << "effect '" << effect << "' not in the schema table";
    EXPECT_NE(dict.find("\"\\\"" + effect + "\\\"\""), std::string::npos)
        << "effect '" << effect << "' not in tests/fuzz/scene.dict";
  }
}

TEST(SceneSchemaDocs, TheCheckFindsAKeyTheDocsDoNotName) {
  // The test above can fail: a made-up key is not named.
  EXPECT_FALSE(names(schema_section(), "haptic_latency_ms"));
  EXPECT_TRUE(names(schema_section(), "K_N_per_mm"));
}

}  // namespace
}  // namespace puncture
