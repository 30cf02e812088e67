// Staged files: names that carry pid and host, removal of the staged files of
// dead runs (and only those), the interrupt registry, atomic single files and
// read errors that give the OS reason.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "puncture/io/atomic_file.hpp"
#include "puncture/io/interrupt_cleanup.hpp"
#include "puncture/io/output_session.hpp"

namespace puncture::io {
namespace {
namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(PUNCTURE_BINARY_DIR) / "test_scratch" / ("io_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

/// The pid of a process that has exited (and been reaped).
long dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return static_cast<long>(child);
}

std::string host_suffix() {
  // The suffix of this process's staging names ("@<host>").
  const std::string name = staging_path_for("x").filename().string();
  return name.substr(name.find('@'));
}

TEST(Staging, NamesCarryPidCounterAndHost) {
  const fs::path a = staging_path_for("/tmp/out/summary.json");
  const fs::path b = staging_path_for("/tmp/out/summary.json");
  EXPECT_NE(a, b);
  EXPECT_EQ(a.parent_path(), fs::path("/tmp/out"));
  const std::string name = a.filename().string();
  EXPECT_EQ(name.rfind(".summary.json.staging-" + std::to_string(::getpid()) + "-", 0), 0u) << name;
  EXPECT_FALSE(is_stale_staging_name(name)) << "this process is alive";
}

TEST(Staging, StaleFilesOfDeadRunsAreRemovedOthersKept) {
  const fs::path dir = scratch("stale");
  const long dead = dead_pid();
  const std::string host = host_suffix();
  const fs::path stale = dir / (".summary.json.staging-" + std::to_string(dead) + "-3" + host);
  const fs::path stale_sub = dir / "frames" / (".a.vtp.staging-" + std::to_string(dead) + "-4" + host);
  const fs::path legacy = dir / (".old.csv.staging-" + std::to_string(dead) + "-1");  // name without a host
  const fs::path alive = dir / (".mine.csv.staging-" + std::to_string(::getpid()) + "-1" + host);
  const fs::path other_host = dir / (".x.csv.staging-" + std::to_string(dead) + "-1@another-machine");
  const fs::path user_file = dir / "notes.staging-1-1";  // not hidden: not ours
  fs::create_directories(dir / "frames");
  for (const fs::path& p : {stale, stale_sub, legacy, alive, other_host, user_file}) std::ofstream(p) << "x";

  // A new session in that directory cleans up after the dead run.
  { OutputSession session(dir); }
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_FALSE(fs::exists(stale_sub));
  EXPECT_FALSE(fs::exists(dir / "frames")) << "a folder only the dead run used";
  EXPECT_FALSE(fs::exists(legacy));
  EXPECT_TRUE(fs::exists(alive));
  EXPECT_TRUE(fs::exists(other_host)) << "a process of another host cannot be checked";
  EXPECT_TRUE(fs::exists(user_file));
  fs::remove_all(dir);
}

TEST(Staging, InterruptCleanupRemovesWhatALiveSessionStaged) {
  const fs::path dir = scratch("interrupt") / "new_output";
  OutputSession session(dir);
  session.write_text("summary.json", "{}");
  session.write_text("frames/f0.vtp", "x");
  const fs::path staged = session.stage("summary.json");
  ASSERT_TRUE(fs::exists(staged));
  // What the signal watcher does on SIGINT/SIGTERM.
  EXPECT_EQ(run_cleanup_now(), 2u);
  EXPECT_FALSE(fs::exists(staged));
  EXPECT_FALSE(fs::exists(dir)) << "the directories the session created are removed when empty";
}

TEST(Staging, CommittedFilesAreNoLongerRegistered) {
  const fs::path dir = scratch("committed");
  {
    OutputSession session(dir);
    session.write_text("a.txt", "A");
    session.commit();
  }
  EXPECT_EQ(run_cleanup_now(), 0u);
  EXPECT_TRUE(fs::exists(dir / "a.txt"));
  fs::remove_all(dir);
}

TEST(AtomicFile, FileWrittenByNameIsStagedThenRenamed) {
  // write_file_atomically_with: a library that writes a file by name (the FEM
  // solver's write_vtu) writes the staging name, registered for the interrupt
  // cleanup while it exists; then it is renamed onto the final name.
  const fs::path dir = scratch("atomic_with");
  fs::path seen;
  write_file_atomically_with(dir / "frame.vtu", [&](const fs::path& staged) {
    seen = staged;
    EXPECT_NE(staged.filename().string().find(".staging-"), std::string::npos) << staged;
    std::ofstream(staged) << "frame";
  });
  EXPECT_EQ(read_text_file(dir / "frame.vtu"), "frame");
  EXPECT_FALSE(fs::exists(seen));
  EXPECT_THROW(write_file_atomically_with(dir / "bad.vtu",
                                          [&](const fs::path& staged) {
                                            std::ofstream(staged) << "half";
                                            throw std::runtime_error("writer failed");
                                          }),
               std::runtime_error);
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) (void)e, ++n;
  EXPECT_EQ(n, 1u) << "the failed writer's staged file is removed";
  EXPECT_EQ(run_cleanup_now(), 0u) << "nothing left registered";
  fs::remove_all(dir);
}

TEST(AtomicFile, WritesReplacesAndReportsTheOsReason) {
  const fs::path dir = scratch("atomic");
  write_file_atomically(dir / "a.csv", "one");
  write_file_atomically(dir / "a.csv", "two");
  EXPECT_EQ(read_text_file(dir / "a.csv"), "two");
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) (void)e, ++n;
  EXPECT_EQ(n, 1u) << "no temporary left";
  try {
    write_file_atomically(dir / "missing_dir" / "b.csv", "x");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos) << e.what();
  }
  try {
    read_text_file(dir / "nope.csv");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos) << e.what();
  }
  try {
    read_text_file(dir);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(OutputSessionErrors, UnwritableOutputIsAnOutputErrorNamingThePath) {
  try {
    OutputSession session("/proc/puncture_cannot_be_created");
    FAIL();
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("/proc/puncture_cannot_be_created"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace puncture::io
