#include "puncture/io/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "puncture/io/host.hpp"
#include "puncture/io/interrupt_cleanup.hpp"

namespace puncture::io {
namespace fs = std::filesystem;

namespace {
std::atomic<unsigned long> staging_counter{0};
}  // namespace

fs::path staging_path_for(const fs::path& final_path) {
  static const std::string host = host_tag();
  return final_path.parent_path() / ("." + final_path.filename().string() + ".staging-" +
                                     std::to_string(static_cast<long>(::getpid())) + "-" +
                                     std::to_string(++staging_counter) + "@" + host);
}

namespace {
// Removes the staged file and throws std::runtime_error naming `path`.
[[noreturn]] void fail_staged(const fs::path& path, const fs::path& tmp, const std::string& what, int error) {
  std::error_code ignored;
  fs::remove(tmp, ignored);
  unregister_cleanup(tmp);
  throw std::runtime_error("cannot write '" + path.string() + "': " + what +
                           (error ? std::string(": ") + std::strerror(error) : std::string()));
}

// Renames the complete staged file onto `path`.
void commit_staged(const fs::path& tmp, const fs::path& path) {
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) fail_staged(path, tmp, "rename failed (" + ec.message() + ")", 0);
  unregister_cleanup(tmp);
}
}  // namespace

void write_file_atomically(const fs::path& path, const std::string& contents) {
  const fs::path tmp = staging_path_for(path);
  register_cleanup(tmp, CleanupKind::File);
  {
    errno = 0;
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) fail_staged(path, tmp, "cannot create a file in '" + path.parent_path().string() + "'", errno);
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.flush();
    if (!out) fail_staged(path, tmp, "write failed", errno);
  }
  commit_staged(tmp, path);
}

void write_file_atomically_with(const fs::path& path, const std::function<void(const fs::path&)>& write) {
  const fs::path tmp = staging_path_for(path);
  register_cleanup(tmp, CleanupKind::File);
  try {
    write(tmp);
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    unregister_cleanup(tmp);
    throw;
  }
  std::error_code ec;
  if (!fs::is_regular_file(tmp, ec)) fail_staged(path, tmp, "the writer made no file", 0);
  commit_staged(tmp, path);
}

std::string read_text_file(const fs::path& path) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (ec || !fs::exists(status))
    throw std::runtime_error("cannot read '" + path.string() + "': " +
                             (ec ? ec.message() : std::string(std::strerror(ENOENT))));
  if (fs::is_directory(status)) throw std::runtime_error("cannot read '" + path.string() + "': it is a directory");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read '" + path.string() + "': " + std::strerror(errno ? errno : EACCES));
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw std::runtime_error("cannot read '" + path.string() + "': read error");
  return s.str();
}

}  // namespace puncture::io
