// The FEM cache key cannot go stale:
//  - every leaf of the default scene's canonical JSON is changed in turn: the
//    key changes exactly when the leaf is not declared real-time-only;
//  - the FEM is run with every real-time-only field changed at once and gives
//    the same result files, sample for sample, as the unchanged scene (while a
//    change of one FEM field, the dwell, does change them): so a field that
//    leaves the key does not change the FEM's result;
//  - a cache entry whose stored key text is not the current one (an older key
//    format, a colliding hash) is recomputed, never reused.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "puncture/scene_io.hpp"
#include "puncture/scene_schema.hpp"
#include "puncture/validation/fem_reference.hpp"
#include "puncture/validation/fem_reference_key.hpp"

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace puncture::validation {
namespace {

Scene default_scene() { return load_scene(fs::path(PUNCTURE_SOURCE_DIR) / "scenes" / "default.json"); }

/// Every leaf of `node` as (JSON pointer, value); an array of numbers or
/// strings is one leaf (its elements are changed together).
void leaves(const json& node, const std::string& at, std::vector<std::string>& out) {
  const bool primitive_array =
      node.is_array() && std::all_of(node.begin(), node.end(), [](const json& e) { return e.is_primitive(); });
  if (node.is_object()) {
    for (auto it = node.begin(); it != node.end(); ++it) leaves(it.value(), at + "/" + it.key(), out);
  } else if (node.is_array() && !primitive_array) {
    for (std::size_t i = 0; i < node.size(); ++i) leaves(node[i], at + "/" + std::to_string(i), out);
  } else {
    out.push_back(at);
  }
}

/// Changed values to try for a leaf, most natural first.
std::vector<json> perturbations(const std::string& pointer, const json& v) {
  const std::string key = pointer.substr(pointer.rfind('/') + 1);
  std::vector<json> out;
  if (v.is_number_integer()) {
    out = {v.get<long>() + 1, v.get<long>() - 1};
  } else if (v.is_number()) {
    const double x = v.get<double>();
    if (x != 0.0) out = {x * 1.1, x * 0.9};
    out.push_back(x + 0.1);
  } else if (v.is_string()) {
    static const std::map<std::string, std::vector<std::string>> choices{
        {"tip", {"hollow", "blunt", "bevel"}},
        {"model", {"neo_hookean", "mooney_rivlin", "veronda_westmann", "ogden"}},
        {"geometry", {"3d", "auto", "axisymmetric"}},
        {"integrator", {"explicit", "quasi_static", "implicit", "sundials"}},
        {"modulus", {"long_term", "instantaneous"}},
        {"kind", {"extruded", "delaunay"}}};
    const auto c = choices.find(key);
    if (c != choices.end()) {
      for (const std::string& s : c->second)
        if (s != v.get<std::string>()) out.push_back(s);
    } else {
      out.push_back(v.get<std::string>() + " (changed)");
      out.push_back(v.get<std::string>() + "_changed");
    }
  } else if (v.is_array() && !v.empty()) {
    json scaled = v, dropped = v;
    bool numeric = true;
    for (json& e : scaled)
      if (e.is_number()) e = e.get<double>() * 1.1;
      else numeric = false;
    if (numeric) out.push_back(scaled);
    dropped.erase(dropped.size() - 1);
    out.push_back(dropped);
  }
  return out;
}

/// Leaves that no single change can alter while the scene stays valid: the
/// schema version, the insertion angle (the FEM takes 0 only; the commands
/// refuse an inclined scene before a key is made), and the
/// material model, criterion and law names and the one Ogden term's share,
/// whose change needs other fields too (their key changes are checked in
/// tests/apps/test_validate_command.cpp).
bool structural(const std::string& pointer) {
  static const std::vector<std::string> suffixes{"/puncture/criterion", "/breakthrough/criterion", "/stiffening/law",
                                                 "/material/model", "/ogden_terms/0/mu_fraction"};
  if (pointer == "/schema_version" || pointer == "/insertion/angle_deg") return true;
  for (const std::string& s : suffixes)
    if (pointer.size() >= s.size() && pointer.compare(pointer.size() - s.size(), s.size(), s) == 0) return true;
  return false;
}

TEST(FemReferenceKey, ChangesWithEveryLeafOfTheDefaultSceneExceptTheRealtimeOnlyOnes) {
  const Scene base = default_scene();
  const FemKeyOptions options;
  const std::string base_key = fem_reference_key_text(base, options, "digest");
  const json canonical = json::parse(scene_to_json_text(base));
  std::vector<std::string> all;
  leaves(canonical, "", all);
  ASSERT_GT(all.size(), 100u) << "the default scene has fewer leaves than expected";
  std::size_t fem_leaves = 0, realtime_leaves = 0;
  std::vector<std::string> unchangeable;
  for (const std::string& pointer : all) {
    const json::json_pointer ptr(pointer);
    bool changed_scene = false;
    for (const json& value : perturbations(pointer, canonical.at(ptr))) {
      json edited = canonical;
      edited[ptr] = value;
      Scene s;
      try {
        s = parse_scene(edited.dump(), "perturbed " + pointer);
      } catch (const std::exception&) {
        continue;  // not a valid scene: try the next change
      }
      changed_scene = true;
      const bool key_changed = fem_reference_key_text(s, options, "digest") != base_key;
      if (is_realtime_only(pointer)) {
        ++realtime_leaves;
        EXPECT_FALSE(key_changed) << pointer << " is declared real-time-only but changes the FEM key";
      } else {
        ++fem_leaves;
        EXPECT_TRUE(key_changed) << pointer << " (" << canonical.at(ptr).dump() << " -> " << value.dump()
                                 << ") is read by the FEM but does not change its cache key";
      }
      break;
    }
    if (!changed_scene) unchangeable.push_back(pointer);
  }
  for (const std::string& pointer : unchangeable)
    EXPECT_TRUE(structural(pointer)) << pointer << ": no change of it gives a valid scene; the test cannot check it";
  // Fields the issue named as missing from the old key are all leaves that change it.
  for (const char* p : {"/layers/0/puncture/toughness_J_per_m2", "/layers/0/puncture/cohesive_strength_kPa",
                        "/fem/cohesive_viscosity_s", "/layers/1/shaft_friction/coefficient",
                        "/layers/1/shaft_friction/static_coefficient", "/fem/stabilization_time_s",
                        "/layers/2/material/ogden_terms/0/alpha", "/needle/tip_angle_deg", "/fem/geometry",
                        "/fem/mesh/path_element_size_mm", "/insertion/dwell_s", "/insertion/withdrawal_speed_mm_per_s"})
    EXPECT_FALSE(is_realtime_only(p)) << p;
  EXPECT_GT(fem_leaves, 40u);
  EXPECT_GT(realtime_leaves, 40u);
}

TEST(FemReferenceKey, TheRealtimeOnlyListAgreesWithTheSceneSchema) {
  // A field the schema says the FEM reads is in the key, every other field
  // is left out of it (scene_schema.hpp's `fem` column). The key is made of
  // the written scene, so the read-only spellings do not enter it.
  for (const SceneField& f : scene_schema()) {
    if (!f.written) continue;
    std::string pointer = f.path;
    for (std::size_t at = pointer.find("/*"); at != std::string::npos; at = pointer.find("/*", at + 2))
      pointer.replace(at, 2, "/0");
    EXPECT_EQ(is_realtime_only(pointer), !f.fem)
        << f.path << (f.fem ? ": the schema says the FEM reads it, the key leaves it out"
                            : ": the schema says the FEM does not read it, the key holds it");
  }
}

TEST(FemReferenceKey, SolverOptionsEnterTheKeyAndOverridesEqualToTheSceneDoNot) {
  const Scene base = default_scene();
  const std::string k = fem_reference_key_text(base, {}, "digest");
  FemKeyOptions refined;
  refined.refinement = base.fem.refinement + 1;
  EXPECT_NE(fem_reference_key_text(base, refined, "digest"), k);
  FemKeyOptions same;
  same.refinement = base.fem.refinement;
  same.degree = base.fem.element_degree;
  EXPECT_EQ(fem_reference_key_text(base, same, "digest"), k);
  FemKeyOptions mesh;
  mesh.mesh_options = {{"sectors", "8"}};
  EXPECT_NE(fem_reference_key_text(base, mesh, "digest"), k);
  EXPECT_NE(fem_reference_key_text(base, {}, "other digest"), k);
  EXPECT_EQ(fem_reference_key_hash(k).size(), 32u);
  EXPECT_NE(fem_reference_key_hash(k), fem_reference_key_hash(k + " "));
  EXPECT_NE(k.find("\"key_format\": " + std::to_string(kFemReferenceKeyFormat)), std::string::npos);
}

#ifdef PUNCTURE_HAVE_FEM
fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("puncture_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

/// The default slab made small and short: the default's materials, friction,
/// needle and axisymmetric geometry, a skin of low toughness that breaks
/// early, 3 mm in and back out.
Scene small_default_scene() {
  Scene s = default_scene();
  s.sample.diameter_m = 16e-3;
  s.layers[1].thickness_m = 2e-3;
  s.layers[2].thickness_m = 4e-3;
  s.insertion.start_height_m = 0.2e-3;
  s.insertion.target_depth_m = 3e-3;
  s.layers[0].puncture.toughness_J_per_m2 = 10.0;
  s.layers[0].puncture.cohesive_strength_Pa = 200e3;
  s.insertion.dwell_s = 0.02;
  s.insertion.withdrawal_speed_m_per_s = 0.02;
  s.fem.load_step_m = 0.5e-3;
  s.fem.mesh.elements_per_needle_radius = 2;
  s.fem.mesh.min_elements_per_layer = 3;
  s.fem.mesh.path_element_size_mm = 0.5;
  for (Layer& l : s.layers) {  // a force mesh that fits the small sample (real-time only)
    l.force_mesh.rings_w = 3;
    l.force_mesh.spacing_L_m = 1e-3;
  }
  return s;
}

/// Every real-time-only leaf of `s` changed at once (the first valid change of each).
Scene with_realtime_only_fields_changed(const Scene& s) {
  json j = json::parse(scene_to_json_text(s));
  std::vector<std::string> all;
  leaves(j, "", all);
  std::size_t changed = 0;
  for (const std::string& pointer : all) {
    if (!is_realtime_only(pointer)) continue;
    const json::json_pointer ptr(pointer);
    for (const json& value : perturbations(pointer, j.at(ptr))) {
      json trial = j;
      trial[ptr] = value;
      try {
        (void)parse_scene(trial.dump(), "trial");
      } catch (const std::exception&) {
        continue;
      }
      j = trial;
      ++changed;
      break;
    }
  }
  EXPECT_GT(changed, 40u);
  return parse_scene(j.dump(), "real-time-only fields changed");
}

/// A result file without its comment (provenance) lines.
std::string result_text(const fs::path& file) {
  std::ifstream in(file);
  EXPECT_TRUE(in) << file;
  std::string line, text;
  while (std::getline(in, line))
    if (line.empty() || line[0] != '#') text += line + "\n";
  return text;
}

FemReferenceOptions quiet_options(const fs::path& cache) {
  FemReferenceOptions o;
  o.cache_dir = cache;
  o.verbose = false;
  o.write_vtu = false;
  return o;
}

TEST(FemReferenceKey, RealtimeOnlyFieldsLeaveTheFemResultAsItWas) {
  const fs::path cache = fresh_dir("fem_key_invariance");
  std::ostringstream log;
  const Scene base = small_default_scene();
  const Scene changed = with_realtime_only_fields_changed(base);
  Scene other_dwell = base;
  other_dwell.insertion.dwell_s = 0.06;
  const FemReference a = obtain_fem_reference(base, quiet_options(cache / "a"), log);
  const FemReference b = obtain_fem_reference(changed, quiet_options(cache / "b"), log);
  const FemReference c = obtain_fem_reference(other_dwell, quiet_options(cache / "c"), log);
  EXPECT_FALSE(a.from_cache || b.from_cache || c.from_cache);
  EXPECT_EQ(a.hash, b.hash);
  EXPECT_NE(a.hash, c.hash);
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(a.dir / "fem_summary.json"));
  EXPECT_FALSE(summary.at("punctures").empty()) << "the small slab's skin should break within 3 mm";
  for (const char* f : {"fem_force_depth.csv", "fem_surface_profile.csv", "fem_recovery_profile.csv"}) {
    const std::string base_text = result_text(a.dir / f);
    EXPECT_GT(base_text.size(), 100u) << f;
    EXPECT_EQ(result_text(b.dir / f), base_text) << f << " changed with a real-time-only field";
  }
  // The comparison can see a difference: a FEM field (the dwell) changes the curve.
  EXPECT_NE(result_text(c.dir / "fem_force_depth.csv"), result_text(a.dir / "fem_force_depth.csv"));
  fs::remove_all(cache);
}

TEST(FemReferenceCache, AnEntryWhoseStoredKeyIsNotTheCurrentOneIsRecomputed) {
  const fs::path cache = fresh_dir("fem_key_stale");
  const Scene scene = small_default_scene();
  const FemReferenceOptions options = quiet_options(cache);
  const std::string key_text = fem_reference_key_text(scene, options);
  // A complete-looking entry under the current hash, written by an older key format.
  const fs::path dir = cache / fem_reference_hash(scene, options);
  fs::create_directories(dir);
  std::ofstream(dir / "fem_summary.json") << "{\"status\": \"ok\"}\n";
  std::ofstream(dir / "fem_force_depth.csv") << "time_s,depth_mm,force_N\n0,0,0\n";
  std::ofstream(dir / "fem_reference_key.json") << "{\"program_version\": \"old\"}\n";
  EXPECT_FALSE(cached_key_matches(dir, key_text));
  std::ostringstream log;
  const FemReference first = obtain_fem_reference(scene, options, log);
  EXPECT_FALSE(first.from_cache) << "an entry of another key was reused";
  EXPECT_TRUE(cached_key_matches(first.dir, key_text));
  EXPECT_GT(result_text(first.dir / "fem_force_depth.csv").size(), 200u);
  // Now the entry is this key's: the next call is served from it.
  const FemReference second = obtain_fem_reference(scene, options, log);
  EXPECT_TRUE(second.from_cache);
  fs::remove_all(cache);
}
#endif

}  // namespace
}  // namespace puncture::validation
