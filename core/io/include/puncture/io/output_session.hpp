// output_session.hpp: all-or-nothing writing of the output files of one command.
//
// Every file of a run is first written under a hidden temporary name in the
// directory where it belongs ("<dir>/.<name>.staging-<pid>-<n>@<host>",
// atomic_file.hpp); commit()
// renames each staged file onto its final name (std::filesystem::rename, an
// atomic replace on POSIX within one file system). If the session is
// destroyed without commit() (an exception unwound the run), every staged
// file is deleted, and so is every directory the session created, so a failed
// run leaves nothing half-written and files from earlier runs stay untouched
// (they are only replaced by commit()). The output directory itself is removed
// again if the session created it and it is empty.
//
// Interrupted runs: every staged file and created directory is registered
// with interrupt_cleanup.hpp, so SIGINT/SIGTERM remove them too (once main()
// called install_interrupt_cleanup()). Runs killed without a chance to clean
// up (SIGKILL) are handled by the next session in the same directory: the
// constructor removes staged files of processes of this host that no longer
// run (remove_stale_staging).
//
// In:  relative names ("summary.csv", "frames/skin_0001.vtp"): relative, no
//      "..", not empty. Out: paths to write to now (stage), the final paths
//      (committed_files, after commit).
//
// Not thread-safe; one session per command. Two sessions writing the same
// file: the later commit wins.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace puncture::io {

/// The output cannot be written (directory not creatable, disk full, ...):
/// the message names the path and the OS reason.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class OutputSession {
 public:
  /// Creates output_dir (and parents) if missing and removes stale staged
  /// files of dead runs in it. Throws OutputError (path and OS reason) if it
  /// cannot be created or is not a directory.
  explicit OutputSession(std::filesystem::path output_dir);
  OutputSession(const OutputSession&) = delete;
  OutputSession& operator=(const OutputSession&) = delete;
  /// Rolls back (removes every staged file and created directory) unless committed.
  ~OutputSession();

  /// Registers relative_name and returns the hidden temporary path to write it
  /// to now (its parent directory exists). Staging the same name twice returns
  /// the same path. Throws std::invalid_argument for an absolute name, a name
  /// with "..", or an empty name; std::logic_error after commit().
  std::filesystem::path stage(const std::string& relative_name);

  /// stage() + write `content` (bytes as given). Throws OutputError on an I/O
  /// error.
  void write_text(const std::string& relative_name, const std::string& content);

  /// Renames every staged file into place, in staging order. Throws
  /// std::runtime_error naming the file if a staged file was never written
  /// (checked for all files before the first rename) or a rename fails.
  /// Throws std::logic_error if called twice.
  void commit();

  /// Final paths of the committed files (empty before commit()).
  const std::vector<std::filesystem::path>& committed_files() const { return committed_; }
  const std::filesystem::path& output_dir() const { return output_dir_; }
  bool committed() const { return is_committed_; }

 private:
  struct Staged {
    std::filesystem::path final_path;
    std::filesystem::path staged_path;
  };
  void rollback() noexcept;

  std::filesystem::path output_dir_;
  std::vector<Staged> staged_;
  std::vector<std::filesystem::path> created_dirs_;  ///< created by this session, parents first (output dir included)
  std::vector<std::filesystem::path> committed_;
  bool is_committed_ = false;
};

}  // namespace puncture::io
