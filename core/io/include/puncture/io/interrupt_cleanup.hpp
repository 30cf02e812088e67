// interrupt_cleanup.hpp: an interrupted run (Ctrl-C, kill, mpirun aborting a
// job) leaves no staged files behind, and a new run removes the staged files
// of runs that died without cleaning up (SIGKILL, power loss).
//
// install_interrupt_cleanup(): call first thing in main(), before any other
//   thread exists. Blocks SIGINT, SIGTERM and SIGHUP in the calling thread
//   (threads started later inherit the mask) and starts one watcher thread
//   that waits for them. On a signal it removes every registered path, says so
//   on stderr, and ends the process by the same signal (exit status 128 + n in
//   a shell).
// register_cleanup(path, kind) / unregister_cleanup(path): what to remove.
//   OutputSession and write_file_atomically register their staged files and
//   the directories they created (removed only if empty) themselves.
// remove_stale_staging(dir, depth): removes the staging files below dir (at
//   most `depth` directory levels down, hidden directories skipped) whose
//   name says they belong to a process of this host that no longer runs
//   (".<name>.staging-<pid>-<n>@<host>", checked with kill(pid, 0)), and the
//   directories that this leaves empty. Returns the number of files removed.
#pragma once

#include <cstddef>
#include <filesystem>

namespace puncture::io {

enum class CleanupKind {
  File,         ///< unlink
  EmptyDir,     ///< rmdir (left alone unless empty)
  Tree          ///< remove_all (a staging directory)
};

void install_interrupt_cleanup();
bool interrupt_cleanup_installed();

void register_cleanup(const std::filesystem::path& path, CleanupKind kind);
void unregister_cleanup(const std::filesystem::path& path);

/// Removes every registered path now (what the watcher does on a signal);
/// returns the number of paths that existed and were removed.
std::size_t run_cleanup_now();

std::size_t remove_stale_staging(const std::filesystem::path& dir, int depth = 3);

/// True if `name` is a staging file name of this host whose process is gone.
bool is_stale_staging_name(const std::string& file_name);

}  // namespace puncture::io
