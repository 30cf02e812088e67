#include "puncture/apps/provenance.hpp"

#include <unistd.h>

#include <ctime>
#include <fstream>
#include <thread>

namespace puncture::apps {

std::string utc_timestamp() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

static std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(colon + 2);
    }
  }
  return "unknown CPU";
}

std::string machine_summary() {
  char host[256] = "unknown";
  gethostname(host, sizeof host - 1);
  return std::string(host) + " (" + cpu_model() + ", " + std::to_string(std::thread::hardware_concurrency()) +
         " cores)";
}

nlohmann::json provenance_json(const std::string& command_line) {
  return {{"command", command_line},
          {"program_version", PUNCTURE_VERSION},
          {"git_revision", PUNCTURE_GIT_REVISION},
          {"date_utc", utc_timestamp()},
          {"machine", machine_summary()}};
}

}  // namespace puncture::apps
