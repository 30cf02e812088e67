// OutputSession: nothing is left behind without commit (also when an
// exception unwinds mid-way); exactly the committed files after commit;
// earlier files survive a failed run and are replaced by a committed one.
#include <puncture/io/output_session.hpp>
#include <puncture/io/csv_table.hpp>
#include <puncture/vtk_io/vtk_polydata.hpp>

#include "test_io_common.hpp"

#include <stdexcept>

namespace {

using puncture::io::OutputSession;
using puncture::io::testing::ScratchDir;
using puncture::io::testing::list_tree;
using puncture::io::testing::read_file;
namespace fs = std::filesystem;

TEST(OutputSession, DestroyedWithoutCommitLeavesNothing) {
  ScratchDir scratch;
  const fs::path out = scratch.path() / "run";
  {
    OutputSession session(out);
    EXPECT_TRUE(fs::is_directory(out));
    session.write_text("summary.csv", "a,b\n1,2\n");
    session.write_text("frames/deep/f0.txt", "frame");
    const fs::path staged = session.stage("notes.txt");
    EXPECT_EQ(staged.parent_path(), out);
    EXPECT_EQ(staged.filename().string().front(), '.') << "staged files are hidden";
    // While the run goes on, the staged files exist under hidden names only.
    EXPECT_FALSE(fs::exists(out / "summary.csv"));
    EXPECT_FALSE(list_tree(out).empty());
  }
  // The session created `out`: it is removed too.
  EXPECT_FALSE(fs::exists(out));
}

TEST(OutputSession, ExceptionMidRunKeepsEarlierFilesAndRemovesStaged) {
  ScratchDir scratch;
  const fs::path out = scratch.path();
  {
    OutputSession earlier(out);
    earlier.write_text("summary.csv", "from the earlier run\n");
    earlier.commit();
  }
  auto failing_run = [&] {
    OutputSession session(out);
    session.write_text("summary.csv", "half-written new run\n");
    Eigen::MatrixX3d v(3, 3);
    v << 0, 0, 0, 1, 0, 0, 0, 1, 0;
    Eigen::MatrixX3i t(1, 3);
    t << 0, 1, 2;
    puncture::io::write_polydata(session, "frames/skin_0000.vtp", v, t, {}, {});
    throw std::runtime_error("solver diverged");
  };
  EXPECT_THROW(failing_run(), std::runtime_error);
  EXPECT_EQ(list_tree(out), (std::set<std::string>{"summary.csv"}));
  EXPECT_EQ(read_file(out / "summary.csv"), "from the earlier run\n");
}

TEST(OutputSession, CommitLeavesExactlyTheCommittedFiles) {
  ScratchDir scratch;
  const fs::path out = scratch.path();
  {
    OutputSession old_run(out);
    old_run.write_text("summary.csv", "old\n");
    old_run.commit();
  }
  OutputSession session(out);
  session.write_text("summary.csv", "new\n");
  session.write_text("frames/a.txt", "A");
  session.write_text("frames/a.txt", "A2");  // same name twice: one file, last content
  session.write_text("b.txt", "B");
  EXPECT_TRUE(session.committed_files().empty());
  session.commit();
  EXPECT_TRUE(session.committed());
  EXPECT_EQ(list_tree(out), (std::set<std::string>{"summary.csv", "frames", "frames/a.txt", "b.txt"}));
  EXPECT_EQ(read_file(out / "summary.csv"), "new\n");
  EXPECT_EQ(read_file(out / "frames/a.txt"), "A2");
  ASSERT_EQ(session.committed_files().size(), 3u);
  EXPECT_EQ(session.committed_files()[0], out / "summary.csv");
  EXPECT_EQ(session.committed_files()[1], out / "frames/a.txt");
  EXPECT_THROW(session.commit(), std::logic_error);
  EXPECT_THROW(session.stage("late.txt"), std::logic_error);
}

TEST(OutputSession, CommitRefusesAFileThatWasStagedButNeverWritten) {
  ScratchDir scratch;
  {
    OutputSession session(scratch.path());
    session.write_text("written.txt", "x");
    session.stage("forgotten.txt");
    try {
      session.commit();
      FAIL() << "commit accepted a file that was never written";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("forgotten.txt"), std::string::npos);
    }
  }
  EXPECT_TRUE(list_tree(scratch.path()).empty()) << "no rename happens before all files are checked";
}

TEST(OutputSession, RejectsNamesOutsideTheOutputDirectory) {
  ScratchDir scratch;
  OutputSession session(scratch.path());
  EXPECT_THROW(session.stage(""), std::invalid_argument);
  EXPECT_THROW(session.stage("/etc/passwd"), std::invalid_argument);
  EXPECT_THROW(session.stage("../escape.txt"), std::invalid_argument);
  EXPECT_THROW(session.stage("a/../../escape.txt"), std::invalid_argument);
  EXPECT_THROW(session.stage("dir/"), std::invalid_argument);
}

TEST(OutputSession, ConstructorFailsOnAFileInTheWay) {
  ScratchDir scratch;
  {
    OutputSession s(scratch.path());
    s.write_text("plain_file", "x");
    s.commit();
  }
  EXPECT_THROW(OutputSession(scratch.path() / "plain_file"), std::runtime_error);
}

}  // namespace
