#include "puncture/io/interrupt_cleanup.hpp"

#include "puncture/io/host.hpp"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace puncture::io {
namespace fs = std::filesystem;

namespace {

std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}
std::map<fs::path, CleanupKind>& registry() {
  static std::map<fs::path, CleanupKind> r;
  return r;
}
std::atomic<bool> installed{false};
// Threads waiting for the registry: once the watcher holds it for good, a
// writer that waits here has closed every file it staged before.
std::atomic<int> waiting_for_registry{0};

using Entries = std::vector<std::pair<fs::path, CleanupKind>>;

// Removes the files and trees of `entries`, then the directories among them
// that are empty (deepest first). Returns the number of files and trees that
// existed and were removed.
std::size_t remove_entries(const Entries& entries) {
  std::size_t removed = 0;
  std::vector<fs::path> dirs;
  for (const auto& [path, kind] : entries) {
    std::error_code ec;
    if (kind == CleanupKind::File) {
      if (fs::remove(path, ec)) ++removed;
    } else if (kind == CleanupKind::Tree) {
      const auto n = fs::remove_all(path, ec);
      if (n != static_cast<std::uintmax_t>(-1) && n > 0) ++removed;
    } else {
      dirs.push_back(path);
    }
  }
  std::sort(dirs.begin(), dirs.end(), [](const fs::path& a, const fs::path& b) {
    return a.string().size() > b.string().size();
  });
  for (const fs::path& d : dirs) {
    std::error_code ec;
    fs::remove(d, ec);
  }
  return removed;
}

sigset_t watched_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);
  return set;
}

bool process_alive(long pid) {
  if (pid <= 0) return true;  // not a pid we can judge: keep the file
  if (::kill(static_cast<pid_t>(pid), 0) == 0) return true;
  return errno != ESRCH;  // EPERM: it exists, owned by someone else
}

void watcher() {
  const sigset_t set = watched_signals();
  int sig = 0;
  while (sigwait(&set, &sig) != 0) {
  }
  // The registry stays locked until the process ends, so no file is staged
  // after the first pass. A file registered just before it may be created
  // just after it (stage() registers, then the caller opens the file): a
  // second pass once the writer is blocked on the registry (every file it
  // staged is then closed), or after at most one second, removes it.
  std::unique_lock<std::mutex> hold(registry_mutex());
  const Entries entries(registry().begin(), registry().end());
  const std::size_t removed = remove_entries(entries);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (waiting_for_registry.load() == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  remove_entries(entries);
  char message[160];
  std::snprintf(message, sizeof message, "\ninterrupted by signal %d (%s): removed %zu staged file(s); nothing was committed\n",
                sig, sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "SIGHUP", removed);
  (void)!::write(STDERR_FILENO, message, std::char_traits<char>::length(message));
  // End the process by the same signal (default action), so the parent sees
  // a death by signal.
  ::signal(sig, SIG_DFL);
  sigset_t one;
  sigemptyset(&one);
  sigaddset(&one, sig);
  pthread_sigmask(SIG_UNBLOCK, &one, nullptr);
  ::raise(sig);
  ::_exit(128 + sig);
}

// Locks the registry, counting the wait (see waiting_for_registry).
std::unique_lock<std::mutex> lock_registry() {
  ++waiting_for_registry;
  std::unique_lock<std::mutex> lock(registry_mutex());
  --waiting_for_registry;
  return lock;
}

}  // namespace

void install_interrupt_cleanup() {
  if (installed.exchange(true)) return;
  const sigset_t set = watched_signals();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  std::thread(watcher).detach();
}

bool interrupt_cleanup_installed() { return installed.load(); }

void register_cleanup(const fs::path& path, CleanupKind kind) {
  const auto lock = lock_registry();
  registry()[path] = kind;
}

void unregister_cleanup(const fs::path& path) {
  const auto lock = lock_registry();
  registry().erase(path);
}

std::size_t run_cleanup_now() {
  const auto lock = lock_registry();
  const Entries entries(registry().begin(), registry().end());
  registry().clear();
  return remove_entries(entries);
}

bool is_stale_staging_name(const std::string& name) {
  const std::string tag = ".staging-";
  if (name.empty() || name[0] != '.') return false;
  const auto at = name.rfind(tag);
  if (at == std::string::npos) return false;
  std::size_t i = at + tag.size();
  auto read_number = [&](long& value) {
    const std::size_t start = i;
    while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i]))) ++i;
    if (i == start || i - start > 12) return false;
    value = std::stol(name.substr(start, i - start));
    return true;
  };
  long pid = 0, counter = 0;
  if (!read_number(pid) || i >= name.size() || name[i] != '-') return false;
  ++i;
  if (!read_number(counter)) return false;
  if (i < name.size()) {
    // "@<host>": only processes of this host can be checked.
    if (name[i] != '@' || name.substr(i + 1) != host_tag()) return false;
  }
  return !process_alive(pid);
}

std::size_t remove_stale_staging(const fs::path& dir, int depth) {
  std::error_code ec;
  if (depth < 0 || !fs::is_directory(dir, ec)) return 0;
  std::size_t removed = 0;
  std::vector<fs::path> subdirs;
  bool removed_here = false;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::path p = it->path();
    const std::string name = p.filename().string();
    std::error_code e2;
    if (it->is_directory(e2)) {
      if (!name.empty() && name[0] != '.') subdirs.push_back(p);
    } else if (is_stale_staging_name(name)) {
      if (fs::remove(p, e2)) ++removed, removed_here = true;
    }
  }
  for (const fs::path& s : subdirs) {
    const std::size_t n = remove_stale_staging(s, depth - 1);
    removed += n;
    if (n > 0 && fs::is_empty(s, ec)) fs::remove(s, ec);  // a directory only the dead run used
  }
  (void)removed_here;
  return removed;
}

}  // namespace puncture::io
