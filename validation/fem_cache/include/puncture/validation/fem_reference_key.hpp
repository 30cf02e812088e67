// fem_reference_key.hpp: the key of a cached FEM reference, derived from
// everything the FEM run reads.
//
// The key text is the scene's canonical JSON (scene_to_json_text: every field
// of the Scene, defaults written out, numbers in the file's units) with the
// fields that only the real-time model reads taken out, plus the solver's own
// options (refinement / degree overrides applied to the scene's fem block, the
// 3D hex mesh options), the program version, a digest of the FEM and mesh
// sources and the key format. So a field that is added to the scene enters the
// key unless scene_schema.hpp's `fem` column says the FEM does not read it
// (realtime_only_fields() is derived from that column); a
// test (tests/validation/test_fem_reference_key.cpp) perturbs every leaf of
// the default scene and runs the FEM with every real-time-only field changed
// to show that those fields leave the FEM's result as it was.
//
// In:  a Scene (SI units), the overrides of FemKeyOptions.
// Out: the key text (JSON, for fem_reference_key.json beside the cached
//      result) and its 128-bit hash (32 hex digits, the cache directory name).
#pragma once

#include <string>
#include <vector>

#include "puncture/scene.hpp"

namespace puncture::validation {

/// Version of the key's layout. A cache entry written with another layout has
/// another hash, and an entry whose stored key text differs from the current
/// one is recomputed (cached_key_matches), so no older entry is reused.
inline constexpr int kFemReferenceKeyFormat = 2;

/// The solver options that are not part of the scene but change the result.
struct FemKeyOptions {
  int refinement = -1;  ///< -1: the scene's fem.refinement
  int degree = -1;      ///< -1: the scene's fem.element_degree
  /// The 3D hex mesh options (meshing::SlabMeshOptions), as name -> value
  /// text; empty in a build without the FEM.
  std::vector<std::pair<std::string, std::string>> mesh_options;
};

/// JSON pointers (RFC 6901, "*" for any array index) of the canonical scene's
/// fields that only the real-time model reads, derived from scene_schema()'s
/// `fem` column: each such field, or the largest block above it that holds no
/// field the FEM reads (e.g. "/realtime", "/layers/*/force_mesh"). Each
/// removes the whole subtree.
const std::vector<std::string>& realtime_only_fields();

/// True when `pointer` (e.g. "/layers/0/force_mesh/w") lies inside one of
/// realtime_only_fields().
bool is_realtime_only(const std::string& pointer);

/// The canonical scene JSON minus realtime_only_fields(), as a JSON text.
std::string fem_relevant_scene_json(const Scene& scene);

/// The whole key text: key format, program version, FEM source digest
/// (`fem_source_digest`), the FEM-relevant scene and the solver options.
std::string fem_reference_key_text(const Scene& scene, const FemKeyOptions& options,
                                   const std::string& fem_source_digest);

/// 128-bit hash of a key text (two FNV-1a 64 passes), 32 hex digits.
std::string fem_reference_key_hash(const std::string& key_text);

}  // namespace puncture::validation
