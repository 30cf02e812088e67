// `puncture calibrate` against a measured-style reference curve, and
// `puncture grade` on a scores file: outputs, the preset round trip through
// `puncture run`, and bad input.
#include <gtest/gtest.h>

#include <set>

#include <filesystem>
#include <fstream>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "csv_header.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/scene_io.hpp"

namespace fs = std::filesystem;

namespace puncture::apps {
namespace {

const fs::path kSourceDir = PUNCTURE_SOURCE_DIR;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("puncture_cmd_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

TEST(CalibrateCommand, RecoversSkinStiffnessFromAReferenceCurveAndWritesARunnablePreset) {
  const fs::path work = fresh_dir("calibrate");
  fs::create_directories(work);
  // The "measured" reference: the default scene with the skin's K raised by 25 %.
  Scene truth = load_scene(kSourceDir / "scenes" / "default.json");
  const double true_K = 1.25 * truth.layers[0].force_mesh.virtual_stiffness_N_per_m;
  truth.layers[0].force_mesh.virtual_stiffness_N_per_m = true_K;
  truth.name = "truth";
  std::ofstream(work / "truth.json") << scene_to_json_text(truth);
  RunOptions run;
  run.scene = work / "truth.json";
  run.output_dir = work / "truth_run";
  run.write_frames = false;
  run.quiet = true;
  std::ostringstream out, err;
  ASSERT_EQ(run_command(run, out, err), 0) << err.str();

  CalibrateOptions options;
  options.scene = kSourceDir / "scenes" / "default.json";
  options.references = {work / "truth_run" / "realtime_curve.csv"};
  options.output_dir = work / "calibration";
  options.layers = {"skin"};
  options.integrator = "quasi_static";  // the fast runs (the scene's implicit one is the default)
  options.quiet = true;
  ASSERT_EQ(calibrate_command(options, out, err), 0) << err.str();
  // The curves of the reference and of the model before and after, and their plot.
  std::ifstream curves(work / "calibration" / "calibration_curves.csv");
  std::string line = test::header_after_provenance(curves);
  EXPECT_EQ(line, "curve,time_s,depth_mm,force_N,phase");
  std::set<std::string> names;
  while (std::getline(curves, line)) names.insert(line.substr(0, line.find(',')));
  EXPECT_EQ(names, (std::set<std::string>{"measured", "before", "after"}));
  EXPECT_TRUE(fs::exists(work / "calibration" / "calibration_force_depth.png"));

  const fs::path preset = work / "calibration" / "default_tuned.json";
  ASSERT_TRUE(fs::exists(preset));
  EXPECT_TRUE(fs::exists(work / "calibration" / "default_tuned.provenance.json"));
  EXPECT_TRUE(fs::exists(work / "calibration" / "calibration_summary.md"));
  const Scene tuned = load_scene(preset);
  EXPECT_NEAR(tuned.layers[0].force_mesh.virtual_stiffness_N_per_m, true_K, 0.05 * true_K);

  // The preset is a scene `puncture run` accepts.
  RunOptions rerun;
  rerun.scene = preset;
  rerun.output_dir = work / "preset_run";
  rerun.write_frames = false;
  rerun.quiet = true;
  EXPECT_EQ(run_command(rerun, out, err), 0) << err.str();
  fs::remove_all(work);
}

TEST(CalibrateCommand, DepthAndForceCurveWithGivenPunctureDepthsReportsEveryTerm) {
  // A measured-style curve with only depth and force (the default scene's
  // run with the skin's cutting force at 1.8 N), the skin's puncture depth
  // given on the command line: the summary lists every term, with n/a where
  // the curve cannot give one, and the tuned parameters with their bounds.
  const fs::path work = fresh_dir("calibrate_depth_force");
  fs::create_directories(work);
  Scene truth = load_scene(kSourceDir / "scenes" / "default.json");
  truth.layers[0].force_law.cutting_force_N = 1.8;
  truth.name = "truth";
  std::ofstream(work / "truth.json") << scene_to_json_text(truth);
  RunOptions run;
  run.scene = work / "truth.json";
  run.output_dir = work / "truth_run";
  run.write_frames = false;
  run.quiet = true;
  std::ostringstream out, err;
  ASSERT_EQ(run_command(run, out, err), 0) << err.str();
  std::ifstream summary_in(work / "truth_run" / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_in);
  const double skin_depth_mm = summary.at("puncture_events").at(0).at("depth_mm").get<double>();
  {
    std::ifstream in(work / "truth_run" / "realtime_curve.csv");
    std::ofstream curve(work / "depth_force.csv");
    curve << "# speed_mm_per_s: 10\ndepth_mm,force_N\n";
    std::string line = test::header_after_provenance(in);
    while (std::getline(in, line)) {
      std::vector<std::string> f;
      std::istringstream s(line);
      for (std::string x; std::getline(s, x, ',');) f.push_back(x);
      curve << f[1] << ',' << f[3] << '\n';
    }
  }
  CalibrateOptions options;
  options.scene = kSourceDir / "scenes" / "default.json";
  options.references = {work / "depth_force.csv"};
  options.output_dir = work / "calibration";
  options.layers = {"skin"};
  options.integrator = "quasi_static";
  options.puncture_depths_mm = {skin_depth_mm};
  options.keep = {"K", "breakthrough", "friction"};
  options.quiet = true;
  ASSERT_EQ(calibrate_command(options, out, err), 0) << err.str();
  std::ifstream md_in(work / "calibration" / "calibration_summary.md");
  std::stringstream md;
  md << md_in.rdbuf();
  for (const char* text : {"## Objective, term by term", "| pressing skin |", "| withdrawal |", "n/a",
                           "the reference has no part columns", "1 puncture depth(s) given", "cutting_force (N)",
                           "--puncture-depths", "--keep K,breakthrough,friction"})
    EXPECT_NE(md.str().find(text), std::string::npos) << text << "\n" << md.str();
  const Scene tuned = load_scene(work / "calibration" / "default_tuned.json");
  EXPECT_NEAR(tuned.layers[0].force_law.cutting_force_N, 1.8, 0.05 * 1.8);
  EXPECT_EQ(tuned.layers[0].force_mesh.virtual_stiffness_N_per_m,
            load_scene(kSourceDir / "scenes" / "default.json").layers[0].force_mesh.virtual_stiffness_N_per_m);
  fs::remove_all(work);
}

TEST(CalibrateCommand, BadKeepOrPunctureDepthsAreErrorsWithNoOutput) {
  const fs::path dir = fresh_dir("calibrate_bad_keep");
  const fs::path ref_dir = fresh_dir("calibrate_bad_keep_reference");
  fs::create_directories(ref_dir);
  std::ofstream(ref_dir / "curve.csv") << "depth_mm,force_N\n0,0\n1,0.5\n2,1.0\n";
  // --fem-speeds asks for FEM references of the scene, which a measured --reference replaces.
  const char* names[] = {"--keep", "--puncture-depths", "--force-weight", "--force-weight", "--fem-speeds",
                         "--surface-fit"};
  for (int which = 0; which < 6; ++which) {
    CalibrateOptions options;
    options.scene = kSourceDir / "scenes" / "default.json";
    options.references = {ref_dir / "curve.csv"};
    options.output_dir = dir;
    options.quiet = true;
    if (which == 0) options.keep = {"everything"};
    else if (which == 1) options.puncture_depths_mm = {-1.0};
    else if (which == 4) options.fem_speeds_mm_per_s = {3.0};
    else if (which == 5) options.surface_fit = true;
    else options.force_weight = which == 2 ? -1.0 : std::numeric_limits<double>::quiet_NaN();
    std::ostringstream out, err;
    EXPECT_EQ(calibrate_command(options, out, err), 2) << names[which];
    EXPECT_NE(err.str().find(names[which]), std::string::npos) << err.str();
    EXPECT_FALSE(fs::exists(dir));
  }
  fs::remove_all(ref_dir);
}

TEST(CalibrateCommand, UnknownExtraParameterIsAnErrorWithNoOutput) {
  const auto dir = fs::temp_directory_path() / "puncture_calibrate_unknown_parameter";
  const auto ref_dir = fs::temp_directory_path() / "puncture_calibrate_unknown_parameter_reference";
  fs::remove_all(dir);
  fs::create_directories(ref_dir);
  {
    std::ofstream ref(ref_dir / "curve.csv");
    ref << "time_s,depth_mm,velocity_mm_per_s,force_N,skin_state\n0,0,10,0,pressed\n0.1,1,10,0.5,pressed\n"
           "0.2,2,10,1.0,pressed\n";
  }
  CalibrateOptions options;
  options.scene = kSourceDir / "scenes" / "default.json";
  options.references = {ref_dir / "curve.csv"};
  options.output_dir = dir;
  options.also_tune = {"stiffness_of_everything"};
  options.quiet = true;
  std::ostringstream out, err;
  EXPECT_NE(calibrate_command(options, out, err), 0);
  EXPECT_NE(err.str().find("--also-tune"), std::string::npos) << err.str();
  EXPECT_FALSE(fs::exists(dir));
  fs::remove_all(ref_dir);
}

TEST(CalibrateCommand, MissingReferenceFileIsAnErrorWithNoOutput) {
  const fs::path dir = fresh_dir("calibrate_bad");
  CalibrateOptions options;
  options.scene = kSourceDir / "scenes" / "default.json";
  options.references = {"/nonexistent/curve.csv"};
  options.output_dir = dir;
  options.quiet = true;
  std::ostringstream out, err;
  EXPECT_NE(calibrate_command(options, out, err), 0);
  EXPECT_NE(err.str().find("/nonexistent/curve.csv"), std::string::npos) << err.str();
  EXPECT_FALSE(fs::exists(dir));
}

TEST(CalibrateCommand, AReferenceThatCannotBeFittedIsBadInputWithNoOutput) {
  // One row; five rows with one drop (no layer identified by them).
  const fs::path dir = fresh_dir("calibrate_unfittable");
  const fs::path ref_dir = fresh_dir("calibrate_unfittable_reference");
  fs::create_directories(ref_dir);
  std::ofstream(ref_dir / "one_row.csv") << "depth_mm,force_N\n0,0\n";
  std::ofstream(ref_dir / "five_rows.csv") << "depth_mm,force_N\n0,0\n1,1\n2,2\n2.5,0.5\n3,0.6\n";
  const std::pair<const char*, const char*> cases[] = {{"one_row.csv", "no force above the noise"},
                                                       {"five_rows.csv", "identifies no parameter"}};
  for (const auto& [file, why] : cases) {
    CalibrateOptions options;
    options.scene = kSourceDir / "scenes" / "default.json";
    options.references = {ref_dir / file};
    options.output_dir = dir;
    options.quiet = true;
    std::ostringstream out, err;
    EXPECT_EQ(calibrate_command(options, out, err), 2) << file << ": " << err.str();
    EXPECT_NE(err.str().find((ref_dir / file).string()), std::string::npos) << err.str();
    EXPECT_NE(err.str().find(why), std::string::npos) << err.str();
    EXPECT_FALSE(fs::exists(dir)) << file;
  }
  fs::remove_all(ref_dir);
}

TEST(CalibrateCommand, UnsurePunctureDetectionAsksForPunctureDepthsWithNoOutput) {
  // The shared noisy curve has one drop (14.6-14.8 mm) but passes the bottom
  // of the default slab's skin and fat: which layer broke there is a guess.
  const fs::path reference = fs::path(PUNCTURE_SHARED_DATA_DIR) / "noisy_drop_example.csv";
  ASSERT_TRUE(fs::exists(reference)) << reference << " is missing: the tests need shared/data beside the clone";
  const fs::path dir = fresh_dir("calibrate_unsure");
  CalibrateOptions options;
  options.scene = kSourceDir / "scenes" / "default.json";
  options.references = {reference};
  options.output_dir = dir;
  options.quiet = true;
  std::ostringstream out, err;
  EXPECT_EQ(calibrate_command(options, out, err), 2) << err.str();
  EXPECT_NE(err.str().find(reference.string()), std::string::npos) << err.str();
  EXPECT_NE(err.str().find("puncture detection is unsure"), std::string::npos) << err.str();
  EXPECT_NE(err.str().find("--puncture-depths"), std::string::npos) << err.str();
  EXPECT_FALSE(fs::exists(dir));
}

TEST(GradeCommand, GradesModelsFromAScoresFile) {
  const fs::path dir = fresh_dir("grade");
  fs::create_directories(dir);
  // Two models, two residents, the paper's seven indicators. Model B scores
  // one point more on every indicator, so its comprehensive score is exactly
  // one more than A's (the weights sum to 1 for each model).
  std::ofstream(dir / "scores.csv") << "model,resident,texture,force,puncture,environment,realtime,training,stability\n"
                                       "A,r1,7,8,6,7,9,8,7\n"
                                       "A,r2,8,7,7,6,8,9,8\n"
                                       "B,r1,8,9,7,8,10,9,8\n"
                                       "B,r2,9,8,8,7,9,10,9\n";
  GradeOptions options;
  options.scores = dir / "scores.csv";
  options.output_dir = dir / "out";
  std::ostringstream out, err;
  ASSERT_EQ(grade_command(options, out, err), 0) << err.str();
  EXPECT_TRUE(fs::exists(dir / "out" / "grading_summary.csv"));
  EXPECT_TRUE(fs::exists(dir / "out" / "grading_schemes.csv"));
  std::ifstream summary(dir / "out" / "grading_summary.csv");
  std::string header, row_a, row_b;
  header = test::header_after_provenance(summary);
  std::getline(summary, row_a);
  std::getline(summary, row_b);
  ASSERT_EQ(header.rfind("model,n_schemes,mean_score,", 0), 0u) << header;
  auto mean_of = [](const std::string& row) {
    std::stringstream s(row);
    std::string model, n, mean;
    std::getline(s, model, ',');
    std::getline(s, n, ',');
    std::getline(s, mean, ',');
    return std::stod(mean);
  };
  EXPECT_EQ(row_a.substr(0, 2), "A,");
  EXPECT_NEAR(mean_of(row_b) - mean_of(row_a), 1.0, 1e-12);

  options.mu = 1.5;
  EXPECT_NE(grade_command(options, out, err), 0);
  options.mu = 0.4;
  options.scores = dir / "missing.csv";
  EXPECT_NE(grade_command(options, out, err), 0);
  fs::remove_all(dir);
}

TEST(SlabRuleCommand, FitsThePresetsOfAFamilyAndRejectsBadInput) {
  const fs::path dir = fresh_dir("slab_rule");
  fs::create_directories(dir);
  // Four "calibrated" presets: the default scene on four slabs with the
  // skin's K = 100 N/m (h / 0.8 mm)^2.
  const double skin_mm[4] = {0.8, 1.6, 1.2, 1.0};
  std::vector<fs::path> presets;
  for (int i = 0; i < 4; ++i) {
    Scene s = load_scene(kSourceDir / "scenes" / "default.json");
    s.layers[0].thickness_m = skin_mm[i] * 1e-3;
    s.layers[0].force_mesh.virtual_stiffness_N_per_m = 100.0 * std::pow(skin_mm[i] / 0.8, 2.0);
    presets.push_back(dir / ("p" + std::to_string(i) + ".json"));
    std::ofstream(presets.back()) << scene_to_json_text(s);
  }
  SlabRuleOptions options;
  options.presets = presets;
  options.output_dir = dir / "rule";
  std::ostringstream out, err;
  ASSERT_EQ(slab_rule_command(options, out, err), 0) << err.str();
  std::ifstream in(dir / "rule" / "slab_rule.json");
  const nlohmann::json rule = nlohmann::json::parse(in);
  ASSERT_EQ(rule["layers"].size(), 1u);
  EXPECT_EQ(rule["layers"][0]["layer"], "skin");
  ASSERT_EQ(rule["layers"][0]["parameters"].size(), 1u);
  EXPECT_EQ(rule["layers"][0]["parameters"][0]["pointer"], "/force_mesh/K_N_per_mm");
  EXPECT_NEAR(rule["layers"][0]["parameters"][0]["exponent"].get<double>(), 2.0, 1e-9);
  EXPECT_TRUE(rule.contains("provenance"));
  EXPECT_TRUE(fs::exists(dir / "rule" / "slab_rule.md"));
  EXPECT_NE(err.str().find("no calibration record"), std::string::npos) << err.str();  // said, not silent

  // With calibration records beside the presets (<stem>.provenance.json, as
  // `puncture calibrate` writes): a value its calibration left at a bound
  // stays out of the fit however wild it is.
  {
    Scene wild = load_scene(presets[2]);
    wild.layers[0].force_mesh.virtual_stiffness_N_per_m = 1e6;
    std::ofstream(presets[2]) << scene_to_json_text(wild);
    for (int i = 0; i < 4; ++i)
      std::ofstream(dir / ("p" + std::to_string(i) + ".provenance.json"))
          << nlohmann::json{{"calibrated_values",
                             {{{"layer", "skin"}, {"pointer", "/force_mesh/K_N_per_mm"},
                               {"status", i == 2 ? "at a bound" : "identified"}}}}}.dump();
    options.output_dir = dir / "recorded";
    std::ostringstream recorded_err;
    ASSERT_EQ(slab_rule_command(options, out, recorded_err), 0) << recorded_err.str();
    EXPECT_EQ(recorded_err.str().find("no calibration record"), std::string::npos) << recorded_err.str();
    std::ifstream rin(dir / "recorded" / "slab_rule.json");
    const nlohmann::json recorded = nlohmann::json::parse(rin);
    ASSERT_EQ(recorded["layers"].size(), 1u);
    ASSERT_EQ(recorded["layers"][0]["parameters"].size(), 1u);
    const nlohmann::json& k = recorded["layers"][0]["parameters"][0];
    EXPECT_NEAR(k["exponent"].get<double>(), 2.0, 1e-9);
    ASSERT_EQ(k["excluded"].size(), 1u);
    EXPECT_EQ(k["excluded"][0]["file"], presets[2].string());
    EXPECT_EQ(k["excluded"][0]["status"], "at a bound");
    // A record that is not JSON: bad input naming it, nothing written.
    std::ofstream(dir / "p1.provenance.json") << "{not json";
    options.output_dir = dir / "broken_record";
    std::ostringstream broken_err;
    EXPECT_EQ(slab_rule_command(options, out, broken_err), kExitBadInput);
    EXPECT_NE(broken_err.str().find("p1.provenance.json"), std::string::npos) << broken_err.str();
    EXPECT_FALSE(fs::exists(dir / "broken_record"));
    fs::remove(dir / "p1.provenance.json");
  }

  // One preset: a usage error, nothing written.
  options.presets = {presets[0]};
  options.output_dir = dir / "one";
  EXPECT_EQ(slab_rule_command(options, out, err), kExitBadInput);
  EXPECT_FALSE(fs::exists(dir / "one"));
  // A negative K in one preset: bad input naming the file and the field.
  Scene bad = load_scene(presets[1]);
  bad.layers[0].force_mesh.virtual_stiffness_N_per_m = 0.0;
  std::ofstream(dir / "bad.json") << scene_to_json_text(bad);
  options.presets = {presets[0], dir / "bad.json"};
  options.output_dir = dir / "bad";
  std::ostringstream bad_err;
  EXPECT_EQ(slab_rule_command(options, out, bad_err), kExitBadInput);
  EXPECT_NE(bad_err.str().find("bad.json"), std::string::npos) << bad_err.str();
  EXPECT_FALSE(fs::exists(dir / "bad" / "slab_rule.json"));

  // calibrate --layer-thickness with one value per layer only.
  CalibrateOptions calibrate;
  calibrate.scene = kSourceDir / "scenes" / "default.json";
  calibrate.output_dir = dir / "calibrate";
  calibrate.layer_thickness_mm = {1.0, 5.0};
  std::ostringstream calibrate_err;
  EXPECT_EQ(calibrate_command(calibrate, out, calibrate_err), kExitBadInput);
  EXPECT_NE(calibrate_err.str().find("--layer-thickness"), std::string::npos) << calibrate_err.str();

  // validate --slab-rule without cases: a usage error before any FEM runs.
  ValidateOptions validate;
  validate.scene = kSourceDir / "scenes" / "default.json";
  validate.output_dir = dir / "validate";
  validate.slab_rule = dir / "rule" / "slab_rule.json";
  std::ostringstream validate_err;
  EXPECT_EQ(validate_command(validate, out, validate_err), kExitBadInput);
  EXPECT_NE(validate_err.str().find("--slab-rule"), std::string::npos) << validate_err.str();
  EXPECT_FALSE(fs::exists(dir / "validate"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace puncture::apps
