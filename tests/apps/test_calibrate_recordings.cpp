// `puncture calibrate` on several bench recordings at once (issue 49): raw
// recordings made from a KNOWN model (the real-time model with a skin whose
// critical force grows with the pressing speed, F_c (v / 10 mm/s)^0.3), at two
// speeds, with seeded sensor noise and an untared offset, each with its
// sidecar. One recording cannot identify the rate exponent n (it stays at its
// start, 0, and the report says why; the recording at the other speed, held
// out, shows the model's puncture force off); two recordings at two speeds
// recover n. A held-out repeat of one speed is judged in the same report, and
// the scatter of the repeats stands beside the model's error.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <functional>
#include <fstream>
#include <nlohmann/json.hpp>
#include <cmath>
#include <random>
#include <sstream>

#include "puncture/apps/commands.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/calibration.hpp"
#include "puncture/validation/fem_reference_curve.hpp"

namespace fs = std::filesystem;
namespace pv = puncture::validation;

namespace puncture::apps {
namespace {

constexpr double kTrueExponent = 0.3;

/// Skin (critical force 2 N at 10 mm/s, rate exponent 0.3) on a fat layer that
/// does not break within the 6 mm insertion; quasi-static mesh, low SH degree.
Scene truth_scene() {
  Scene s = parse_scene(R"({
    "schema_version": 1, "name": "rate_truth",
    "sample": { "diameter_mm": 60.0 },
    "needle": { "radius_mm": 0.635, "tip": "blunt" },
    "layers": [
      { "name": "skin", "thickness_mm": 0.8, "density_kg_per_m3": 1100,
        "force_mesh": { "K_N_per_mm": 0.16, "w": 8, "L_mm": 2.0, "surface_stiffness_N_per_mm": 0.2,
                        "deformed_threshold_mm": 0.01, "node_damping_N_s_per_m": 0.05 },
        "damping_d_N_s_per_m2": 3000, "resumption_rate": 0.05,
        "force_law": { "breakthrough": { "criterion": "critical_force", "critical_force_N": 2.0,
                                         "rate_exponent": 0.3, "reference_speed_mm_per_s": 10.0 } },
        "material": { "model": "neo_hookean", "youngs_modulus_kPa": 35.0, "poisson_ratio": 0.48 } },
      { "name": "fat", "thickness_mm": 20.0, "density_kg_per_m3": 920,
        "force_mesh": { "K_N_per_mm": 0.08, "w": 4, "L_mm": 1.0, "surface_stiffness_N_per_mm": 0.05,
                        "deformed_threshold_mm": 0.15, "node_damping_N_s_per_m": 0.05 },
        "damping_d_N_s_per_m2": 1000, "resumption_rate": 0.05,
        "force_law": { "breakthrough": { "criterion": "critical_force", "critical_force_N": 40.0 } },
        "material": { "model": "neo_hookean", "youngs_modulus_kPa": 2.0, "poisson_ratio": 0.48 } }
    ],
    "insertion": { "start_height_mm": 3.0, "speed_mm_per_s": 10.0, "target_depth_mm": 6.0,
                   "dwell_s": 0.0, "withdrawal_speed_mm_per_s": 50.0, "angle_deg": 0.0 },
    "realtime": { "sh_degree": 8, "haptic_rate_Hz": 5000, "integrator": "quasi_static", "frame_rate_Hz": 10 },
    "effects": ["surface_force", "damping", "resumption"]
  })", "rate_truth");
  return s;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("puncture_cmd_recordings_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string text_of(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The truth inserted at `speed_mm_per_s`, written as a rig writes it: 200 Hz,
/// time (s), stage position (mm, 30 mm at the surface, growing into the
/// tissue), force with a 0.3 N offset and Gaussian noise of `noise_N` (seeded);
/// its sidecar <stem>.json beside it. sample_scale != 1: a repeat on another
/// sample (the skin's K and critical force times it).
fs::path write_recording(const fs::path& dir, const std::string& stem, double speed_mm_per_s, unsigned seed,
                         double sample_scale = 1.0, double noise_N = 0.01, double angle_deg = 0.0) {
  Scene truth = truth_scene();
  // At an angle the stage drives the needle along its axis: its travel is the depth along the needle.
  truth.insertion.angle_deg = angle_deg;
  const double cos_a = std::cos(angle_deg * M_PI / 180.0);
  // Another sample of the tissue: the skin's K and critical force scaled.
  truth.layers[0].force_mesh.virtual_stiffness_N_per_m *= sample_scale;
  truth.layers[0].force_law.breakthrough.critical_force_N *= sample_scale;
  const pv::InsertionCurve c = pv::simulate_insertion_curve(pv::scene_at_insertion_speed(truth, speed_mm_per_s * 1e-3));
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_N);
  std::ofstream csv(dir / (stem + ".csv"));
  csv << "# synthetic bench recording of the test's truth model at " << speed_mm_per_s << " mm/s\nt_s,stage_mm,F_N\n";
  double next = 0.0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (c.time_s[i] + 1e-12 < next) continue;
    csv << c.time_s[i] << ',' << 30.0 + c.depth_m[i] / cos_a * 1e3 << ',' << 0.3 + c.force_N[i] + noise(rng) << '\n';
    next += 0.005;
  }
  std::ofstream(dir / (stem + ".json")) << R"({"time": {"column": "t_s", "unit": "s"},
    "position": {"column": "stage_mm", "unit": "mm", "into_tissue": "increasing"},
    "force": {"column": "F_N", "unit": "N", "sign": 1}})";
  return dir / (stem + ".csv");
}

/// The start: the truth with n = 0, d 30 % low and F_c 20 % low, as a scene file.
fs::path write_start_scene(const fs::path& dir) {
  Scene start = truth_scene();
  start.layers[0].force_law.breakthrough.rate_exponent = 0.0;
  start.layers[0].damping_N_s_per_m2 *= 0.7;
  start.layers[0].force_law.breakthrough.critical_force_N = 1.6;
  std::ofstream(dir / "start.json") << scene_to_json_text(start);
  return dir / "start.json";
}

CalibrateOptions skin_options(const fs::path& scene, const fs::path& out) {
  CalibrateOptions o;
  o.scene = scene;
  o.output_dir = out;
  o.layers = {"skin"};
  // The skin's K kept: its critical force at v_ref (F_c), d and n are tuned.
  o.keep = {"K"};
  o.quiet = true;
  return o;
}

const nlohmann::json* parameter(const nlohmann::json& identifiability, const std::string& name) {
  for (const nlohmann::json& p : identifiability.at("parameters"))
    if (p.at("layer") == "skin" && p.at("parameter") == name) return &p;
  return nullptr;
}

}  // namespace

TEST(CalibrateRecordings, TwoSpeedsIdentifyTheRateExponentThatOneLeavesUnidentified) {
  const fs::path work = fresh_dir("rate");
  const fs::path fast = write_recording(work, "fast", 10.0, 11);
  const fs::path slow = write_recording(work, "slow", 4.0, 12);
  const fs::path stiffer = write_recording(work, "fast_stiffer_sample", 10.0, 13, 1.08);
  const fs::path softer = write_recording(work, "fast_softer_sample", 10.0, 14, 0.92);
  const fs::path scene = write_start_scene(work);
  std::ostringstream out, err;

  // One recording (10 mm/s), the 4 mm/s one held out: n stays at 0, and the report says why.
  CalibrateOptions one = skin_options(scene, work / "one");
  one.references = {fast};
  one.held_out = {slow};
  ASSERT_EQ(calibrate_command(one, out, err), 0) << err.str();
  const nlohmann::json prov1 = nlohmann::json::parse(text_of(work / "one" / "rate_truth_tuned.provenance.json"));
  const nlohmann::json* n1 = parameter(prov1.at("identifiability"), "breakthrough_rate_exponent");
  ASSERT_NE(n1, nullptr);
  EXPECT_EQ(n1->at("value").get<double>(), 0.0);
  EXPECT_EQ(n1->at("status"), "not identifiable");
  EXPECT_NE(n1->at("reason").get<std::string>().find("one speed"), std::string::npos) << n1->dump();
  const std::string md1 = text_of(work / "one" / "calibration_summary.md");
  EXPECT_NE(md1.find("| " + slow.string() + " | **held out** | 4 |"), std::string::npos) << md1;

  // Both speeds fitted, two repeats of 10 mm/s on other samples held out: n recovered.
  CalibrateOptions two = skin_options(scene, work / "two");
  two.references = {fast, slow};
  two.held_out = {stiffer, softer};
  ASSERT_EQ(calibrate_command(two, out, err), 0) << err.str();
  const nlohmann::json prov2 = nlohmann::json::parse(text_of(work / "two" / "rate_truth_tuned.provenance.json"));
  const nlohmann::json* n2 = parameter(prov2.at("identifiability"), "breakthrough_rate_exponent");
  ASSERT_NE(n2, nullptr);
  EXPECT_NEAR(n2->at("value").get<double>(), kTrueExponent, 0.05);
  EXPECT_EQ(n2->at("status"), "identified");
  const Scene tuned = load_scene(work / "two" / "rate_truth_tuned.json");
  EXPECT_NEAR(tuned.layers[0].force_law.breakthrough.rate_exponent, kTrueExponent, 0.05);
  EXPECT_NEAR(tuned.layers[0].force_law.breakthrough.critical_force_N, 2.0, 0.1);

  // The report: the held-out repeats judged, and the scatter of the three
  // 10 mm/s recordings (punctures 0.92-1.08 x 2 N) beside the model, which
  // lies between them.
  const std::string md2 = text_of(work / "two" / "calibration_summary.md");
  EXPECT_NE(md2.find("| " + stiffer.string() + " | **held out** | 10 |"), std::string::npos) << md2;
  EXPECT_NE(md2.find("| " + softer.string() + " | **held out** | 10 |"), std::string::npos) << md2;
  EXPECT_NE(md2.find("## Scatter of repeats"), std::string::npos);
  EXPECT_NE(md2.find("### 4 mm/s: 1 recording(s)"), std::string::npos) << md2;
  const std::size_t group = md2.find("### 10 mm/s: 3 recording(s)");
  ASSERT_NE(group, std::string::npos) << md2;
  EXPECT_NE(md2.find("| skin (3 of 3) |", group), std::string::npos) << md2;
  EXPECT_NE(md2.find("| yes |", group), std::string::npos) << md2;  // the model's puncture force within the repeats'
  EXPECT_NE(md2.find("it sits inside the scatter.", group), std::string::npos) << md2;
  EXPECT_NE(text_of(work / "two" / "repeat_scatter.csv").find("group,speed_mm_per_s,depth_mm"), std::string::npos);
  if (!::testing::Test::HasFailure()) fs::remove_all(work);
}

TEST(CalibrateRecordings, ARecordingWithoutSpeedOrFittedAndHeldOutIsBadInputWithNoOutput) {
  const fs::path work = fresh_dir("bad");
  const fs::path fast = write_recording(work, "fast", 10.0, 11);
  std::ofstream(work / "curve.csv") << "depth_mm,force_N\n0,0\n1,0.5\n2,1.0\n3,0.2\n";
  const fs::path scene = write_start_scene(work);
  std::ostringstream out, err;
  CalibrateOptions o = skin_options(scene, work / "out");
  o.references = {fast, work / "curve.csv"};
  EXPECT_EQ(calibrate_command(o, out, err), 2);
  EXPECT_NE(err.str().find((work / "curve.csv").string() + ": no insertion speed"), std::string::npos) << err.str();
  EXPECT_FALSE(fs::exists(work / "out"));
  o.references = {fast};
  o.held_out = {fast};
  err.str("");
  EXPECT_EQ(calibrate_command(o, out, err), 2);
  EXPECT_NE(err.str().find("is also a --reference"), std::string::npos) << err.str();
  EXPECT_FALSE(fs::exists(work / "out"));
  fs::remove_all(work);
}

// `puncture validate --reference`: the scene's model judged against the same
// kind of recordings without fitting. The truth follows its own recordings
// (force RMSE within the noise, the skin's puncture where the recording's
// drop is); the start model (n = 0, F_c 20 % low) misses the puncture force
// by about its error; two recordings of one speed give the scatter section.
nlohmann::json recording_entry(const nlohmann::json& report, const fs::path& path) {
  for (const nlohmann::json& r : report.at("recordings"))
    if (r.at("recording") == path.string()) return r;
  ADD_FAILURE() << "no entry for " << path;
  return nlohmann::json::object();
}

TEST(ValidateRecordings, TheTruthFollowsItsRecordingsAndTheStartModelMissesItsPunctureForce) {
  const fs::path work = fresh_dir("validate");
  const fs::path fast = write_recording(work, "fast", 10.0, 21);
  const fs::path slow = write_recording(work, "slow", 4.0, 22);
  const fs::path repeat = write_recording(work, "fast_stiffer_sample", 10.0, 23, 1.08);
  std::ofstream(work / "truth.json") << scene_to_json_text(truth_scene());
  const fs::path start = write_start_scene(work);
  std::ostringstream out, err;

  ValidateOptions truth;
  truth.scene = work / "truth.json";
  truth.output_dir = work / "truth_report";
  truth.references = {fast, slow, repeat};
  truth.quiet = true;
  ASSERT_EQ(validate_command(truth, out, err), 0) << err.str();
  const nlohmann::json report = nlohmann::json::parse(text_of(work / "truth_report" / "recordings_validation.json"));
  for (const fs::path& own : {fast, slow}) {
    const nlohmann::json r = recording_entry(report, own);
    EXPECT_LT(r.at("force_rmse_relative").get<double>(), 0.03) << r.dump();  // noise 0.01 N on a 2 N peak
    const nlohmann::json& skin = r.at("layers").at(0);
    ASSERT_TRUE(skin.at("recording_punctured").get<bool>() && skin.at("model_punctured").get<bool>()) << r.dump();
    EXPECT_NEAR(skin.at("model").at("depth_mm").get<double>(), skin.at("recording").at("depth_mm").get<double>(), 0.1);
    EXPECT_NEAR(skin.at("model").at("force_N").get<double>() / skin.at("recording").at("force_N").get<double>(), 1.0,
                0.05) << r.dump();
  }
  ASSERT_EQ(report.at("repeat_scatter").size(), 1u) << report.dump();  // the two 10 mm/s recordings
  EXPECT_EQ(report.at("repeat_scatter").at(0).at("recordings"), 2);
  const std::string md = text_of(work / "truth_report" / "recordings_validation.md");
  EXPECT_NE(md.find("## Scatter of repeats"), std::string::npos) << md;
  EXPECT_NE(md.find("beside the scene's model's"), std::string::npos) << md;
  EXPECT_TRUE(fs::exists(work / "truth_report" / "recording_curves.csv"));
  EXPECT_TRUE(fs::exists(work / "truth_report" / "repeat_scatter.csv"));

  ValidateOptions off = truth;
  off.scene = start;
  off.output_dir = work / "start_report";
  off.references = {slow};
  ASSERT_EQ(validate_command(off, out, err), 0) << err.str();
  const nlohmann::json off_report = nlohmann::json::parse(text_of(work / "start_report" / "recordings_validation.json"));
  const nlohmann::json skin = recording_entry(off_report, slow).at("layers").at(0);
  ASSERT_TRUE(skin.at("model_punctured").get<bool>()) << skin.dump();
  // n = 0, F_c 20 % low and d 30 % low: at 4 mm/s its puncture force is off by
  // more than the 5 % the truth meets, and its curve by more than the truth's.
  const double ratio = skin.at("model").at("force_N").get<double>() / skin.at("recording").at("force_N").get<double>();
  EXPECT_GT(std::abs(ratio - 1.0), 0.05) << skin.dump();
  EXPECT_GT(recording_entry(off_report, slow).at("force_rmse_relative").get<double>(),
            recording_entry(report, slow).at("force_rmse_relative").get<double>());
  if (!::testing::Test::HasFailure()) fs::remove_all(work);
}

TEST(ValidateRecordings, AMissingRecordingOrAFemOptionIsBadInputWithNoOutput) {
  const fs::path work = fresh_dir("validate_bad");
  const fs::path scene = write_start_scene(work);
  std::ostringstream out, err;
  ValidateOptions o;
  o.scene = scene;
  o.output_dir = work / "out";
  o.references = {work / "no_such_recording.csv"};
  o.quiet = true;
  EXPECT_EQ(validate_command(o, out, err), 2);
  EXPECT_NE(err.str().find((work / "no_such_recording.csv").string()), std::string::npos) << err.str();
  o.references = {write_recording(work, "fast", 10.0, 11)};
  o.refinement = 1;
  err.str("");
  EXPECT_EQ(validate_command(o, out, err), 2);
  EXPECT_NE(err.str().find("--refinement"), std::string::npos) << err.str();
  EXPECT_FALSE(fs::exists(work / "out"));
  fs::remove_all(work);
}


// A bench recording of an inclined insertion (30 deg to the surface normal):
// the stage's travel is the depth along the needle and the load cell reads the
// force along it. The truth scene at 30 deg follows its recording (force RMSE
// within the noise, the skin's puncture at the recording's depth); the same
// truth at 0 deg, which presses the surface 1 / cos 30 as hard per mm of
// travel and feels all of it along the needle, does not. Calibrating the
// start model (F_c 20 % low) at 30 deg on the recording recovers F_c.
TEST(ObliqueRecordings, TheInclinedTruthFollowsItsRecordingAndCalibrationRecoversTheCriticalForce) {
  const fs::path work = fresh_dir("oblique");
  const fs::path rec = write_recording(work, "oblique_30deg", 10.0, 31, 1.0, 0.01, 30.0);
  Scene truth = truth_scene();
  truth.insertion.angle_deg = 30.0;
  std::ofstream(work / "truth_30.json") << scene_to_json_text(truth);
  std::ofstream(work / "truth_0.json") << scene_to_json_text(truth_scene());
  std::ostringstream out, err;

  auto judged = [&](const fs::path& scene, const std::string& name) {
    ValidateOptions v;
    v.scene = scene;
    v.output_dir = work / name;
    v.references = {rec};
    v.quiet = true;
    EXPECT_EQ(validate_command(v, out, err), 0) << err.str();
    return recording_entry(nlohmann::json::parse(text_of(work / name / "recordings_validation.json")), rec);
  };
  const nlohmann::json at_angle = judged(work / "truth_30.json", "report_30");
  EXPECT_LT(at_angle.at("force_rmse_relative").get<double>(), 0.03) << at_angle.dump();
  const nlohmann::json& skin = at_angle.at("layers").at(0);
  ASSERT_TRUE(skin.at("recording_punctured").get<bool>() && skin.at("model_punctured").get<bool>()) << at_angle.dump();
  EXPECT_NEAR(skin.at("model").at("depth_mm").get<double>(), skin.at("recording").at("depth_mm").get<double>(), 0.1);
  EXPECT_NEAR(skin.at("model").at("force_N").get<double>() / skin.at("recording").at("force_N").get<double>(), 1.0,
              0.05);
  const nlohmann::json axial = judged(work / "truth_0.json", "report_0");
  EXPECT_GT(axial.at("force_rmse_relative").get<double>(), 3.0 * at_angle.at("force_rmse_relative").get<double>())
      << axial.dump();

  Scene start = truth;
  start.layers[0].force_law.breakthrough.critical_force_N = 1.6;
  std::ofstream(work / "start_30.json") << scene_to_json_text(start);
  CalibrateOptions o = skin_options(work / "start_30.json", work / "calibrated");
  o.references = {rec};
  ASSERT_EQ(calibrate_command(o, out, err), 0) << err.str();
  const Scene tuned = load_scene(work / "calibrated" / "rate_truth_tuned.json");
  EXPECT_EQ(tuned.insertion.angle_deg, 30.0);
  EXPECT_NEAR(tuned.layers[0].force_law.breakthrough.critical_force_N, 2.0, 0.06);
  if (!::testing::Test::HasFailure()) fs::remove_all(work);
}

}  // namespace puncture::apps

namespace puncture::apps {

// The axisymmetric FEM reference, the comparison models and the comparisons
// against the FEM insert along the sample axis only; the 3D reference (a blunt
// tip) takes an angle while its mesh can follow the path. Every command that
// cannot run a scene refuses it before any FEM run, naming the field, with
// exit code 2 and no output.
TEST(ObliqueRecordings, TheFemCommandsRefuseAnInclinedSceneNamingTheField) {
  const fs::path work = fresh_dir("oblique_fem");
  Scene scene = truth_scene();  // a blunt tip: the 3D reference
  scene.insertion.angle_deg = 30.0;
  const fs::path path = work / "inclined.json";
  std::ofstream(path) << scene_to_json_text(scene);
  auto refused_scene = [&](const fs::path& scene_path, const char* what, const std::string& because,
                           const std::function<int(std::ostream&, std::ostream&)>& command) {
    std::ostringstream out, err;
    EXPECT_EQ(command(out, err), 2) << what;
    EXPECT_NE(err.str().find(scene_path.string() + ": /insertion/angle_deg: "), std::string::npos)
        << what << ": " << err.str();
    EXPECT_NE(err.str().find(because), std::string::npos) << what << ": " << err.str();
    EXPECT_FALSE(fs::exists(work / "out")) << what;
  };
  auto refused = [&](const char* what, const std::function<int(std::ostream&, std::ostream&)>& command) {
    refused_scene(path, what, "30 deg", command);
  };
  auto fem_on = [&](const fs::path& scene_path) {
    return [&work, scene_path](std::ostream& out, std::ostream& err) {
      FemOptions o;
      o.scene = scene_path;
      o.output_dir = work / "out";
      return fem_command(o, out, err);
    };
  };
  // `fem`: a bevel tip (the axisymmetric reference) at an angle, and a blunt one too steep for its mesh.
  Scene bevel = scene;
  bevel.needle.tip = "bevel";
  bevel.needle.tip_angle_deg = 12.0;
  const fs::path bevel_path = work / "inclined_bevel.json";
  std::ofstream(bevel_path) << scene_to_json_text(bevel);
  refused_scene(bevel_path, "fem, bevel", "axisymmetric FEM reference", fem_on(bevel_path));
  Scene steep = scene;
  steep.insertion.angle_deg = 45.0;
  steep.insertion.target_depth_m = 0.020;  // 20 mm off the axis of the 30 mm radius: in the sample, but the mesh would fold
  const fs::path steep_path = work / "inclined_steep.json";
  std::ofstream(steep_path) << scene_to_json_text(steep);
  refused_scene(steep_path, "fem, steep", "widen /sample/diameter_mm", fem_on(steep_path));
  refused("validate", [&](std::ostream& out, std::ostream& err) {
    ValidateOptions o;
    o.scene = path;
    o.output_dir = work / "out";
    return validate_command(o, out, err);
  });
  refused("calibrate", [&](std::ostream& out, std::ostream& err) {
    CalibrateOptions o = skin_options(path, work / "out");
    return calibrate_command(o, out, err);
  });
  refused("compare", [&](std::ostream& out, std::ostream& err) {
    CompareOptions o;
    o.scene = path;
    o.output_dir = work / "out";
    return compare_command(o, out, err);
  });
  if (!::testing::Test::HasFailure()) fs::remove_all(work);
}

// `puncture fem` on the blunt scene at 30 deg: the 3D reference runs the
// first 0.2 mm and writes the inclined needle's columns.
TEST(ObliqueRecordings, TheFemCommandRunsTheBluntNeedleAtAnAngle) {
  const fs::path work = fresh_dir("oblique_fem_run");
  Scene scene = truth_scene();
  scene.insertion.angle_deg = 30.0;
  scene.insertion.start_height_m = 0.5e-3;
  const fs::path path = work / "inclined.json";
  std::ofstream(path) << scene_to_json_text(scene);
  FemOptions o;
  o.scene = path;
  o.output_dir = work / "out";
  o.write_vtu = false;
  o.stop_depth_mm = 0.2;
  o.quiet = true;
  std::ostringstream out, err;
  ASSERT_EQ(fem_command(o, out, err), 0) << err.str();
  std::ifstream csv(work / "out" / "fem_force_depth.csv");
  std::string line, header;
  double last_depth = 0.0, last_path = 0.0, last_force = 0.0;
  while (std::getline(csv, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header.empty()) {
      header = line;
      continue;
    }
    std::stringstream fields(line);
    std::vector<double> v;
    for (std::string f; std::getline(fields, f, ',') && v.size() < 7;) v.push_back(std::stod(f));
    last_depth = v[1], last_force = v[3], last_path = v[5];
  }
  EXPECT_EQ(header.rfind("time_s,depth_mm,velocity_mm_per_s,force_N,tip_stretch,path_depth_mm,lateral_force_N", 0), 0u)
      << header;
  EXPECT_NEAR(last_depth, 0.2, 1e-9);
  EXPECT_NEAR(last_path, 0.2 / std::cos(30.0 * M_PI / 180.0), 1e-8);
  EXPECT_GT(last_force, 0.0);
  if (!::testing::Test::HasFailure()) fs::remove_all(work);
}

}  // namespace puncture::apps
