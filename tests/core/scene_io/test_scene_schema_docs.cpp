// The scene schema as the writer produces it against what documents it: every
// key a scene file can hold (written back by scene_to_json_text, every
// optional block switched on) is named in scenes/README.md's schema table and
// in the fuzz dictionary (tests/fuzz/scene.dict), and so is every effect name.
// A field added to the reader and writer but not to the docs fails here.
#include <gtest/gtest.h>

#include <fstream>
#include <cmath>
#include <regex>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "puncture/scene_io.hpp"
#include "puncture/scene_schema.hpp"

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
  l.force_law.cutting_rate.viscous_fraction = 0.2;  // written when used
  l.force_law.rupture_release_rate.exponent = 0.3;   // written when used
  s.comparison.mass_spring_stiffness_scale.assign(s.layers.size(), 1.0);
  s.comparison.mass_spring_springs = "nonlinear";  // written when not the default
  s.comparison.stiffness_scale.assign(s.layers.size(), 1.0);
  s.comparison.prescribed_puncture_depths_m = {1e-3};
  s.comparison.prony_g = {0.2};
  s.comparison.prony_tau_s = {1.0};
  return s;
}

/// The scene with every block written out, and again with each other
/// breakthrough criterion, stiffening law, FEM puncture criterion and tip
/// (which write other keys).
std::vector<json> written_variants() {
  std::vector<json> out;
  Scene s = scene_with_every_block();
  out.push_back(json::parse(scene_to_json_text(s)));
  ForceLaw& law = s.layers[0].force_law;
  law.breakthrough.kind = BreakthroughCriterion::Kind::CriticalEnergy;
  law.breakthrough.critical_energy_J = 1e-3;
  law.stiffening.kind = StiffeningLaw::Kind::Exponential;
  s.layers[0].puncture.kind = PunctureCriterion::Kind::CriticalForce;
  s.layers[1].puncture.kind = PunctureCriterion::Kind::CriticalStretch;
  s.needle.tip = "blunt";
  out.push_back(json::parse(scene_to_json_text(s)));
  law.breakthrough.kind = BreakthroughCriterion::Kind::Rings;
  out.push_back(json::parse(scene_to_json_text(s)));
  return out;
}

/// Every key of the written schema, with the criteria and laws that write other keys.
std::set<std::string> written_keys() {
  std::set<std::string> keys;
  for (const json& j : written_variants()) collect_keys(j, keys);
  return keys;
}

/// Leaf paths of j with array indices as "*" (an array of scalars is one leaf).
void collect_paths(const json& j, const std::string& path, std::set<std::string>& out) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) collect_paths(it.value(), path + "/" + it.key(), out);
  } else if (j.is_array() && !j.empty() && (j.front().is_object() || j.front().is_array())) {
    for (const json& e : j) collect_paths(e, path + "/*", out);
  } else {
    out.insert(path);
  }
}

/// The first concrete JSON pointer in j that matches the schema path
/// ("*": any array index), or "" when j holds none.
std::string first_match(const json& j, const std::string& path, std::size_t from = 1, const std::string& done = "") {
  if (from > path.size()) return done;
  const std::size_t end = std::min(path.find('/', from), path.size());
  const std::string token = path.substr(from, end - from);
  if (token == "*") {
    if (!j.is_array()) return {};
    for (std::size_t i = 0; i < j.size(); ++i) {
      const std::string m = first_match(j[i], path, end + 1, done + "/" + std::to_string(i));
      if (!m.empty()) return m;
    }
    return {};
  }
  if (!j.is_object() || !j.contains(token)) return {};
  return first_match(j.at(token), path, end + 1, done + "/" + token);
}

/// The first written variant that holds the field, and where (pointer).
const json* variant_with(const std::vector<json>& variants, const std::string& path, std::string& pointer) {
  for (const json& j : variants) {
    pointer = first_match(j, path);
    if (!pointer.empty()) return &j;
  }
  return nullptr;
}

/// The reader's error for text j, or "" when it accepts it.
std::string reader_error(const json& j) {
  try {
    parse_scene(j.dump(), "schema_check.json");
  } catch (const SceneError& e) {
    return e.what();
  }
  return {};
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

TEST(SceneSchema, TheWriterWritesExactlyTheSchemasWrittenFields) {
  std::set<std::string> written;
  for (const json& j : written_variants()) collect_paths(j, "", written);
  std::set<std::string> declared;
  for (const SceneField& f : scene_schema()) {
    EXPECT_TRUE(declared.insert(f.path).second) << "the schema declares " << f.path << " twice";
    if (f.written) EXPECT_TRUE(written.count(f.path)) << "the schema's field " << f.path << " is never written";
    else EXPECT_FALSE(written.count(f.path)) << f.path << " is written but declared read-only";
  }
  for (const std::string& p : written)
    EXPECT_TRUE(declared.count(p)) << "the writer writes " << p << ", which the schema (scene_schema.cpp) does not declare";
}

TEST(SceneSchema, TheReaderRejectsAValueBeyondEachRangeNamingItsPath) {
  // Each bound of the table, crossed by the smallest step that leaves it
  // (the bound itself when it is open), in the first written variant that
  // holds the field: the reader refuses and names the field's JSON path.
  const std::vector<json> variants = written_variants();
  int checked = 0;
  for (const SceneField& f : scene_schema()) {
    if (!f.range.bounded() || !f.written) continue;
    const bool list = f.type == SceneFieldType::NumberList;
    std::string field;
    const json* base = variant_with(variants, f.path, field);
    ASSERT_NE(base, nullptr) << "no written variant holds " << f.path;
    const std::string pointer = field + (list ? "/0" : "");
    const bool integer = f.type == SceneFieldType::Integer;
    std::vector<double> beyond;
    if (std::isfinite(f.range.lower))
      beyond.push_back(f.range.lower_open ? f.range.lower
                                          : f.range.lower - (integer ? 1.0 : 0.5 * std::abs(f.range.lower) + 0.5));
    if (std::isfinite(f.range.upper))
      beyond.push_back(f.range.upper_open ? f.range.upper
                                          : f.range.upper + (integer ? 1.0 : 0.5 * std::abs(f.range.upper) + 0.5));
    for (double v : beyond) {
      json j = *base;
      if (integer) j[json::json_pointer(pointer)] = static_cast<long long>(v);
      else j[json::json_pointer(pointer)] = v;
      const std::string error = reader_error(j);
      EXPECT_NE(error.find(field), std::string::npos)
          << f.path << " = " << v << " outside the schema's range: " << (error.empty() ? "accepted" : error);
      ++checked;
    }
  }
  EXPECT_GT(checked, 80);
}

TEST(SceneSchema, TheReaderAcceptsEachBoundOfAClosedRangeAndJustInsideAnOpenOne) {
  // The other side of the test above: a range declared wider than the
  // reader's fails here (a value inside it is refused naming the field).
  const std::vector<json> variants = written_variants();
  for (const SceneField& f : scene_schema()) {
    if (!f.range.bounded() || !f.written) continue;
    const bool list = f.type == SceneFieldType::NumberList, integer = f.type == SceneFieldType::Integer;
    std::string field;
    const json* base = variant_with(variants, f.path, field);
    ASSERT_NE(base, nullptr) << "no written variant holds " << f.path;
    const std::string pointer = field + (list ? "/0" : "");
    // The insertion's speeds are also bounded below by the scripted
    // insertion's duration limit (scene_limits.hpp: travel / speed), a bound
    // that depends on other fields: just inside theirs is 1 mm/s.
    const bool speed = f.path.rfind("/insertion/", 0) == 0 && f.key().find("speed_mm_per_s") != std::string::npos;
    auto inside = [&](double bound, bool open, double direction) {
      if (speed && direction > 0.0) return bound + 1.0;
      if (!open) return bound;
      return bound + direction * (integer ? 1.0 : 1e-6 * std::max(1.0, std::abs(bound)));
    };
    std::vector<double> values;
    if (std::isfinite(f.range.lower)) values.push_back(inside(f.range.lower, f.range.lower_open, +1.0));
    if (std::isfinite(f.range.upper)) values.push_back(inside(f.range.upper, f.range.upper_open, -1.0));
    // The insertion angle's upper bound also depends on the sample's width
    // (the inclined path must stay inside it): the bound is checked on a wide sample.
    const bool angle = f.path == "/insertion/angle_deg";
    for (double v : values) {
      json j = *base;
      if (integer) j[json::json_pointer(pointer)] = static_cast<long long>(v);
      else j[json::json_pointer(pointer)] = v;
      if (angle) j["sample"]["diameter_mm"] = 500.0;
      const std::string error = reader_error(j);
      EXPECT_EQ(error.find(field), std::string::npos) << f.path << " = " << v << " inside the schema's range: " << error;
    }
  }
}

TEST(SceneSchema, TheReaderNamesEveryMissingRequiredField) {
  const std::vector<json> variants = written_variants();
  int checked = 0;
  for (const SceneField& f : scene_schema()) {
    if (!f.required || !f.written) continue;
    std::string pointer;
    const json* base = variant_with(variants, f.path, pointer);
    ASSERT_NE(base, nullptr) << "no written variant holds " << f.path;
    json j = *base;
    const json::json_pointer ptr(pointer);
    j[ptr.parent_pointer()].erase(f.key());
    const std::string error = reader_error(j);
    EXPECT_NE(error.find(pointer), std::string::npos) << f.path << " removed: " << (error.empty() ? "accepted" : error);
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

TEST(SceneSchema, EveryKeyIsInTheSchemaTableAndTheFuzzDictionary) {
  const std::string docs = schema_section();
  const std::string dict = read_text(std::string(PUNCTURE_SOURCE_DIR) + "/tests/fuzz/scene.dict");
  for (const SceneField& f : scene_schema()) {
    EXPECT_TRUE(names(docs, f.key())) << "scenes/README.md's schema table does not name '" << f.key() << "' (" << f.path << ")";
    EXPECT_NE(dict.find("\"\\\"" + f.key() + "\\\"\""), std::string::npos)
        << "tests/fuzz/scene.dict has no entry for '" << f.key() << "'";
  }
}

TEST(SceneSchemaDocs, TheCheckFindsAKeyTheDocsDoNotName) {
  // The test above can fail: a made-up key is not named.
  EXPECT_FALSE(names(schema_section(), "haptic_latency_ms"));
  EXPECT_TRUE(names(schema_section(), "K_N_per_mm"));
}

}  // namespace
}  // namespace puncture
