#include <puncture/io/output_session.hpp>

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <system_error>

#include <puncture/io/atomic_file.hpp>
#include <puncture/io/interrupt_cleanup.hpp>

namespace puncture::io {
namespace fs = std::filesystem;

OutputSession::OutputSession(fs::path output_dir) : output_dir_(std::move(output_dir)) {
  if (output_dir_.empty()) throw std::invalid_argument("OutputSession: empty output directory");
  // Create the missing directories one by one, so rollback removes exactly
  // the ones this session made.
  std::vector<fs::path> missing;
  std::error_code ec;
  for (fs::path p = fs::absolute(output_dir_, ec); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    if (!fs::create_directory(*it, ec) && ec)
      throw OutputError("cannot create output directory '" + output_dir_.string() + "': " + ec.message());
    created_dirs_.push_back(*it);
    register_cleanup(*it, CleanupKind::EmptyDir);
  }
  if (!fs::is_directory(output_dir_, ec))
    throw OutputError("cannot use output directory '" + output_dir_.string() + "': it exists and is not a directory");
  if (::access(output_dir_.c_str(), W_OK | X_OK) != 0)
    throw OutputError("cannot write to output directory '" + output_dir_.string() + "': " + std::strerror(errno));
  remove_stale_staging(output_dir_);
}

OutputSession::~OutputSession() {
  if (!is_committed_) rollback();
}

fs::path OutputSession::stage(const std::string& relative_name) {
  if (is_committed_)
    throw std::logic_error("OutputSession::stage('" + relative_name + "') after commit()");
  const fs::path rel = fs::path(relative_name);
  if (relative_name.empty() || rel.has_root_path() || !rel.has_filename())
    throw std::invalid_argument("OutputSession::stage: '" + relative_name +
                                "' is not a relative file name");
  for (const auto& part : rel)
    if (part == "..")
      throw std::invalid_argument("OutputSession::stage: '" + relative_name +
                                  "' must not leave the output directory (contains '..')");
  const fs::path final_path = output_dir_ / rel.lexically_normal();
  for (const auto& s : staged_)
    if (s.final_path == final_path) return s.staged_path;

  fs::path dir = output_dir_;
  for (const auto& part : rel.lexically_normal().parent_path()) {
    dir /= part;
    if (fs::exists(dir)) {
      if (!fs::is_directory(dir))
        throw OutputError("cannot write '" + final_path.string() + "': '" + dir.string() + "' is not a directory");
      continue;
    }
    std::error_code ec;
    fs::create_directory(dir, ec);
    if (ec) throw OutputError("cannot create '" + dir.string() + "': " + ec.message());
    created_dirs_.push_back(dir);
    register_cleanup(dir, CleanupKind::EmptyDir);
  }
  const fs::path staged_path = staging_path_for(final_path);
  staged_.push_back({final_path, staged_path});
  register_cleanup(staged_path, CleanupKind::File);
  return staged_path;
}

void OutputSession::write_text(const std::string& relative_name, const std::string& content) {
  const fs::path path = stage(relative_name);
  errno = 0;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
  out.close();
  if (!out)
    throw OutputError("cannot write '" + (output_dir_ / relative_name).string() + "'" +
                      (errno ? std::string(": ") + std::strerror(errno) : std::string()));
}

void OutputSession::commit() {
  if (is_committed_) throw std::logic_error("OutputSession::commit() called twice");
  for (const auto& s : staged_)
    if (!fs::is_regular_file(s.staged_path))
      throw OutputError("OutputSession::commit: '" + s.final_path.string() + "' was staged but never written");
  for (const auto& s : staged_) {
    std::error_code ec;
    fs::rename(s.staged_path, s.final_path, ec);
    if (ec)
      throw OutputError("cannot move '" + s.staged_path.string() + "' to '" + s.final_path.string() +
                        "': " + ec.message());
    unregister_cleanup(s.staged_path);
    committed_.push_back(s.final_path);
  }
  for (const auto& d : created_dirs_) unregister_cleanup(d);
  is_committed_ = true;
}

void OutputSession::rollback() noexcept {
  for (const auto& s : staged_) {
    std::error_code ec;
    fs::remove(s.staged_path, ec);
    unregister_cleanup(s.staged_path);
  }
  // Deepest first; remove() leaves a directory alone unless it is empty (a
  // file committed before a failed rename keeps its directory).
  for (auto it = created_dirs_.rbegin(); it != created_dirs_.rend(); ++it) {
    std::error_code ec;
    fs::remove(*it, ec);
    unregister_cleanup(*it);
  }
}

}  // namespace puncture::io
