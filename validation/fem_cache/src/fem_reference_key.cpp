// fem_reference_key.cpp: see fem_reference_key.hpp.
#include "puncture/validation/fem_reference_key.hpp"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "puncture/io/content_hash.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/scene_schema.hpp"

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
  // From the schema's `fem` column: each field the FEM does not read, widened
  // to the largest block above it that holds no field the FEM reads.
  static const std::vector<std::string> fields = [] {
    const std::vector<SceneField>& schema = scene_schema();
    auto all_realtime_only_under = [&](const std::string& block) {
      return std::none_of(schema.begin(), schema.end(), [&](const SceneField& f) {
        return f.fem && f.path.compare(0, block.size() + 1, block + "/") == 0;
      });
    };
    std::vector<std::string> out;
    for (const SceneField& f : schema) {
      if (f.fem || !f.written) continue;
      std::string subtree = f.path;
      for (std::size_t cut = f.path.find('/', 1); cut != std::string::npos; cut = f.path.find('/', cut + 1)) {
        const std::string block = f.path.substr(0, cut);
        if (block.back() != '*' && all_realtime_only_under(block)) {
          subtree = block;
          break;
        }
      }
      if (std::find(out.begin(), out.end(), subtree) == out.end()) out.push_back(subtree);
    }
    return out;
  }();
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
