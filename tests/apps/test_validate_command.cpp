// FEM reference cache (key invariance, second call served from the cache) and
// `puncture validate` end to end on a small three-layer scene with a coarse mesh.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "csv_header.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/validation/fem_reference.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/metrics.hpp"
#include "puncture/validation/recording.hpp"

namespace fs = std::filesystem;

namespace puncture::apps {
namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("puncture_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

Layer make_layer(const std::string& name, double thickness_m, double E_Pa, double critical_force_N) {
  Layer l;
  l.name = name;
  l.thickness_m = thickness_m;
  l.material.youngs_modulus_Pa = E_Pa;
  l.material.poisson_ratio = 0.45;
  l.puncture.kind = PunctureCriterion::Kind::CriticalForce;
  l.puncture.critical_force_N = critical_force_N;
  l.force_mesh.rings_w = 4;
  l.force_mesh.spacing_L_m = 1e-3;
  return l;
}

/// Three layers in a 16 mm sample, 3 mm insertion: the FEM finishes in seconds.
Scene small_scene() {
  Scene s;
  s.name = "validate_test";
  s.sample.diameter_m = 0.016;
  s.layers = {make_layer("skin", 0.8e-3, 2.0e5, 0.05), make_layer("fat", 2.5e-3, 2.0e4, 0.03),
              make_layer("muscle", 4.0e-3, 5.0e4, 100.0)};
  s.insertion.start_height_m = 0.5e-3;
  s.insertion.speed_m_per_s = 0.01;
  s.insertion.target_depth_m = 3e-3;
  s.insertion.dwell_s = 0.05;
  s.fem.load_step_m = 0.25e-3;
  s.realtime.sh_degree = 8;
  return s;
}

#ifdef PUNCTURE_HAVE_FEM
validation::FemReferenceOptions coarse_options(const fs::path& cache) {
  validation::FemReferenceOptions o;
  o.cache_dir = cache;
  o.verbose = false;
  o.write_vtu = false;
  o.mesh.elements_through_skin = 1;
  o.mesh.sectors = 8;
  o.mesh.radial_grading = 1.6;
  o.mesh.thickness_grading = 1.6;
  return o;
}
#endif

TEST(FemReferenceHash, IgnoresRealtimeOnlyFields) {
  const Scene base = small_scene();
  const validation::FemReferenceOptions options;
  const std::string h = validation::fem_reference_hash(base, options);
  EXPECT_EQ(h.size(), 32u);
  std::vector<std::pair<std::string, std::function<void(Scene&)>>> realtime_only{
      {"K", [](Scene& s) { s.layers[0].force_mesh.virtual_stiffness_N_per_m *= 2; }},
      {"w", [](Scene& s) { s.layers[1].force_mesh.rings_w += 3; }},
      {"L", [](Scene& s) { s.layers[2].force_mesh.spacing_L_m *= 1.5; }},
      {"d", [](Scene& s) { s.layers[0].damping_N_s_per_m2 *= 3; }},
      {"surface stiffness", [](Scene& s) { s.layers[0].force_mesh.surface_stiffness_N_per_m *= 2; }},
      {"resumption time", [](Scene& s) { s.layers[1].resumption_time_s = 0.2; }},
      {"sh_degree", [](Scene& s) { s.realtime.sh_degree = 24; }},
      {"integrator", [](Scene& s) { s.realtime.integrator = "explicit"; }},
      {"haptic rate", [](Scene& s) { s.realtime.haptic_rate_Hz = 2000; }},
      {"density", [](Scene& s) { s.layers[2].density_kg_per_m3 = 1500; }},
      {"real-time force law", [](Scene& s) { s.layers[0].force_law.cutting_force_N = 2.0; }},
      {"effects", [](Scene& s) { s.effects.resumption = false; }},
      {"name", [](Scene& s) { s.name = "renamed"; }},
  };
  for (const auto& [what, change] : realtime_only) {
    Scene s = base;
    change(s);
    EXPECT_EQ(validation::fem_reference_hash(s, options), h) << "a change of " << what << " must hit the cache";
  }
}

TEST(FemReferenceHash, ChangesWithEverythingTheFemSees) {
  const Scene base = small_scene();
  const validation::FemReferenceOptions options;
  const std::string h = validation::fem_reference_hash(base, options);
  std::vector<std::pair<std::string, std::function<void(Scene&)>>> fem_relevant{
      {"E", [](Scene& s) { s.layers[1].material.youngs_modulus_Pa *= 1.0000001; }},
      {"nu", [](Scene& s) { s.layers[2].material.poisson_ratio = 0.49; }},
      {"material model", [](Scene& s) { s.layers[0].material.model = "mooney_rivlin"; }},
      {"thickness", [](Scene& s) { s.layers[0].thickness_m = 1.0e-3; }},
      {"critical force", [](Scene& s) { s.layers[1].puncture.critical_force_N = 0.04; }},
      {"criterion kind", [](Scene& s) { s.layers[1].puncture.kind = PunctureCriterion::Kind::CriticalStretch; }},
      {"diameter", [](Scene& s) { s.sample.diameter_m = 0.02; }},
      {"needle radius", [](Scene& s) { s.needle.radius_m = 0.5e-3; }},
      {"speed", [](Scene& s) { s.insertion.speed_m_per_s = 0.02; }},
      {"target depth", [](Scene& s) { s.insertion.target_depth_m = 4e-3; }},
      {"start height", [](Scene& s) { s.insertion.start_height_m = 1e-3; }},
      {"load step", [](Scene& s) { s.fem.load_step_m = 0.2e-3; }},
      {"scene refinement", [](Scene& s) { s.fem.refinement = 1; }},
      {"newton tolerance", [](Scene& s) { s.fem.newton_tolerance = 1e-9; }},
      // The axisymmetric reference runs the whole trajectory.
      {"dwell", [](Scene& s) { s.insertion.dwell_s = 3.0; }},
      {"withdrawal", [](Scene& s) { s.insertion.withdrawal_speed_m_per_s = 0.05; }},
      {"fracture energy", [](Scene& s) {
         s.layers[0].puncture.kind = PunctureCriterion::Kind::FractureEnergy;
         s.layers[0].puncture.toughness_J_per_m2 = 1000.0;
       }},
      {"shaft friction", [](Scene& s) { s.layers[1].shaft_friction.dynamic_coefficient = 0.1; }},
      {"cohesive viscosity", [](Scene& s) { s.fem.cohesive_viscosity_s = 0.01; }},
      {"stabilisation time", [](Scene& s) { s.fem.stabilization_time_s = 0.01; }},
      {"tip angle", [](Scene& s) { s.needle.tip_angle_deg = 30.0; }},
      {"geometry", [](Scene& s) { s.fem.geometry = "axisymmetric"; }},
      {"fem mesh", [](Scene& s) { s.fem.mesh.radial_growth = 1.5; }},
  };
  std::map<std::string, std::string> seen{{h, "base"}};
  for (const auto& [what, change] : fem_relevant) {
    Scene s = base;
    change(s);
    const std::string changed = validation::fem_reference_hash(s, options);
    EXPECT_NE(changed, h) << "a change of " << what << " must change the key";
    EXPECT_TRUE(seen.emplace(changed, what).second) << what << " collides with " << seen[changed];
  }
  validation::FemReferenceOptions refined = options;
  refined.refinement = 1;
  EXPECT_NE(validation::fem_reference_hash(base, refined), h) << "refinement override";
  validation::FemReferenceOptions q2 = options;
  q2.degree = 2;
  EXPECT_NE(validation::fem_reference_hash(base, q2), h) << "degree override";
  // An override equal to the scene's own value is the same FEM.
  validation::FemReferenceOptions same = options;
  same.refinement = base.fem.refinement;
  same.degree = base.fem.element_degree;
  EXPECT_EQ(validation::fem_reference_hash(base, same), h);
#ifdef PUNCTURE_HAVE_FEM
  validation::FemReferenceOptions mesh = options;
  mesh.mesh.sectors = 8;
  EXPECT_NE(validation::fem_reference_hash(base, mesh), h) << "mesh options";
#endif
  // Output-only options are not part of the key.
  validation::FemReferenceOptions other_dir = options;
  other_dir.cache_dir = "elsewhere";
  other_dir.write_vtu = false;
  other_dir.verbose = false;
  EXPECT_EQ(validation::fem_reference_hash(base, other_dir), h);
}

#ifdef PUNCTURE_HAVE_FEM
TEST(FemReferenceCache, SecondCallComesFromTheCacheWithoutRunning) {
  const fs::path cache = fresh_dir("fem_cache");
  const Scene scene = small_scene();
  std::ostringstream out;
  const validation::FemReference first = validation::obtain_fem_reference(scene, coarse_options(cache), out);
  EXPECT_FALSE(first.from_cache);
  EXPECT_EQ(first.dir, cache / first.hash);
  for (const char* f : {"fem_force_depth.csv", "fem_surface_profile.csv", "fem_recovery_profile.csv",
                        "fem_summary.json", "fem_reference_key.json"})
    EXPECT_TRUE(fs::is_regular_file(first.dir / f)) << f;
  // Nothing but the finished entry is left in the cache directory.
  std::size_t entries = 0;
  for (const auto& e : fs::directory_iterator(cache)) {
    ++entries;
    EXPECT_EQ(e.path().filename().string(), first.hash);
  }
  EXPECT_EQ(entries, 1u);
  // The cached curve is the FEM's insertion: it reaches the target depth with the skin punctured.
  std::ifstream csv(first.dir / "fem_force_depth.csv");
  std::string line, last;
  while (std::getline(csv, line) && !line.empty() && line[0] == '#') {
  }  // the FEM's provenance lines, if any
  EXPECT_EQ(line.rfind("time_s,depth_mm,velocity_mm_per_s,force_N,tip_stretch,skin_state", 0), 0u) << line;
  while (std::getline(csv, line))
    if (!line.empty()) last = line;
  std::istringstream fields(last);
  std::string time, depth, velocity, force, stretch, skin;
  std::getline(fields, time, ',');
  std::getline(fields, depth, ',');
  std::getline(fields, velocity, ',');
  std::getline(fields, force, ',');
  std::getline(fields, stretch, ',');
  std::getline(fields, skin, ',');
  EXPECT_NEAR(std::stod(depth), scene.insertion.target_depth_m * 1e3, 1e-9);
  EXPECT_EQ(skin, "punctured");

  const auto stamp = fs::last_write_time(first.dir / "fem_summary.json");
  // A realtime-only change: same key, served from the cache, files untouched.
  Scene retuned = scene;
  retuned.layers[0].force_mesh.virtual_stiffness_N_per_m *= 4;
  retuned.realtime.sh_degree = 12;
  const validation::FemReference second = validation::obtain_fem_reference(retuned, coarse_options(cache), out);
  EXPECT_TRUE(second.from_cache);
  EXPECT_EQ(second.dir, first.dir);
  EXPECT_EQ(fs::last_write_time(first.dir / "fem_summary.json"), stamp);
  fs::remove_all(cache);
}

TEST(ValidateCommand, ReportOfASmallSceneAndSecondRunFromCache) {
  const fs::path work = fresh_dir("validate");
  fs::create_directories(work);
  const fs::path scene_file = work / "small.json";
  std::ofstream(scene_file) << scene_to_json_text(small_scene());
  ValidateOptions options;
  options.scene = scene_file;
  options.output_dir = work / "report";
  options.cache_dir = work / "cache";
  options.quiet = true;
  std::ostringstream out, err;
  ASSERT_EQ(validate_command(options, out, err), 0) << err.str();
  const fs::path dir = options.output_dir;
  for (const char* f : {"validation_summary.md", "layer_metrics.csv", "force_depth_aligned.csv",
                        "deflection_profiles.csv", "realtime_curve.csv", "fem_force_depth.csv", "fem_curve.csv",
                        "validation_metrics.json", "validation.pvd"})
    EXPECT_TRUE(fs::is_regular_file(dir / f)) << f;

  // The aligned table carries the FEM's own insertion samples and the real-time
  // force interpolated at the same depths (checked against both curve files).
  const validation::InsertionCurve fem = validation::read_insertion_curve(dir / "fem_curve.csv");
  const validation::InsertionCurve rt = validation::read_insertion_curve(dir / "realtime_curve.csv");
  std::vector<double> rt_depth, rt_force;
  for (std::size_t i : validation::insertion_phase(rt)) rt_depth.push_back(rt.depth_m[i]), rt_force.push_back(rt.force_N[i]);
  std::ifstream aligned(dir / "force_depth_aligned.csv");
  std::string line = test::header_after_provenance(aligned);
  EXPECT_EQ(line, "depth_mm,fem_force_N,realtime_force_N,difference_N");
  std::size_t rows = 0, checked = 0;
  const std::vector<std::size_t> fem_phase = validation::insertion_phase(fem);
  while (std::getline(aligned, line)) {
    ASSERT_LT(rows, fem_phase.size());
    std::istringstream s(line);
    std::string depth, f_fem, f_rt;
    std::getline(s, depth, ',');
    std::getline(s, f_fem, ',');
    std::getline(s, f_rt, ',');
    const std::size_t i = fem_phase[rows++];
    EXPECT_NEAR(std::stod(depth), fem.depth_m[i] * 1e3, 1e-9);
    EXPECT_NEAR(std::stod(f_fem), fem.force_N[i], 1e-9);
    // Linear interpolation by hand between the bracketing real-time ticks.
    const double d = fem.depth_m[i];
    for (std::size_t j = 0; j + 1 < rt_depth.size(); ++j)
      if (rt_depth[j] <= d && d <= rt_depth[j + 1]) {
        const double t = (d - rt_depth[j]) / (rt_depth[j + 1] - rt_depth[j]);
        EXPECT_NEAR(std::stod(f_rt), rt_force[j] + t * (rt_force[j + 1] - rt_force[j]), 1e-9);
        ++checked;
        break;
      }
  }
  EXPECT_EQ(rows, fem_phase.size());
  EXPECT_GT(checked, rows / 2);

  // ParaView collection: the FEM fields (part 0) and the real-time surfaces beside them.
  std::ifstream pvd_in(dir / "validation.pvd");
  std::stringstream pvd;
  pvd << pvd_in.rdbuf();
  EXPECT_NE(pvd.str().find("part=\"0\" file=\"fem/"), std::string::npos);
  EXPECT_NE(pvd.str().find("file=\"realtime/skin_surface_"), std::string::npos);

  // Provenance in every file of the report, also in the copies of the FEM's files.
  std::size_t with_provenance = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    std::ifstream in(e.path(), std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string ext = e.path().extension().string();
    if (ext == ".csv")
      EXPECT_EQ(text.rfind("# command: puncture", 0), 0u) << e.path();
    else if (ext == ".vtu" || ext == ".vtp")
      EXPECT_NE(text.find("provenance_command"), std::string::npos) << e.path();
    else if (ext == ".pvd" || ext == ".pvtu")
      EXPECT_NE(text.find("<!-- provenance: command: puncture"), std::string::npos) << e.path();
    else if (ext == ".json" || ext == ".md")
      EXPECT_NE(text.find("git"), std::string::npos) << e.path();
    else if (ext != ".png")
      ADD_FAILURE() << "unexpected report file " << e.path();
    ++with_provenance;
  }
  EXPECT_GT(with_provenance, 10u);

  // Summary: provenance and links.
  std::ifstream md_in(dir / "validation_summary.md");
  std::stringstream md;
  md << md_in.rdbuf();
  EXPECT_NE(md.str().find("git revision"), std::string::npos);
  EXPECT_NE(md.str().find("(layer_metrics.csv)"), std::string::npos);

  // Metrics: the skin breaks in the FEM; its deflection before breakthrough was compared.
  std::ifstream metrics_in(dir / "validation_metrics.json");
  const nlohmann::json metrics = nlohmann::json::parse(metrics_in);
  EXPECT_FALSE(metrics.at("fem_reference").at("from_cache").get<bool>());
  EXPECT_TRUE(metrics.at("layers").at(0).at("fem_punctured").get<bool>());
  EXPECT_TRUE(metrics.at("layers").at(0).contains("deflection"));
  // The acceptance per layer and the whole-trajectory terms, in both files.
  EXPECT_NE(md.str().find("Acceptance per layer"), std::string::npos);
  ASSERT_EQ(metrics.at("acceptance").size(), metrics.at("layers").size());
  const auto& skin = metrics["acceptance"][0];
  EXPECT_EQ(skin.at("layer"), "skin");
  EXPECT_EQ(skin.at("accepted").get<bool>(), skin["pressing_and_cut_force_rmse_relative"]["met"].get<bool>() &&
                                                 skin["puncture_depth_error_m"]["met"].get<bool>() &&
                                                 skin["puncture_force_error_relative"]["met"].get<bool>());
  // One definition per metric name: the per-layer pressing RMSE, the
  // acceptance's pressing-and-cut RMSE and the whole-insertion RMSE have
  // names of their own, in the JSON and in the report's table headers.
  EXPECT_TRUE(metrics["layers"][0].contains("pressing_force_rmse_relative"));
  EXPECT_FALSE(metrics["layers"][0].contains("force_rmse_relative"));
  EXPECT_FALSE(skin.contains("force_rmse_relative"));
  EXPECT_TRUE(metrics["overall"].contains("force_rmse_relative"));
  EXPECT_NE(md.str().find("| pressing force RMSE (N) | pressing RMSE / FEM peak |"), std::string::npos);
  EXPECT_NE(md.str().find("| force RMSE over pressing and cut / peak (limit"), std::string::npos);
  EXPECT_EQ(md.str().find("| force RMSE (N) |"), std::string::npos);
  bool has_overall = false;
  for (const auto& t : metrics.at("trajectory_terms")) has_overall |= t.at("term") == "overall";
  EXPECT_TRUE(has_overall);

  // Second validation of a retuned scene: the FEM comes from the cache.
  Scene retuned = small_scene();
  retuned.layers[0].force_mesh.virtual_stiffness_N_per_m *= 2;
  std::ofstream(scene_file) << scene_to_json_text(retuned);
  options.write_vtk = false;
  options.output_dir = work / "report2";
  ASSERT_EQ(validate_command(options, out, err), 0) << err.str();
  std::ifstream metrics2_in(options.output_dir / "validation_metrics.json");
  EXPECT_TRUE(nlohmann::json::parse(metrics2_in).at("fem_reference").at("from_cache").get<bool>());
  EXPECT_FALSE(fs::exists(options.output_dir / "validation.pvd"));
  fs::remove_all(work);
}
#endif

#ifdef PUNCTURE_HAVE_FEM
/// The columns of a CSV the program wrote, by header name (the "# ..." lines before the header skipped).
std::map<std::string, std::vector<std::string>> csv_columns(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line) && !line.empty() && line[0] == '#') {
  }
  std::vector<std::string> names;
  for (std::istringstream h(line); std::getline(h, line, ',');) names.push_back(line);
  std::map<std::string, std::vector<std::string>> columns;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    for (std::size_t c = 0; c < names.size() && std::getline(row, line, ','); ++c) columns[names[c]].push_back(line);
  }
  return columns;
}

/// The sweep's error of a real-time run against the FEM (sweep.hpp), computed here from the FEM's own CSV
/// and the run's ticks: at every FEM sample of the insertion (velocity > 0) whose depth is not recorded
/// twice (a force drop) and lies within the run's insertion, the run's force linearly interpolated at that
/// depth minus the FEM force; RMSE over those samples, and its ratio to the FEM's insertion peak |force|.
struct IndependentError {
  double force_rmse_N = 0.0, relative = 0.0;
  int samples = 0;
};
IndependentError error_against_fem_csv(const ScriptedRunResult& run, const fs::path& fem_csv) {
  auto columns = csv_columns(fem_csv);
  std::vector<double> depth, force;  // FEM insertion samples
  for (std::size_t i = 0; i < columns["force_N"].size(); ++i)
    if (std::stod(columns["velocity_mm_per_s"].at(i)) > 0.0)
      depth.push_back(std::stod(columns["depth_mm"][i]) * 1e-3), force.push_back(std::stod(columns["force_N"][i]));
  std::vector<double> run_depth, run_force;  // the run's insertion ticks (depth strictly rising)
  for (const TickResult& t : run.ticks)
    if (t.velocity_m_per_s > 0.0 && (run_depth.empty() || t.depth_m > run_depth.back()))
      run_depth.push_back(t.depth_m), run_force.push_back(t.total_force_N);
  IndependentError e;
  double sum_sq = 0.0, peak = 0.0;
  for (std::size_t i = 0; i < depth.size(); ++i) {
    peak = std::max(peak, std::abs(force[i]));
    const bool drop = (i > 0 && depth[i - 1] == depth[i]) || (i + 1 < depth.size() && depth[i + 1] == depth[i]);
    if (drop || depth[i] < run_depth.front() || depth[i] > run_depth.back()) continue;
    std::size_t hi = 1;
    while (hi + 1 < run_depth.size() && run_depth[hi] < depth[i]) ++hi;
    const double t = (depth[i] - run_depth[hi - 1]) / (run_depth[hi] - run_depth[hi - 1]);
    const double f = run_force[hi - 1] + t * (run_force[hi] - run_force[hi - 1]);
    sum_sq += (f - force[i]) * (f - force[i]);
    ++e.samples;
  }
  e.force_rmse_N = std::sqrt(sum_sq / e.samples);
  e.relative = e.force_rmse_N / peak;
  return e;
}

TEST(SweepCommand, TableOfEveryRealtimeKnobAgainstTheFem) {
  const fs::path work = fresh_dir("sweep");
  fs::create_directories(work);
  const fs::path scene_file = work / "small.json";
  std::ofstream(scene_file) << scene_to_json_text(small_scene());
  SweepOptions options;
  options.scene = scene_file;
  options.output_dir = work / "sweep";
  options.cache_dir = work / "cache";
  options.include_fem_knobs = false;
  options.quiet = true;
  std::ostringstream out, err;
  ASSERT_EQ(sweep_command(options, out, err), 0) << err.str();
  for (const char* f : {"accuracy_cost.csv", "accuracy_cost.md", "accuracy_cost.json"})
    EXPECT_TRUE(fs::is_regular_file(options.output_dir / f)) << f;
  std::ifstream csv(options.output_dir / "accuracy_cost.csv");
  std::string line = test::header_after_provenance(csv);
  EXPECT_EQ(line.rfind("model,knob,value,baseline,status,force_rmse_N", 0), 0u) << line;
  std::map<std::string, int> variants;
  int baselines = 0;
  std::vector<std::vector<std::string>> baseline_rows;
  while (std::getline(csv, line)) {
    std::vector<std::string> f;
    std::istringstream s(line);
    for (std::string x; std::getline(s, x, ',');) f.push_back(x);
    ASSERT_GE(f.size(), 13u) << line;
    ++variants[f[0] + ":" + f[1]];
    if (f[3] == "1") ++baselines;
    if (f[3] == "1" && f[0] == "realtime") baseline_rows.push_back(f);
    if (f[0] == "fem") {
      // The only FEM setting is the reference itself: zero error.
      EXPECT_EQ(std::stod(f[5]), 0.0);
      EXPECT_GT(std::stod(f[10]), 0.0);
    } else if (f[4] == "ok") {
      EXPECT_GT(std::stod(f[10]), 0.0) << "tick time, " << line;
      // p99 over the ticks with contact (a mean can exceed it: one preempted tick weighs on the mean only).
      EXPECT_GT(std::stod(f[11]), 0.0) << line;
      EXPECT_TRUE(std::isfinite(std::stod(f[5]))) << line;
    }
  }
  EXPECT_EQ(variants["fem:refinement_degree"], 1);
  EXPECT_GE(variants["realtime:sh_degree"], 5);
  EXPECT_GE(variants["realtime:rings_w_delta"], 4);
  EXPECT_EQ(variants["realtime:spacing_L_factor"], 5);
  EXPECT_EQ(variants["realtime:integrator"], 3);
  EXPECT_EQ(variants["realtime:haptic_rate_Hz"], 5);
  EXPECT_EQ(baselines, 6);  // one per knob

  // Each knob's baseline is the scene itself: the five real-time baseline rows have the same errors
  // (force RMSE, relative, depth error, punctures compared, missed), and those are the errors computed
  // here from the FEM's CSV in the cache and a run of the scene (to the 8 digits of the table).
  ASSERT_EQ(baseline_rows.size(), 5u);
  for (const auto& row : baseline_rows)
    for (std::size_t c = 5; c <= 9; ++c) EXPECT_EQ(row[c], baseline_rows[0][c]) << row[1] << " column " << c;
  fs::path fem_csv;
  for (const auto& entry : fs::recursive_directory_iterator(options.cache_dir))
    if (entry.path().filename() == "fem_force_depth.csv") fem_csv = entry.path();
  ASSERT_FALSE(fem_csv.empty()) << "no FEM curve in " << options.cache_dir;
  const Scene scene = small_scene();
  RealtimeModel model = build_realtime_model(scene);
  const IndependentError expected = error_against_fem_csv(run_scripted_insertion(model, scene), fem_csv);
  ASSERT_GT(expected.samples, 5);
  EXPECT_NEAR(std::stod(baseline_rows[0][5]), expected.force_rmse_N, 1e-6 * expected.force_rmse_N);
  EXPECT_NEAR(std::stod(baseline_rows[0][6]), expected.relative, 1e-6 * expected.relative);
  fs::remove_all(work);
}
#endif

TEST(ValidateCommand, BadSceneExitsWithTwoAndWritesNothing) {
  const fs::path work = fresh_dir("validate_bad");
  fs::create_directories(work);
  std::ofstream(work / "bad.json") << "{ \"schema_version\": 1, \"layers\": 3 }";
  ValidateOptions options;
  options.scene = work / "bad.json";
  options.output_dir = work / "report";
  options.cache_dir = work / "cache";
  options.quiet = true;
  std::ostringstream out, err;
  EXPECT_EQ(validate_command(options, out, err), 2);
  EXPECT_NE(err.str().find("bad.json"), std::string::npos) << err.str();
  EXPECT_FALSE(fs::exists(options.output_dir));
  EXPECT_FALSE(fs::exists(options.cache_dir));
  fs::remove_all(work);
}

TEST(ValidateCommand, CasesGiveOneReportPerCaseAndTheHeldOutSummary) {
  const fs::path work = fresh_dir("validate_cases");
  fs::create_directories(work);
  const fs::path scene_file = work / "small.json";
  std::ofstream(scene_file) << scene_to_json_text(small_scene());
  std::ofstream(work / "cases.json") << R"({"cases": [{"name": "own"},
      {"name": "fast", "overrides": {"insertion": {"speed_mm_per_s": 20, "withdrawal_speed_mm_per_s": 20}}}]})";
  ValidateOptions options;
  options.scene = scene_file;
  options.cases = work / "cases.json";
  options.model_note = "not calibrated";
  // A reason for every layer of both cases: each shows where its layer
  // misses; where it is accepted it is listed as stale, with a warning.
  std::ofstream(work / "why.json") << R"({"reasons": [
      {"case": "own", "layer": "skin", "why": "own skin"}, {"case": "own", "layer": "fat", "why": "own fat"},
      {"case": "own", "layer": "muscle", "why": "own muscle"}, {"case": "fast", "layer": "skin", "why": "fast skin"},
      {"case": "fast", "layer": "fat", "why": "fast fat"}, {"case": "fast", "layer": "muscle", "why": "fast muscle"}]})";
  options.why_misses = work / "why.json";
  options.output_dir = work / "report";
  options.cache_dir = work / "cache";
  options.write_vtk = false;
  options.quiet = true;
  std::ostringstream out, err;
  ASSERT_EQ(validate_command(options, out, err), 0) << err.str();
  const fs::path dir = options.output_dir;
  for (const char* c : {"own", "fast"}) {
    EXPECT_TRUE(fs::is_regular_file(dir / c / "validation_metrics.json")) << c;
    EXPECT_TRUE(fs::is_regular_file(dir / c / "scene.json")) << c;
    EXPECT_FALSE(fs::exists(dir / c / "validation.pvd")) << c;  // --no-vtk
  }
  // The case's scene is the model's with the override, and its report ran at that speed.
  const Scene fast = load_scene(dir / "fast" / "scene.json");
  EXPECT_DOUBLE_EQ(fast.insertion.speed_m_per_s, 0.02);
  const validation::InsertionCurve curve = validation::read_insertion_curve(dir / "fast" / "realtime_curve.csv");
  double fastest = 0.0;
  for (double v : curve.velocity_m_per_s) fastest = std::max(fastest, v);
  EXPECT_NEAR(fastest, 0.02, 1e-9);

  std::ifstream in(dir / "heldout_summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  ASSERT_EQ(summary["cases"].size(), 2u);
  EXPECT_EQ(summary["cases"][0]["name"], "own");
  EXPECT_FALSE(summary["cases"][0]["held_out"].get<bool>());
  EXPECT_TRUE(summary["cases"][1]["held_out"].get<bool>());
  EXPECT_EQ(summary["model_note"], "not calibrated");
  std::size_t accepted = 0;
  for (const auto& c : summary["cases"]) {
    ASSERT_EQ(c["layers"].size(), 3u);
    // Each row agrees with that case's own report.
    std::ifstream m(dir / c["name"].get<std::string>() / "validation_metrics.json");
    const nlohmann::json metrics = nlohmann::json::parse(m);
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(c["layers"][k]["accepted"].get<bool>(), metrics["acceptance"][k]["accepted"].get<bool>());
      const std::string expected_why = c["name"].get<std::string>() + " " + c["layers"][k]["layer"].get<std::string>();
      if (c["layers"][k]["accepted"].get<bool>()) {
        EXPECT_TRUE(c["layers"][k]["why"].is_null());
        ++accepted;
      } else {
        EXPECT_EQ(c["layers"][k]["why"], expected_why);
      }
    }
  }
  EXPECT_EQ(summary["stale_reasons"].size(), accepted);
  EXPECT_EQ(err.str().find("is accepted now") != std::string::npos, accepted > 0) << err.str();
  EXPECT_EQ(summary["reasons_file"], (work / "why.json").string());
  EXPECT_TRUE(fs::is_regular_file(dir / "heldout_summary.md"));
  fs::remove_all(work);
}

TEST(ValidateCommand, BadCasesFileExitsWithTwoAndWritesNothing) {
  const fs::path work = fresh_dir("validate_bad_cases");
  fs::create_directories(work);
  const fs::path scene_file = work / "small.json";
  std::ofstream(scene_file) << scene_to_json_text(small_scene());
  // The second case overrides a thickness count the scene does not have:
  // found before any FEM runs or any report is written.
  std::ofstream(work / "cases.json") << R"({"cases": [{"name": "own"},
      {"name": "slab", "overrides": {"layer_thickness_mm": [1, 2]}}]})";
  ValidateOptions options;
  options.scene = scene_file;
  options.cases = work / "cases.json";
  options.output_dir = work / "report";
  options.cache_dir = work / "cache";
  options.quiet = true;
  std::ostringstream out, err;
  EXPECT_EQ(validate_command(options, out, err), 2);
  EXPECT_NE(err.str().find("case slab"), std::string::npos) << err.str();
  EXPECT_NE(err.str().find("layer_thickness_mm"), std::string::npos) << err.str();
  EXPECT_FALSE(fs::exists(options.output_dir));
  EXPECT_FALSE(fs::exists(options.cache_dir));

  // A reasons file naming a layer the model does not have: the same, before any FEM.
  std::ofstream(work / "cases.json") << R"({"cases": [{"name": "own"}]})";
  std::ofstream(work / "why.json") << R"({"reasons": [{"case": "own", "layer": "bone", "why": "w"}]})";
  options.why_misses = work / "why.json";
  std::ostringstream err2;
  EXPECT_EQ(validate_command(options, out, err2), 2);
  EXPECT_NE(err2.str().find("why.json: /reasons/0/layer"), std::string::npos) << err2.str();
  EXPECT_FALSE(fs::exists(options.output_dir));
  EXPECT_FALSE(fs::exists(options.cache_dir));
  // --why-misses without --cases: a usage error.
  options.cases.clear();
  std::ostringstream err3;
  EXPECT_NE(validate_command(options, out, err3), 0);
  EXPECT_NE(err3.str().find("--why-misses"), std::string::npos) << err3.str();
  EXPECT_FALSE(fs::exists(options.output_dir));
  fs::remove_all(work);
}

}  // namespace
}  // namespace puncture::apps
