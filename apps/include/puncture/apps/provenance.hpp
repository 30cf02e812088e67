// provenance.hpp: who/what/where/when for every output file, so a reader can
// reproduce it: program version and git revision, UTC date, host name, CPU
// model and core count.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace puncture::apps {

std::string utc_timestamp();      ///< e.g. "2026-11-21T23:59:00Z"
std::string machine_summary();    ///< e.g. "host (Intel Xeon ..., 2 cores)"
nlohmann::json provenance_json(const std::string& command_line);

}  // namespace puncture::apps
