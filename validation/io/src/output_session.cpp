#include <puncture/io/output_session.hpp>

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace puncture::io {
namespace fs = std::filesystem;

namespace {
std::atomic<unsigned long> session_counter{0};
}

OutputSession::OutputSession(fs::path output_dir) : output_dir_(std::move(output_dir)) {
  if (output_dir_.empty()) throw std::invalid_argument("OutputSession: empty output directory");
  std::error_code ec;
  fs::create_directories(output_dir_, ec);
  if (ec || !fs::is_directory(output_dir_))
    throw std::runtime_error("OutputSession: cannot create output directory '" + output_dir_.string() +
                             "'" + (ec ? ": " + ec.message() : std::string()));
  token_ = std::to_string(static_cast<long>(::getpid())) + "-" + std::to_string(++session_counter);
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

  // Create the missing parent directories one by one so rollback can remove
  // exactly the ones this session made.
  fs::path dir = output_dir_;
  for (const auto& part : rel.lexically_normal().parent_path()) {
    dir /= part;
    if (fs::exists(dir)) {
      if (!fs::is_directory(dir))
        throw std::runtime_error("OutputSession::stage: '" + dir.string() + "' is not a directory");
      continue;
    }
    std::error_code ec;
    fs::create_directory(dir, ec);
    if (ec)
      throw std::runtime_error("OutputSession::stage: cannot create '" + dir.string() + "': " +
                               ec.message());
    created_dirs_.push_back(dir);
  }
  const fs::path staged_path =
      final_path.parent_path() / ("." + final_path.filename().string() + ".staging-" + token_);
  staged_.push_back({final_path, staged_path});
  return staged_path;
}

void OutputSession::write_text(const std::string& relative_name, const std::string& content) {
  const fs::path path = stage(relative_name);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
  out.close();
  if (!out) throw std::runtime_error("OutputSession: failed to write '" + path.string() + "'");
}

void OutputSession::commit() {
  if (is_committed_) throw std::logic_error("OutputSession::commit() called twice");
  for (const auto& s : staged_)
    if (!fs::is_regular_file(s.staged_path))
      throw std::runtime_error("OutputSession::commit: '" + s.final_path.string() +
                               "' was staged but never written");
  for (const auto& s : staged_) {
    std::error_code ec;
    fs::rename(s.staged_path, s.final_path, ec);
    if (ec)
      throw std::runtime_error("OutputSession::commit: cannot move '" + s.staged_path.string() +
                               "' to '" + s.final_path.string() + "': " + ec.message());
    committed_.push_back(s.final_path);
  }
  is_committed_ = true;
}

void OutputSession::rollback() noexcept {
  for (const auto& s : staged_) {
    std::error_code ec;
    fs::remove(s.staged_path, ec);
  }
  // Deepest first; remove() leaves a directory alone unless it is empty (a
  // file committed before a failed rename keeps its directory).
  for (auto it = created_dirs_.rbegin(); it != created_dirs_.rend(); ++it) {
    std::error_code ec;
    fs::remove(*it, ec);
  }
}

}  // namespace puncture::io
