// `puncture run` end to end: outputs of the default scene, and bad input that
// is reported with file and JSON path, a non-zero exit and no files left.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "csv_header.hpp"
#include "puncture/apps/commands.hpp"

namespace fs = std::filesystem;

namespace puncture::apps {
namespace {

const fs::path kSourceDir = PUNCTURE_SOURCE_DIR;
const fs::path kProgram = fs::path(PUNCTURE_BINARY_DIR) / "apps" / "puncture";

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("puncture_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

std::size_t count_files(const fs::path& dir) {
  if (!fs::exists(dir)) return 0;
  std::size_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) ++n;
  return n;
}

TEST(RunCommand, DefaultSceneWritesCurveSummaryAndFrames) {
  const fs::path dir = fresh_dir("default");
  RunOptions options;
  options.scene = kSourceDir / "scenes" / "default.json";
  options.output_dir = dir;
  options.quiet = false;
  std::ostringstream out, err;
  ASSERT_EQ(run_command(options, out, err), 0) << err.str();

  // Summary: three punctures in the order skin, fat, muscle, at increasing depth.
  std::ifstream in(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  const auto& events = summary.at("puncture_events");
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].at("layer"), "skin");
  EXPECT_EQ(events[1].at("layer"), "fat");
  EXPECT_EQ(events[2].at("layer"), "muscle");
  EXPECT_LT(events[0].at("depth_mm").get<double>(), events[1].at("depth_mm").get<double>());
  EXPECT_LT(events[1].at("depth_mm").get<double>(), events[2].at("depth_mm").get<double>());
  EXPECT_TRUE(summary.at("provenance").contains("machine"));
  // The printed report names the events and the output directory.
  EXPECT_NE(out.str().find("muscle"), std::string::npos);
  EXPECT_NE(out.str().find(dir.string()), std::string::npos);

  // Curve CSV: header with per-layer columns and one row per tick.
  std::ifstream csv(dir / "realtime_curve.csv");
  const std::string header = test::header_after_provenance(csv);
  EXPECT_EQ(header.rfind("time_s,depth_mm,velocity_mm_per_s,force_N,tip_force_N,cutting_force_N,friction_force_N,"
                         "phase,path_depth_mm,lateral_force_N,force_x_N,force_y_N,force_z_N,torque_x_N_m,torque_y_N_m,"
                         "torque_z_N_m,skin_state,",
                         0),
            0u)
      << header;
  std::size_t rows = 0;
  for (std::string line; std::getline(csv, line);) ++rows;
  const auto& timing = summary.at("tick_timing_us");
  EXPECT_EQ(rows, timing.at("ticks").get<std::size_t>());
  // The cost where the work is: ticks with contact, mean and p99.
  EXPECT_GT(timing.at("contact_ticks").get<std::size_t>(), rows / 2);
  EXPECT_LT(timing.at("contact_ticks").get<std::size_t>(), rows);
  EXPECT_GT(timing.at("contact_mean").get<double>(), 0.0);
  EXPECT_GE(timing.at("contact_p99").get<double>(), timing.at("all_median").get<double>());

  EXPECT_TRUE(fs::exists(dir / "sh_fit_error.csv"));
  EXPECT_TRUE(fs::exists(dir / "realtime.pvd"));
  EXPECT_TRUE(fs::exists(dir / "frames" / "skin_surface_0000.vtp"));
  EXPECT_TRUE(fs::exists(dir / "frames" / "muscle_force_mesh_0000.vtp"));
  // No staging leftovers.
  for (const auto& e : fs::recursive_directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".staging"), std::string::npos) << e.path();
  fs::remove_all(dir);
}

TEST(RunCommand, BadSceneNamesFileAndPathAndLeavesNothing) {
  const fs::path dir = fresh_dir("bad");
  const fs::path scene = fs::temp_directory_path() / ("puncture_bad_scene_" + std::to_string(::getpid()) + ".json");
  {
    std::ifstream in(kSourceDir / "scenes" / "default.json");
    nlohmann::json j = nlohmann::json::parse(in);
    j["layers"][1]["thickness_mm"] = -1.0;
    std::ofstream(scene) << j.dump(2);
  }
  RunOptions options;
  options.scene = scene;
  options.output_dir = dir;
  options.quiet = true;
  std::ostringstream out, err;
  EXPECT_NE(run_command(options, out, err), 0);
  EXPECT_NE(err.str().find(scene.string()), std::string::npos) << err.str();
  EXPECT_NE(err.str().find("/layers/1/thickness_mm"), std::string::npos) << err.str();
  EXPECT_EQ(count_files(dir), 0u);
  fs::remove(scene);
}

TEST(RunCommand, UnwritableOutputFailsCleanly) {
  // The output "directory" is an existing regular file.
  const fs::path file = fs::temp_directory_path() / ("puncture_not_a_dir_" + std::to_string(::getpid()));
  std::ofstream(file) << "x";
  RunOptions options;
  options.scene = kSourceDir / "scenes" / "default.json";
  options.output_dir = file;
  options.quiet = true;
  std::ostringstream out, err;
  EXPECT_NE(run_command(options, out, err), 0);
  EXPECT_FALSE(err.str().empty());
  EXPECT_TRUE(fs::is_regular_file(file));
  fs::remove(file);
}

TEST(PunctureProgram, ExitCodesOfTheExecutable) {
  ASSERT_TRUE(fs::exists(kProgram)) << kProgram;
  const std::string quiet = " > /dev/null 2>&1";
  EXPECT_EQ(std::system((kProgram.string() + " --help" + quiet).c_str()), 0);
  EXPECT_NE(std::system((kProgram.string() + " run /nonexistent/scene.json" + quiet).c_str()), 0);
  EXPECT_NE(std::system((kProgram.string() + " frobnicate" + quiet).c_str()), 0);
  // Malformed JSON: non-zero exit, message on stderr naming the file.
  const fs::path scene = fs::temp_directory_path() / ("puncture_malformed_" + std::to_string(::getpid()) + ".json");
  std::ofstream(scene) << "{ \"schema_version\": 1, ";
  const fs::path log = scene.string() + ".log";
  EXPECT_NE(std::system((kProgram.string() + " run " + scene.string() + " -o " + (scene.string() + ".out") + " 2> " +
                         log.string()).c_str()),
            0);
  std::ifstream in(log);
  const std::string message((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(message.find(scene.string()), std::string::npos) << message;
  EXPECT_NE(message.find("malformed JSON"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(scene.string() + ".out") && count_files(scene.string() + ".out") > 0);
  fs::remove(scene);
  fs::remove(log);
}

}  // namespace
}  // namespace puncture::apps
