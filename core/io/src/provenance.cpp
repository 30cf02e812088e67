#include "puncture/io/provenance.hpp"

#include "puncture/io/host.hpp"

#include <link.h>

#include <ctime>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <thread>

namespace puncture::io {

std::string utc_timestamp() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

namespace {
std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos && colon + 2 <= line.size()) return line.substr(colon + 2);
    }
  }
  return "unknown CPU";
}

int find_blas(dl_phdr_info* info, std::size_t, void* data) {
  const std::string name = info->dlpi_name ? info->dlpi_name : "";
  if (name.find("/libblas.so") == std::string::npos) return 0;
  *static_cast<std::string*>(data) = name;
  return 1;
}

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}
}  // namespace

std::string blas_library() {
  std::string loaded;
  dl_iterate_phdr(find_blas, &loaded);
  if (loaded.empty()) return "";
  std::error_code ec;
  const std::filesystem::path real = std::filesystem::canonical(loaded, ec);
  if (ec) return loaded;
  const std::string dir = real.parent_path().filename().string();  // Debian's alternatives: blas, openblas-serial, ...
  return dir == "blas" ? "reference BLAS" : dir;
}

std::string machine_summary() {
  const std::string blas = blas_library();
  return host_name() + " (" + cpu_model() + ", " + std::to_string(std::thread::hardware_concurrency()) + " cores" +
         (blas.empty() ? "" : ", " + blas) + ")";
}

Provenance make_provenance(const std::string& command_line) {
  return {command_line, program_version(), git_revision(), utc_timestamp(), machine_summary()};
}

std::vector<std::pair<std::string, std::string>> provenance_fields(const Provenance& p) {
  return {{"command", one_line(p.command)},
          {"program_version", one_line(p.program_version)},
          {"git_revision", one_line(p.git_revision)},
          {"date_utc", one_line(p.date_utc)},
          {"machine", one_line(p.machine)}};
}

std::string provenance_comment_lines(const Provenance& p) {
  std::string out;
  for (const auto& [key, value] : provenance_fields(p)) out += "# " + key + ": " + value + "\n";
  return out;
}

}  // namespace puncture::io
