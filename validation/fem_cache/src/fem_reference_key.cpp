// fem_reference_key.cpp: see fem_reference_key.hpp.
#include "puncture/validation/fem_reference_key.hpp"

#include <nlohmann/json.hpp>

#include "puncture/io/content_hash.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/scene_io.hpp"

namespace puncture::validation {

namespace {

using json = nlohmann::json;

/// Splits "/a/b/0" into {"a", "b", "0"} (no escapes: scene keys have none).
std::vector<std::string> tokens(const std::string& pointer) {
  std::vector<std::string> out;
  std::size_t at = 0;
  while (at < pointer.size() && pointer[at] == '/') {
    const std::size_t next = pointer.find('/', at + 1);
    out.push_back(pointer.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1));
    if (next == std::string::npos) break;
    at = next;
  }
  return out;
}

/// Removes the subtree at `pattern` (tokens, "*" = every array element) from `node`.
void erase_pattern(json& node, const std::vector<std::string>& pattern, std::size_t depth) {
  if (depth + 1 == pattern.size()) {
    if (node.is_object()) node.erase(pattern[depth]);
    return;
  }
  if (pattern[depth] == "*") {
    if (node.is_array())
      for (json& element : node) erase_pattern(element, pattern, depth + 1);
    return;
  }
  if (node.is_object() && node.contains(pattern[depth])) erase_pattern(node[pattern[depth]], pattern, depth + 1);
}

}  // namespace

const std::vector<std::string>& realtime_only_fields() {
  // Everything else in the canonical scene JSON is read by the FEM or may
  // be: a field absent from this list is part of the key.
  static const std::vector<std::string> fields{
      "/name",                        // labels only (the cached summary names the scene that made it)
      "/description",
      "/layers/*/density_kg_per_m3",  // the FEM is quasi-static
      "/layers/*/force_mesh",         // K, w, L, surface stiffness, threshold, node damping
      "/layers/*/damping_d_N_s_per_m2",
      "/layers/*/resumption_time_s",
      "/layers/*/force_law",          // breakthrough, stiffening, cutting, friction of the real-time law
      "/layers/*/material/source",    // provenance text
      "/layers/*/material/viscoelastic/source",
      "/layers/*/puncture/source",
      "/layers/*/shaft_friction/source",
      "/realtime",
      "/effects",
      "/haptics",
      "/comparison",                  // the comparison models' tetrahedral mesh and integrator
  };
  return fields;
}

bool is_realtime_only(const std::string& pointer) {
  const std::vector<std::string> p = tokens(pointer);
  for (const std::string& field : realtime_only_fields()) {
    const std::vector<std::string> f = tokens(field);
    if (f.size() > p.size()) continue;
    bool inside = true;
    for (std::size_t i = 0; i < f.size() && inside; ++i) inside = f[i] == "*" || f[i] == p[i];
    if (inside) return true;
  }
  return false;
}

std::string fem_relevant_scene_json(const Scene& scene) {
  json canonical = json::parse(scene_to_json_text(scene));
  for (const std::string& field : realtime_only_fields()) erase_pattern(canonical, tokens(field), 0);
  return canonical.dump(2);
}

std::string fem_reference_key_text(const Scene& scene, const FemKeyOptions& options,
                                   const std::string& fem_source_digest) {
  // The overrides are applied to the scene, so an override equal to the
  // scene's own value is the same FEM.
  Scene effective = scene;
  if (options.refinement >= 0) effective.fem.refinement = options.refinement;
  if (options.degree >= 1) effective.fem.element_degree = options.degree;
  nlohmann::ordered_json key;
  key["key_format"] = kFemReferenceKeyFormat;
  key["program_version"] = io::program_version();
  key["fem_source_digest"] = fem_source_digest;
  key["scene"] = json::parse(fem_relevant_scene_json(effective));
  nlohmann::ordered_json mesh = nlohmann::ordered_json::object();
  for (const auto& [name, value] : options.mesh_options) mesh[name] = value;
  key["hex_mesh_options"] = mesh;
  return key.dump(2) + "\n";
}

std::string fem_reference_key_hash(const std::string& key_text) {
  return io::fnv1a64_hex(key_text) + io::fnv1a64_hex(key_text, 0x84222325cbf29ce4ULL);
}

}  // namespace puncture::validation
