// `puncture calibrate --reference` on a raw rig recording (time, stage
// position, force; validation/harness recording.hpp): the shared rig-like
// recording calibrates with no hand-entered depth (its skin puncture detected
// within 0.1 mm of 14.74 mm from contact), and a recording or format that
// cannot be read is bad input (exit 2, the file and the field named, nothing
// written).
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "puncture/apps/commands.hpp"

namespace fs = std::filesystem;

namespace puncture::apps {
namespace {

const fs::path kSourceDir = PUNCTURE_SOURCE_DIR;
const fs::path kSharedData = PUNCTURE_SHARED_DATA_DIR;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("puncture_cmd_raw_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

CalibrateOptions phantom_options(const fs::path& reference, const fs::path& out) {
  CalibrateOptions o;
  o.scene = kSourceDir / "scenes" / "skin_on_muscle_phantom.json";
  if (!reference.empty()) o.references = {reference};
  o.output_dir = out;
  o.quiet = true;
  return o;
}

std::string text_of(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(CalibrateRawRecording, SharedRigRecordingCalibratesWithNoHandEnteredDepth) {
  const fs::path rig = kSharedData / "rig_like_recording.csv";
  ASSERT_TRUE(fs::exists(rig)) << rig << " is missing: the tests need shared/data beside the repository clone";
  const fs::path dir = fresh_dir("rig");
  CalibrateOptions o = phantom_options(rig, dir);
  o.recording.format_file = kSourceDir / "validation" / "cases" / "rig_like_recording_format.json";
  // Only the skin's critical force and cutting force: the detection is what is tested here.
  o.layers = {"skin"};
  o.keep = {"K", "stiffening", "friction"};
  std::ostringstream out, err;
  ASSERT_EQ(calibrate_command(o, out, err), 0) << err.str();
  const std::string name = "skin_on_muscle_phantom_tuned";
  const nlohmann::json prov = nlohmann::json::parse(text_of(dir / (name + ".provenance.json")));
  const nlohmann::json& ref = prov.at("references").at(0);
  const nlohmann::json& punctures = ref.at("reference_punctures");
  EXPECT_EQ(punctures.at("source"), "force drops");
  EXPECT_TRUE(punctures.at("doubts").empty());
  EXPECT_EQ(punctures.at("contact_onset_mm"), 0.0);  // the raw recording's contact fit
  ASSERT_TRUE(punctures.at("punctures").at(0).at("found").get<bool>());
  EXPECT_NEAR(punctures.at("punctures").at(0).at("depth_mm").get<double>(), 14.74, 0.1);
  EXPECT_NEAR(std::stod(ref.at("metadata").at("tare_N").get<std::string>()), 0.31, 0.01);
  EXPECT_NEAR(ref.at("trajectory").at("speed_mm_per_s").get<double>(), 2.0, 1e-6);
  // The command that reproduces it names the format; the detection is plotted.
  EXPECT_NE(text_of(dir / "calibration_curves.csv").find("--recording-format " + o.recording.format_file.string()),
            std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "reference_detection.png"));
  fs::remove_all(dir);
}

TEST(CalibrateRawRecording, BadFormatOrRecordingIsExitTwoNamingTheFileAndFieldWithNoOutput) {
  const fs::path work = fresh_dir("bad");
  const fs::path dir = work / "out";
  fs::create_directories(work);
  std::ofstream(work / "bench.csv") << "t_us,stage_mm,Fz_N\n0,10,0.3\n10000,10,0.3\n20000,10,0.3\n";
  // The sidecar beside it leaves out the stage's direction.
  std::ofstream(work / "bench.json") << R"({"time": {"column": "t_us"}, "position": {"column": "stage_mm"},
    "force": {"column": "Fz_N", "sign": 1}})";
  std::ostringstream out, err;
  EXPECT_EQ(calibrate_command(phantom_options(work / "bench.csv", dir), out, err), 2);
  EXPECT_NE(err.str().find((work / "bench.json").string() + ": field 'position.into_tissue': missing"), std::string::npos)
      << err.str();
  EXPECT_FALSE(fs::exists(dir));
  // The command line fixes the field; the stage does not move.
  CalibrateOptions o = phantom_options(work / "bench.csv", dir);
  o.recording.overrides.into_tissue = validation::StageDirection::Increasing;
  o.recording.overrides.source = "the command line";
  err.str("");
  EXPECT_EQ(calibrate_command(o, out, err), 2);
  EXPECT_NE(err.str().find((work / "bench.csv").string() + ": the stage does not move"), std::string::npos) << err.str();
  EXPECT_FALSE(fs::exists(dir));
  // A format without a recording.
  o = phantom_options("", dir);
  o.recording.format_file = work / "bench.json";
  err.str("");
  EXPECT_EQ(calibrate_command(o, out, err), 2);
  EXPECT_NE(err.str().find("--recording-format"), std::string::npos) << err.str();
  EXPECT_FALSE(fs::exists(dir));
  fs::remove_all(work);
}

}  // namespace puncture::apps
