// provenance_json.hpp: the Provenance of provenance.hpp as a JSON object
// (header-only; needs nlohmann_json, which puncture_io_core links).
#pragma once

#include <nlohmann/json.hpp>

#include "puncture/io/provenance.hpp"

namespace puncture::io {

/// {"command": ..., "program_version": ..., "git_revision": ..., "date_utc": ..., "machine": ...}
inline nlohmann::json provenance_json(const Provenance& p) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [key, value] : provenance_fields(p)) j[key] = value;
  return j;
}

}  // namespace puncture::io
