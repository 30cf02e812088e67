// The program's contract at its edges: exit codes, --version, -q, provenance
// in every output file, warnings for implausible results, decimation of huge
// per-tick tables, and interrupted runs that leave nothing behind.
#include <gtest/gtest.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <thread>

#ifdef PUNCTURE_HAVE_VTK
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataReader.h>
#endif

#include "puncture/apps/commands.hpp"
#include "puncture/io/csv_reader.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/calibration.hpp"

extern char** environ;

namespace fs = std::filesystem;

namespace puncture::apps {
namespace {

const fs::path kSourceDir = PUNCTURE_SOURCE_DIR;
const fs::path kProgram = fs::path(PUNCTURE_BINARY_DIR) / "apps" / "puncture";

fs::path fresh(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("puncture_hard_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

nlohmann::json default_scene_json() {
  std::ifstream in(kSourceDir / "scenes" / "default.json");
  return nlohmann::json::parse(in);
}

fs::path write_scene(const std::string& name, const nlohmann::json& j) {
  const fs::path p = fresh(name + "_scene").string() + ".json";
  std::ofstream(p) << j.dump(2);
  return p;
}

struct Result {
  int exit_code = -1;
  std::string out, err;
};

/// Runs the puncture executable with `args` (shell words), capturing output.
Result run_program(const std::string& args) {
  const fs::path out = fresh("stdout"), err = fresh("stderr");
  Result r;
  const int status = std::system((kProgram.string() + " " + args + " > " + out.string() + " 2> " + err.string()).c_str());
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream o(out), e(err);
  std::stringstream so, se;
  so << o.rdbuf(), se << e.rdbuf();
  r.out = so.str(), r.err = se.str();
  fs::remove(out), fs::remove(err);
  return r;
}

std::vector<fs::path> staging_files(const fs::path& dir) {
  std::vector<fs::path> found;
  if (!fs::exists(dir)) return found;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".staging-") != std::string::npos) found.push_back(e.path());
  return found;
}

TEST(ProgramContract, VersionPrintsTheBuildRevisionAndTheFemSourceDigest) {
  const Result r = run_program("--version");
  EXPECT_EQ(r.exit_code, 0);
  const std::string head = std::string("puncture ") + io::program_version() + " (git " + io::git_revision() +
                           ", FEM sources ";
  ASSERT_EQ(r.out.substr(0, head.size()), head);
  // 16 hex digits of the sources' SHA-256 (the cache key's digest), never the
  // "none" of a build that did not compute it.
  EXPECT_TRUE(std::regex_match(r.out.substr(head.size()), std::regex("[0-9a-f]{16}\\)\n"))) << r.out;
}

TEST(ProgramContract, ExitCodesAreTheDocumentedOnes) {
  EXPECT_EQ(run_program("--help").exit_code, 0);
  EXPECT_EQ(run_program("").exit_code, kExitBadInput);                  // no subcommand
  EXPECT_EQ(run_program("frobnicate").exit_code, kExitBadInput);        // unknown subcommand
  EXPECT_EQ(run_program("run --bogus-flag").exit_code, kExitBadInput);  // unknown option
  EXPECT_EQ(run_program("fem --refinement 9").exit_code, kExitBadInput);
  EXPECT_EQ(run_program("fem --stop-depth -1").exit_code, kExitBadInput);
  EXPECT_EQ(run_program("grade").exit_code, kExitBadInput);             // missing required argument

  Result r = run_program("run /nonexistent/scene.json");
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.err.find("/nonexistent/scene.json: cannot open scene file: No such file or directory"), std::string::npos)
      << r.err;
  r = run_program("run " + kSourceDir.string());
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.err.find("is a directory, not a scene file"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("malformed"), std::string::npos) << r.err;

  // An output that cannot be written is blamed on the output, not on the scene.
  const fs::path scene = kSourceDir / "scenes" / "default.json";
  r = run_program("run " + scene.string() + " -q --no-frames -o /proc/puncture_no_such_dir");
  EXPECT_EQ(r.exit_code, kExitOutput);
  EXPECT_NE(r.err.find("error: cannot create output directory '/proc/puncture_no_such_dir'"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(scene.string()), std::string::npos) << r.err;

  // A bad scores file is bad input (2), a bad --mu too.
  const fs::path scores = fresh("scores").string() + ".csv";
  std::ofstream(scores) << "model,resident,a\nm,r,not_a_number\n";
  r = run_program("grade " + scores.string() + " -o " + fresh("grade_out").string());
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.err.find(":2: column 3 (a): not a finite number"), std::string::npos) << r.err;
  EXPECT_EQ(run_program("grade " + scores.string() + " --mu 2").exit_code, kExitBadInput);
  fs::remove(scores);

  // Speed 0 names the JSON path and leaves no folder behind.
  nlohmann::json j = default_scene_json();
  j["insertion"]["speed_mm_per_s"] = 0;
  const fs::path bad = write_scene("speed0", j);
  const fs::path out_dir = fresh("speed0_out");
  r = run_program("run " + bad.string() + " -o " + out_dir.string());
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.err.find("/insertion/speed_mm_per_s: must be > 0"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out_dir));
  fs::remove(bad);
}

#ifdef PUNCTURE_HAVE_FEM
TEST(ProgramContract, FemStopDepthEndsTheInsertionThereWithoutHoldOrWithdrawal) {
  const fs::path dir = fresh("fem_stop");
  const Result r = run_program("fem " + (kSourceDir / "scenes" / "default.json").string() +
                               " --stop-depth 0.6 --no-vtu -q -o " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::CsvDocument t = io::read_csv_file(dir / "fem_force_depth.csv");
  ASSERT_FALSE(t.records.empty());
  const std::size_t depth = t.require_column("depth_mm"), phase = t.require_column("phase");
  EXPECT_NEAR(t.number(t.records.back(), depth), 0.6, 1e-9);
  for (const io::CsvRecord& row : t.records) {
    EXPECT_NE(row.fields[phase], "dwell");
    EXPECT_NE(row.fields[phase], "withdrawal");
  }
  fs::remove_all(dir);
}
#endif

TEST(ProgramContract, QuietPrintsNothingOnStdout) {
  const fs::path dir = fresh("quiet");
  const Result r = run_program("run " + (kSourceDir / "scenes" / "default.json").string() + " --no-frames -q -o " +
                               dir.string());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "");
  EXPECT_TRUE(fs::exists(dir / "summary.json"));
  // Without -q the report is printed.
  const Result loud = run_program("run " + (kSourceDir / "scenes" / "default.json").string() + " --no-frames -o " +
                                  dir.string());
  EXPECT_NE(loud.out.find("Puncture events (3)"), std::string::npos);
  fs::remove_all(dir);
}

TEST(ProgramContract, EveryOutputFileCarriesProvenance) {
  const fs::path dir = fresh("provenance");
  RunOptions options;
  options.scene = kSourceDir / "scenes" / "default.json";
  options.output_dir = dir;
  options.quiet = true;
  std::ostringstream out, err;
  ASSERT_EQ(run_command(options, out, err), 0) << err.str();
  EXPECT_EQ(out.str(), "");
  std::size_t checked = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    const fs::path p = e.path();
    std::ifstream in(p);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (p.extension() == ".csv") {
      const io::CsvDocument doc = io::parse_csv(text, p.string());
      ASSERT_NE(doc.metadata_value("command"), nullptr) << p;
      EXPECT_EQ(*doc.metadata_value("git_revision"), io::git_revision()) << p;
      EXPECT_NE(doc.metadata_value("date_utc"), nullptr) << p;
      EXPECT_NE(doc.metadata_value("machine"), nullptr) << p;
    } else if (p.extension() == ".json") {
      const nlohmann::json j = nlohmann::json::parse(text);
      EXPECT_EQ(j.at("provenance").at("git_revision"), io::git_revision()) << p;
    } else if (p.extension() == ".pvd") {
      EXPECT_NE(text.find("<!-- provenance: command: puncture run"), std::string::npos) << p;
    } else if (p.extension() == ".vtp") {
#ifdef PUNCTURE_HAVE_VTK
      if (checked > 40) continue;  // a sample of the frames is enough
      vtkNew<vtkXMLPolyDataReader> reader;
      reader->SetFileName(p.c_str());
      reader->Update();
      vtkFieldData* fd = reader->GetOutput()->GetFieldData();
      auto* command = vtkStringArray::SafeDownCast(fd->GetAbstractArray("provenance_command"));
      auto* unit = vtkStringArray::SafeDownCast(fd->GetAbstractArray("coordinate_unit"));
      ASSERT_NE(command, nullptr) << p;
      ASSERT_NE(unit, nullptr) << p;
      EXPECT_EQ(command->GetValue(0).rfind("puncture run", 0), 0u) << p;
      EXPECT_EQ(unit->GetValue(0), "m");
#endif
    } else {
      ADD_FAILURE() << "unexpected output file " << p;
    }
    ++checked;
  }
  EXPECT_GT(checked, 10u);
  fs::remove_all(dir);
}

TEST(ProgramContract, ImplausibleResultsAreWarnings) {
  nlohmann::json j = default_scene_json();
  j["layers"][0]["force_mesh"]["K_N_per_mm"] = 1e300;
  const fs::path scene = write_scene("k1e300", j);
  const fs::path dir = fresh("k1e300_out");
  RunOptions options;
  options.scene = scene;
  options.output_dir = dir;
  options.write_frames = false;
  options.quiet = true;
  std::ostringstream out, err;
  ASSERT_EQ(run_command(options, out, err), 0) << err.str();
  EXPECT_NE(err.str().find("warning: peak needle force"), std::string::npos) << err.str();
  EXPECT_NE(err.str().find("warning: layer 'skin' was not punctured"), std::string::npos) << err.str();
  std::ifstream in(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  ASSERT_GE(summary.at("warnings").size(), 2u);
  EXPECT_NE(summary["warnings"][0].get<std::string>().find("exceeds 50 N"), std::string::npos);
  fs::remove_all(dir);
  fs::remove(scene);

  // The default scene is plausible: no warnings.
  const fs::path ok_dir = fresh("plausible_out");
  options.scene = kSourceDir / "scenes" / "default.json";
  options.output_dir = ok_dir;
  std::ostringstream out2, err2;
  ASSERT_EQ(run_command(options, out2, err2), 0);
  EXPECT_EQ(err2.str(), "");
  std::ifstream in2(ok_dir / "summary.json");
  EXPECT_TRUE(nlohmann::json::parse(in2).at("warnings").empty());
  fs::remove_all(ok_dir);
}

TEST(ProgramContract, HugePerTickTablesAreDecimatedWithAWarning) {
  nlohmann::json j = default_scene_json();
  j["realtime"]["haptic_rate_Hz"] = 100000;  // 100 kHz over ~2.7 s: ~270 000 ticks
  j["realtime"]["integrator"] = "quasi_static";
  j["insertion"]["target_depth_mm"] = 12.0;
  j["insertion"]["dwell_s"] = 0.0;
  j["effects"] = {"surface_force", "damping", "resumption"};
  const fs::path scene = write_scene("decimate", j);
  const fs::path dir = fresh("decimate_out");
  RunOptions options;
  options.scene = scene;
  options.output_dir = dir;
  options.quiet = true;
  std::ostringstream out, err;
  ASSERT_EQ(run_command(options, out, err), 0) << err.str();
  EXPECT_NE(err.str().find("warning: realtime_curve.csv:"), std::string::npos) << err.str();
  std::ifstream in(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  const auto& curve = summary.at("realtime_curve");
  EXPECT_EQ(curve.at("decimation_stride").get<int>(), 2);
  EXPECT_LE(curve.at("rows").get<std::size_t>(), 200000u + 10u);
  const io::CsvDocument doc = io::read_csv_file(dir / "realtime_curve.csv");
  EXPECT_EQ(doc.records.size(), curve.at("rows").get<std::size_t>());
  ASSERT_NE(doc.metadata_value("decimation"), nullptr);
  // Every puncture event's tick is kept: the state columns change where the events are.
  const std::size_t skin = doc.require_column("skin_state");
  std::size_t punctured_rows = 0;
  for (const auto& r : doc.records) punctured_rows += r.fields[skin] == "punctured";
  EXPECT_GT(punctured_rows, 0u);
  fs::remove_all(dir);
  fs::remove(scene);
}

TEST(ProgramContract, InterruptedRunLeavesNothingBehind) {
  for (int sig : {SIGINT, SIGTERM}) {
    // A long run (60 s of dwell) that is interrupted while it writes frames.
    nlohmann::json j = default_scene_json();
    j["insertion"]["dwell_s"] = 60.0;
    j["realtime"]["frame_rate_Hz"] = 10.0;
    const fs::path scene = write_scene("interrupt", j);
    const fs::path dir = fresh("interrupt_out");
    const std::string dir_s = dir.string(), scene_s = scene.string();
    std::vector<char*> argv{const_cast<char*>(kProgram.c_str()), const_cast<char*>("run"),
                            const_cast<char*>(scene_s.c_str()), const_cast<char*>("-q"), const_cast<char*>("-o"),
                            const_cast<char*>(dir_s.c_str()), nullptr};
    pid_t child = 0;
    ASSERT_EQ(::posix_spawn(&child, kProgram.c_str(), nullptr, nullptr, argv.data(), environ), 0);
    // Wait until it has staged some frames.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (staging_files(dir).size() < 20 && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_GE(staging_files(dir).size(), 20u) << "the run did not stage files in time";
    ::kill(child, sig);
    int status = 0;
    ::waitpid(child, &status, 0);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "status " << status;
    EXPECT_TRUE(staging_files(dir).empty());
    EXPECT_FALSE(fs::exists(dir)) << "the run created the folder, so it removes it";
    fs::remove_all(dir);
    fs::remove(scene);
  }
}

TEST(ProgramContract, ANewRunRemovesStagedFilesOfADeadRun) {
  const fs::path dir = fresh("stale_out");
  fs::create_directories(dir / "frames");
  // A run killed with SIGKILL (no chance to clean up) leaves its staged files.
  nlohmann::json j = default_scene_json();
  j["insertion"]["dwell_s"] = 60.0;
  const fs::path scene = write_scene("killed", j);
  const std::string dir_s = dir.string(), scene_s = scene.string();
  std::vector<char*> argv{const_cast<char*>(kProgram.c_str()), const_cast<char*>("run"),
                          const_cast<char*>(scene_s.c_str()), const_cast<char*>("-q"), const_cast<char*>("-o"),
                          const_cast<char*>(dir_s.c_str()), nullptr};
  pid_t child = 0;
  ASSERT_EQ(::posix_spawn(&child, kProgram.c_str(), nullptr, nullptr, argv.data(), environ), 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (staging_files(dir).size() < 5 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_GE(staging_files(dir).size(), 5u);

  RunOptions options;
  options.scene = kSourceDir / "scenes" / "default.json";
  options.output_dir = dir;
  options.write_frames = false;
  options.quiet = true;
  std::ostringstream out, err;
  ASSERT_EQ(run_command(options, out, err), 0) << err.str();
  EXPECT_TRUE(staging_files(dir).empty());
  fs::remove_all(dir);
  fs::remove(scene);
}

}  // namespace
}  // namespace puncture::apps

namespace puncture::apps {
namespace {

/// A file's text with every run of white space made one space (READMEs wrap their lines anywhere).
std::string collapsed_text(const fs::path& path) {
  std::ifstream in(path);
  std::string text, word;
  while (in >> word) text += (text.empty() ? "" : " ") + word;
  return text;
}

TEST(DocumentedDefaults, CalibrationBoundFactorIsOneValueInTheCommandTheLibraryAndTheDocs) {
  // One default, declared once (validation::kDefaultCalibrationBoundFactor): the command's options, the
  // library's options, `calibrate --help`, apps/README.md and validation/calibration/README.md all say the same number.
  const double f = validation::kDefaultCalibrationBoundFactor;
  EXPECT_EQ(CalibrateOptions{}.bound_factor, f);
  EXPECT_EQ(validation::CalibrationOptions{}.bound_factor, f);
  std::ostringstream number;
  number << f;
  const Result help = run_program("calibrate --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("range); default " + number.str()), std::string::npos) << help.out;
  const std::string apps_readme = collapsed_text(kSourceDir / "apps" / "README.md");
  EXPECT_NE(apps_readme.find("F = " + number.str() + " by default"), std::string::npos) << "apps/README.md";
  const std::string calibration_readme = collapsed_text(kSourceDir / "validation" / "calibration" / "README.md");
  EXPECT_NE(calibration_readme.find("f = `CalibrationOptions::bound_factor`, " + number.str() + " by default"),
            std::string::npos)
      << "validation/calibration/README.md";
}

}  // namespace
}  // namespace puncture::apps

namespace puncture::apps {
namespace {

TEST(CommittedResults, DefaultRunWasMadeFromTheCurrentDefaultScene) {
  // results/default_run/summary.json records the scene it ran; when
  // scenes/default.json changes, the committed result is stale: rerun
  // `bash scripts/results_default_run.sh`.
  std::ifstream in(kSourceDir / "results" / "default_run" / "summary.json");
  ASSERT_TRUE(in) << "results/default_run/summary.json is missing";
  const nlohmann::json summary = nlohmann::json::parse(in);
  const Scene current = load_scene(kSourceDir / "scenes" / "default.json");
  const Scene recorded = parse_scene(summary.at("settings").dump(), "results/default_run/summary.json:/settings");
  EXPECT_EQ(scene_to_json_text(recorded), scene_to_json_text(current))
      << "results/default_run is stale: run bash scripts/results_default_run.sh";
  EXPECT_TRUE(summary.contains("provenance"));
  EXPECT_TRUE(summary.contains("warnings"));
}

}  // namespace
}  // namespace puncture::apps
