// `puncture compare` end to end on a small slab against a synthetic FEM
// reference placed in the cache as a complete entry of the scene's key (the
// full default FEM takes minutes; the test fails if the command runs the FEM
// instead): table, ranking, curves, ParaView series, summary, and each model's
// force RMSE recomputed here from its curve and the synthetic reference; bad
// input.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "puncture/apps/commands.hpp"
#include "puncture/validation/fem_reference.hpp"
#include "puncture/scene_io.hpp"

namespace fs = std::filesystem;

namespace puncture::apps {
namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("puncture_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

/// Skin 1 mm, fat 3 mm, muscle 4 mm, 10 mm across; 4 mm insertion.
Scene small_scene() {
  Scene s = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  s.name = "compare_test";
  s.sample.diameter_m = 10e-3;
  const double thickness[3] = {1e-3, 3e-3, 4e-3};
  for (int k = 0; k < 3; ++k) {
    Layer& l = s.layers[static_cast<std::size_t>(k)];
    l.thickness_m = thickness[k];
    l.force_mesh.rings_w = 3;
    l.force_mesh.spacing_L_m = 1.5e-3;
    l.force_mesh.deformed_threshold_m = 50e-6;
  }
  s.insertion.start_height_m = 0.2e-3;
  s.insertion.target_depth_m = 4e-3;
  s.insertion.dwell_s = 0.02;
  s.insertion.withdrawal_speed_m_per_s = 0.05;
  s.realtime.sh_degree = 8;
  s.comparison.mesh.size_at_axis_m = 0.6e-3;
  s.comparison.mesh.size_far_m = 2.5e-3;
  s.comparison.mesh.grading = 0.5;
  return s;
}

/// A synthetic FEM reference: the skin pressed 0..1.2 mm at 20 mN/mm, broken
/// there; the fat pressed from 1.2 to 2.5 mm at 5 mN/mm, broken; the muscle
/// pressed from 4 mm (the end). Skin profiles u_z(r) = -delta a / max(r, a).
/// A complete cache entry: curve, profiles, summary, an empty ParaView series
/// and the key text of `scene`.
struct SyntheticSample {
  double depth_mm, force_N;
};
std::vector<SyntheticSample> write_synthetic_reference(const Scene& scene, const fs::path& cache) {
  validation::FemReferenceOptions options;
  options.cache_dir = cache;
  const fs::path dir = cache / validation::fem_reference_hash(scene, options);
  fs::create_directories(dir);
  std::ofstream(dir / "fem_reference_key.json") << validation::fem_reference_key_text(scene, options);
  std::ofstream(dir / "fem_fields.pvd")
      << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n</Collection>\n</VTKFile>\n";
  std::vector<SyntheticSample> samples;
  std::ofstream curve(dir / "fem_force_depth.csv");
  curve << "time_s,depth_mm,velocity_mm_per_s,force_N,tip_stretch,skin_state,fat_state,muscle_state\n";
  const double speed = 10.0;  // mm/s
  auto row = [&](double depth, double force, const char* s, const char* f, const char* m) {
    samples.push_back({depth, force});
    curve << (depth + 0.2) / speed << ',' << depth << ',' << speed << ',' << force << ",1," << s << ',' << f << ','
          << m << '\n';
  };
  for (double d = -0.2; d < 1.2 - 1e-9; d += 0.1) row(d, d > 0 ? 0.02 * d : 0.0, d >= 0 ? "pressed" : "untouched", "untouched", "untouched");
  row(1.2, 0.024, "pressed", "untouched", "untouched");
  row(1.2, 0.0, "punctured", "pressed", "untouched");
  for (double d = 1.3; d < 2.5 - 1e-9; d += 0.1) row(d, 0.005 * (d - 1.2), "punctured", "pressed", "untouched");
  row(2.5, 0.0065, "punctured", "pressed", "untouched");
  row(2.5, 0.0, "punctured", "punctured", "untouched");
  for (double d = 2.6; d <= 4.0 + 1e-9; d += 0.1) row(d, 0.0, "punctured", "punctured", "untouched");
  curve.close();
  std::ofstream profile(dir / "fem_surface_profile.csv");
  profile << "step,depth_mm,r_mm,uz_mm,surface\n";
  for (int step = 1; step <= 3; ++step) {
    const double depth = 0.3 * step;
    for (double r : {0.0, 0.3, 0.635, 1.0, 2.0, 3.0, 4.0, 5.0})
      profile << step << ',' << depth << ',' << r << ',' << -depth * 0.635 / std::max(r, 0.635) << ",skin\n";
  }
  profile.close();
  std::ofstream(dir / "fem_recovery_profile.csv") << "layer,phase,depth_mm,r_mm,uz_mm\n";
  std::ofstream(dir / "fem_summary.json")
      << R"({"status": "ok", "n_dofs": 1234, "n_ranks": 1, "load_steps": 40, "wall_time_s": 20.0, "punctures": []})";
  return samples;
}

/// Force RMSE of a model curve file (curves/<model>.csv) against the synthetic
/// samples, over the FEM peak: the model's insertion rows (velocity > 0, up to
/// its deepest sample) interpolated linearly in depth at every synthetic depth
/// that is recorded once (a depth recorded twice is a drop and not compared).
double hand_force_rmse_relative(const fs::path& model_curve, const std::vector<SyntheticSample>& reference) {
  std::ifstream in(model_curve);
  std::string line;
  std::vector<std::string> columns;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::string c;
    while (std::getline(s, c, ',')) columns.push_back(c);
    break;
  }
  const auto col = [&](const char* name) {
    return static_cast<std::size_t>(std::find(columns.begin(), columns.end(), name) - columns.begin());
  };
  const std::size_t c_depth = col("depth_mm"), c_velocity = col("velocity_mm_per_s"), c_force = col("force_N");
  EXPECT_LT(std::max({c_depth, c_velocity, c_force}), columns.size()) << model_curve;
  std::vector<double> depth, force;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::istringstream s(line);
    std::string x;
    while (std::getline(s, x, ',')) f.push_back(x);
    if (f.size() != columns.size()) continue;
    const double d = std::stod(f[c_depth]);
    if (!(std::stod(f[c_velocity]) > 0.0)) {
      if (!depth.empty() && d < depth.back()) break;  // withdrawal began
      continue;
    }
    if (!depth.empty() && d < depth.back()) break;
    depth.push_back(d), force.push_back(std::stod(f[c_force]));
  }
  double sum = 0.0, peak = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < reference.size(); ++i) {
    peak = std::max(peak, std::abs(reference[i].force_N));
    const double z = reference[i].depth_mm;
    const bool repeated = (i > 0 && reference[i - 1].depth_mm == z) ||
                          (i + 1 < reference.size() && reference[i + 1].depth_mm == z);
    if (repeated || depth.size() < 2 || z < depth.front() || z > depth.back()) continue;
    const std::size_t hi = static_cast<std::size_t>(std::upper_bound(depth.begin(), depth.end(), z) - depth.begin());
    double f = force.back();
    if (hi < depth.size()) {
      const std::size_t lo = hi - 1;
      const double t = depth[hi] > depth[lo] ? (z - depth[lo]) / (depth[hi] - depth[lo]) : 1.0;
      f = force[lo] + t * (force[hi] - force[lo]);
    }
    sum += (f - reference[i].force_N) * (f - reference[i].force_N);
    ++n;
  }
  EXPECT_GT(n, 30u) << model_curve;
  return std::sqrt(sum / static_cast<double>(n)) / peak;
}

TEST(CompareCommand, TableRankingCurvesAndSeriesOnASmallSlab) {
  const fs::path dir = fresh_dir("compare");
  const Scene scene = small_scene();
  const fs::path scene_file = dir / "small.json";
  std::ofstream(scene_file) << scene_to_json_text(scene);
  const std::vector<SyntheticSample> reference = write_synthetic_reference(load_scene(scene_file), dir / "cache");
  CompareOptions options;
  options.scene = scene_file;
  options.output_dir = dir / "out";
  options.cache_dir = dir / "cache";
  options.models = {"realtime", "shf", "bem", "mass_tensor", "fem"};
  // The scene's own moduli and rules (identified, the linear models would fit
  // the piecewise linear synthetic reference exactly: no error to recompute).
  options.scene_parameters = true;
  options.frames = 2;
  options.quiet = true;
  std::ostringstream out, err;
  ASSERT_EQ(compare_command(options, out, err), 0) << err.str();
  // The synthetic entry was used, not replaced by a FEM run.
  validation::FemReferenceOptions fem_options;
  fem_options.cache_dir = options.cache_dir;
  std::ifstream summary(fem_options.cache_dir / validation::fem_reference_hash(load_scene(scene_file), fem_options) /
                        "fem_summary.json");
  std::stringstream summary_text;
  summary_text << summary.rdbuf();
  EXPECT_NE(summary_text.str().find("\"n_dofs\": 1234"), std::string::npos) << "the cached synthetic reference was replaced";
  for (const char* f : {"comparison.csv", "ranking.csv", "comparison.md", "comparison_summary.json", "fem_curve.csv",
                        "deflection_profiles.csv", "curves/realtime.csv", "curves/mass_tensor.csv", "mesh.vtu",
                        "comparison.pvd"})
    EXPECT_TRUE(fs::exists(options.output_dir / f)) << f;

  std::ifstream table(options.output_dir / "comparison.csv");
  std::string header, line;
  std::getline(table, header);
  EXPECT_NE(header.find("force_rmse_relative"), std::string::npos);
  EXPECT_NE(header.find("step_time_p99_ms"), std::string::npos);
  EXPECT_NE(header.find("memory_MB"), std::string::npos);
  std::vector<std::string> columns;
  {
    std::istringstream s(header);
    std::string c;
    while (std::getline(s, c, ',')) columns.push_back(c);
  }
  const auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(columns.begin(), columns.end(), name) - columns.begin());
  };
  std::vector<std::string> models;
  while (std::getline(table, line)) {
    std::vector<std::string> fields;
    std::istringstream s(line);
    std::string f;
    while (std::getline(s, f, ',')) fields.push_back(f);
    models.push_back(fields[0]);
    const double rmse = std::stod(fields[column("force_rmse_relative")]);
    if (models.back() == "fem") {
      EXPECT_EQ(rmse, 0.0);
    } else {
      EXPECT_GT(rmse, 0.0) << models.back();
      // The table's force RMSE is the one computed here from the model's own curve.
      const fs::path model_curve = options.output_dir / "curves" / (models.back() + ".csv");
      if (fs::exists(model_curve)) {
        const double by_hand = hand_force_rmse_relative(model_curve, reference);
        EXPECT_NEAR(rmse, by_hand, 1e-4 * by_hand) << models.back();
      } else {
        ADD_FAILURE() << "no curve file for " << models.back();
      }
      EXPECT_GT(std::stod(fields[column("step_time_p99_ms")]), 0.0) << models.back();
      EXPECT_GT(std::stod(fields[column("memory_MB")]), 0.0) << models.back();
    }
  }
  EXPECT_EQ(models, (std::vector<std::string>{"realtime", "shf", "bem", "mass_tensor", "fem"}));

  std::ifstream ranking(options.output_dir / "ranking.csv");
  std::getline(ranking, header);
  std::vector<int> ranks;
  while (std::getline(ranking, line) && line[0] != '#') {
    std::istringstream s(line);
    std::string model, rank;
    std::getline(s, model, ',');
    std::getline(s, rank, ',');
    ranks.push_back(std::stoi(rank));
  }
  std::sort(ranks.begin(), ranks.end());
  EXPECT_EQ(ranks, (std::vector<int>{1, 2, 3, 4, 5}));
  std::ifstream md(options.output_dir / "comparison.md");
  std::stringstream text;
  text << md.rdbuf();
  // The synthetic reference has no tip/cutting/friction columns, and the report says so.
  EXPECT_NE(text.str().find("no cutting/friction columns"), std::string::npos);
  EXPECT_NE(text.str().find("Ranking"), std::string::npos);
  fs::remove_all(dir);
}

/// The column `name` of every data row of a CSV file (header first, '#' lines skipped).
std::vector<std::string> csv_column(const fs::path& file, const std::string& name, std::vector<std::string>* first = nullptr) {
  std::ifstream in(file);
  std::string line;
  std::vector<std::string> columns, values;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::istringstream s(line);
    std::string f;
    while (std::getline(s, f, ',')) fields.push_back(f);
    if (columns.empty()) {
      columns = fields;
      continue;
    }
    const std::size_t c = static_cast<std::size_t>(std::find(columns.begin(), columns.end(), name) - columns.begin());
    values.push_back(c < fields.size() ? fields[c] : "");
    if (first) first->push_back(fields[0]);
  }
  return values;
}

TEST(CompareCommand, ModelsBreakWhereTheFemDoesAndAreJudgedOnHeldOutCases) {
  // Every comparison model's critical forces are identified on the scene's
  // trajectory: the synthetic FEM breaks the skin at 1.2 mm and the fat at
  // 2.5 mm, so every model does (within a step of needle travel, 10 um); then
  // every model, unchanged, runs a held-out case (3 mm/s) against that case's
  // FEM, and the ranking of comparison.md is the held-out one.
  const fs::path dir = fresh_dir("compare_heldout");
  const Scene scene = small_scene();
  const fs::path scene_file = dir / "small.json";
  std::ofstream(scene_file) << scene_to_json_text(scene);
  write_synthetic_reference(load_scene(scene_file), dir / "cache");
  Scene slow = load_scene(scene_file);
  slow.insertion.speed_m_per_s = 3e-3;
  write_synthetic_reference(slow, dir / "cache");
  const fs::path cases_file = dir / "cases.json";
  std::ofstream(cases_file) << R"({"description": "test", "cases": [{"name": "calibration", "overrides": {}},
      {"name": "slow", "overrides": {"insertion": {"speed_mm_per_s": 3.0}}}]})";
  CompareOptions options;
  options.scene = scene_file;
  options.output_dir = dir / "out";
  options.cache_dir = dir / "cache";
  options.models = {"realtime", "shf", "bem", "mass_tensor", "fem"};
  options.cases = cases_file;
  options.frames = 0;
  options.write_vtk = false;
  options.quiet = true;
  std::ostringstream out, err;
  ASSERT_EQ(compare_command(options, out, err), 0) << err.str();
  std::vector<std::string> models;
  const std::vector<std::string> skin = csv_column(options.output_dir / "comparison.csv", "skin_puncture_mm", &models);
  const std::vector<std::string> fat = csv_column(options.output_dir / "comparison.csv", "fat_puncture_mm");
  ASSERT_EQ(models.size(), 5u);
  for (std::size_t i = 0; i < models.size(); ++i) {
    if (models[i] == "realtime" || models[i] == "fem") continue;  // the real-time model keeps its own rules
    EXPECT_NEAR(std::stod(skin[i]), 1.2, 0.011) << models[i];
    EXPECT_NEAR(std::stod(fat[i]), 2.5, 0.011) << models[i];
    EXPECT_TRUE(fs::exists(options.output_dir / "identified" / (models[i] + ".json"))) << models[i];
    const Scene identified = load_scene(options.output_dir / "identified" / (models[i] + ".json"));
    EXPECT_EQ(identified.layers[0].force_law.breakthrough.kind, BreakthroughCriterion::Kind::CriticalForce);
  }
  // Held out: one row per model (not the FEM) for the one held-out case.
  std::vector<std::string> heldout_cases;
  const std::vector<std::string> heldout_models =
      csv_column(options.output_dir / "heldout.csv", "model", &heldout_cases);
  EXPECT_EQ(heldout_models, (std::vector<std::string>{"realtime", "shf", "bem", "mass_tensor"}));
  for (const std::string& c : heldout_cases) EXPECT_EQ(c, "slow");
  EXPECT_TRUE(fs::exists(options.output_dir / "ranking_heldout.csv"));
  std::ifstream md(options.output_dir / "comparison.md");
  std::stringstream text;
  text << md.rdbuf();
  EXPECT_NE(text.str().find("## Ranking on the held-out cases"), std::string::npos);
  EXPECT_NE(text.str().find("## Every model identified against the FEM"), std::string::npos);
  EXPECT_NE(text.str().find("## Where the time goes"), std::string::npos);
  // The time budget: every phase measured (none negative), the models'
  // identifications and the runs two at a time among them, adding up to the total.
  std::ifstream summary_file(options.output_dir / "comparison_summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  const double total_s = summary["wall_time_s"].get<double>();
  double sum_s = 0.0;
  std::set<std::string> phases;
  for (const nlohmann::json& e : summary["time_budget"]) {
    const double s = e["wall_time_s"].get<double>();
    EXPECT_GE(s, 0.0) << e.dump();
    sum_s += s;
    phases.insert(e["phase"].get<std::string>());
  }
  EXPECT_NEAR(sum_s, total_s, 1e-6 * total_s);
  for (const char* p : {"FEM reference, calibration trajectory", "FEM references, 2 cases",
                        "identifications against the FEM", "bem: calibration-trajectory run",
                        "volumetric runs and held-out phase", "the rest"})
    EXPECT_EQ(phases.count(p), 1u) << p;
  // The volumetric model's run on the calibration trajectory went with the
  // held-out runs (two at a time): its time is in that phase's note.
  EXPECT_EQ(phases.count("mass_tensor: calibration-trajectory run"), 0u);
  for (const nlohmann::json& e : summary["time_budget"])
    if (e["phase"] == "volumetric runs and held-out phase")
      EXPECT_NE(e["note"].get<std::string>().find("calibration-trajectory runs of mass_tensor"), std::string::npos)
          << e.dump();
  // The identifications ran side by side: each model's own time is in the
  // phase's note, and none exceeds the phase.
  for (const nlohmann::json& e : summary["time_budget"])
    if (e["phase"] == "identifications against the FEM") {
      for (const char* model : {"shf", "bem", "mass_tensor"})
        EXPECT_NE(e["note"].get<std::string>().find(std::string(" ") + model + " "), std::string::npos) << e.dump();
      for (const auto& [model, id] : summary["model_identification"].items())
        EXPECT_LE(id["wall_time_s"].get<double>(), e["wall_time_s"].get<double>() + 1e-9) << model;
    }
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}

TEST(CompareCommand, BadInputFailsCleanly) {
  const fs::path dir = fresh_dir("compare_bad");
  const Scene scene = small_scene();
  const fs::path scene_file = dir / "small.json";
  std::ofstream(scene_file) << scene_to_json_text(scene);
  CompareOptions options;
  options.scene = scene_file;
  options.output_dir = dir / "out";
  options.cache_dir = dir / "cache";
  options.quiet = true;
  std::ostringstream out, err;
  options.models = {"realtime", "cloth"};
  EXPECT_EQ(compare_command(options, out, err), 2) << "a bad --models value is bad input";
  EXPECT_NE(err.str().find("unknown model 'cloth'"), std::string::npos) << err.str();
  options.models = {"realtime"};
  const fs::path weights = dir / "weights.json";
  std::ofstream(weights) << R"({"schema": "puncture-delphi-weights/1", "indicators": [
      {"name": "x", "metric": "force_rmse_relative", "best": 0, "worst": 1, "weight": 0.7}]})";
  options.weights = weights;
  err.str("");
  EXPECT_EQ(compare_command(options, out, err), 2) << "a malformed weights file is bad input";
  EXPECT_NE(err.str().find("/indicators: weights must sum to 1"), std::string::npos) << err.str();
  std::ofstream(dir / "bad.json") << R"({"schema_version": 1, "name": "x"})";
  options.scene = dir / "bad.json";
  err.str("");
  EXPECT_EQ(compare_command(options, out, err), 2);
  EXPECT_FALSE(fs::exists(options.output_dir));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace puncture::apps
