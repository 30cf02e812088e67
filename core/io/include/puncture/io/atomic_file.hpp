// atomic_file.hpp: whole-file reading and all-or-nothing writing of single
// files (for code that does not write through an OutputSession, e.g. the FEM
// reference on each MPI rank).
//
// write_file_atomically(path, contents): writes to the hidden temporary
//   "<dir>/.<name>.staging-<pid>-<n>@<host>" (the OutputSession's staging name,
//   so remove_stale_staging() and the interrupt cleanup know it), then renames
//   it onto path (atomic on POSIX within one file system). On any failure the
//   temporary is removed and std::runtime_error names the file and the OS
//   reason. While it exists, the temporary is registered for removal on
//   SIGINT/SIGTERM (interrupt_cleanup.hpp).
// write_file_atomically_with(path, write): the same for a file another
//   library writes by name (deal.II's DataOut behind a solver's write_vtu):
//   write(staging_path) makes the file, which is then renamed onto path. An
//   exception from write removes the staged file and propagates.
// read_text_file(path): the bytes of a regular file; std::runtime_error with
//   the OS reason ("No such file or directory", "Is a directory", ...).
#pragma once

#include <filesystem>
#include <functional>
#include <string>

namespace puncture::io {

void write_file_atomically(const std::filesystem::path& path, const std::string& contents);

void write_file_atomically_with(const std::filesystem::path& path,
                                const std::function<void(const std::filesystem::path& staging_path)>& write);

std::string read_text_file(const std::filesystem::path& path);

/// The hidden staging name of `final_path` for this process:
/// "<dir>/.<name>.staging-<pid>-<n>@<host>" with a process-wide counter n.
std::filesystem::path staging_path_for(const std::filesystem::path& final_path);

}  // namespace puncture::io
