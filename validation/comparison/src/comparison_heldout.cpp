// comparison_heldout.cpp: every identified model on the held-out cases; see
// comparison_heldout.hpp.
#include "comparison_heldout.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>

#include "comparison_runs.hpp"
#include "comparison_tables.hpp"
#include "side_by_side.hpp"
#include "puncture/comparison/model_factory.hpp"
#include "puncture/comparison/sparse_spd_factor.hpp"
#include "puncture/meshing/comparison_tet_slab_mesh.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/validation_cases.hpp"

namespace puncture::validation::comparison_report_detail {

namespace {

constexpr double kMm = 1e-3;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kHeldOutThreads = 2;

/// One case as the models see it: its base scene, its FEM reference and, if
/// a volumetric model is compared, its own tetrahedral mesh (slab and depth).
struct CaseSetup {
  Scene base;
  ComparisonReference reference;
  std::shared_ptr<const meshing::TetMesh> mesh;
};

CaseSetup setup_case(const ComparisonCase& c, const Scene& scene, const std::map<std::string, Scene>& model_scenes) {
  CaseSetup setup;
  setup.base = case_scene(scene_to_json_text(scene), scene.name, c.validation_case).scene;
  setup.reference = read_comparison_reference(setup.base, c.fem.dir);
  if (std::any_of(model_scenes.begin(), model_scenes.end(),
                  [](const auto& m) { return comparison::is_volumetric_model(m.first); }))
    setup.mesh = std::make_shared<meshing::TetMesh>(meshing::build_comparison_tet_mesh(setup.base));
  return setup;
}

/// One model on one case: its row.
HeldOutRow run_model_on_case(const ComparisonCase& c, const CaseSetup& setup, const std::string& key,
                             const Scene& identified_scene, const std::function<void()>& check_interrupt) {
  const auto start = std::chrono::steady_clock::now();
  const Scene model_scene = case_scene(scene_to_json_text(identified_scene), key + " model scene", c.validation_case).scene;
  std::unique_ptr<comparison::ComparisonModel> model =
      comparison::make_comparison_model(key, model_scene, comparison::is_volumetric_model(key) ? setup.mesh : nullptr);
  ModelRunOptions run_options;
  run_options.profile_depths_m = setup.reference.profile_depths_m;
  run_options.profile_radii_m = setup.reference.profile_radii_m;
  run_options.measure_inversion = true;
  if (check_interrupt) run_options.on_progress = [&check_interrupt](double) { check_interrupt(); };
  ModelRun run = run_comparison_model(*model, model_scene, run_options);
  run.model = key;
  HeldOutRow row;
  row.case_name = c.validation_case.name;
  row.held_out = c.validation_case.held_out;
  row.metrics = metrics_against_reference(model_scene, run, setup.reference.data, trajectory_steps(model_scene));
  row.failure = run.failure;
  row.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return row;
}

double mean_of_finite(const std::vector<double>& values) {
  double sum = 0.0;
  int n = 0;
  for (double v : values)
    if (std::isfinite(v)) sum += v, ++n;
  return n > 0 ? sum / n : kNaN;
}

}  // namespace

std::vector<HeldOutRow> run_heldout_cases(const Scene& scene, const std::map<std::string, Scene>& model_scenes,
                                          const ComparisonReportOptions& options, std::ostream& out,
                                          std::ostream& err, const std::vector<std::function<void()>>& first_jobs) {
  // Every (held-out case, model) pair is one independent run; they share
  // nothing but the case's mesh and reference (read only), so they run two
  // at a time (one per core of the reference machine). A case that is not
  // held out is the calibration trajectory: the main table's runs.
  std::vector<CaseSetup> setups(options.cases.size());
  std::vector<std::pair<std::size_t, std::string>> jobs;
  for (std::size_t i = 0; i < options.cases.size(); ++i) {
    if (!options.cases[i].validation_case.held_out) continue;
    setups[i] = setup_case(options.cases[i], scene, model_scenes);
    for (const std::string& key : options.models)
      if (model_scenes.count(key)) jobs.emplace_back(i, key);  // not "fem"
  }
  std::vector<HeldOutRow> rows(jobs.size());
  std::mutex report_mutex;
  const std::size_t first = first_jobs.size();
  run_side_by_side(first + jobs.size(), comparison::concurrent_solver_threads(kHeldOutThreads), [&](std::size_t i) {
    if (i < first) return first_jobs[i]();
    const std::size_t j = i - first;
    const ComparisonCase& c = options.cases[jobs[j].first];
    const std::string& key = jobs[j].second;
    if (!options.quiet) {
      const std::lock_guard<std::mutex> lock(report_mutex);
      out << "[compare] case " << c.validation_case.name << ": " << key << " ...\n" << std::flush;
    }
    try {
      rows[j] = run_model_on_case(c, setups[jobs[j].first], key, model_scenes.at(key), options.check_interrupt);
    } catch (const std::exception& e) {  // the model could not be built on this case, or an interrupt
      rows[j].case_name = c.validation_case.name;
      rows[j].held_out = c.validation_case.held_out;
      rows[j].metrics.model = key;
      rows[j].failure = e.what();
    }
    // An interrupt (which throws again at every check once raised) ends the phase here.
    if (options.check_interrupt) options.check_interrupt();
    if (!rows[j].failure.empty()) {
      const std::lock_guard<std::mutex> lock(report_mutex);
      err << "warning: " << key << " failed on case " << c.validation_case.name << " " << rows[j].failure << "\n";
    }
  });
  return rows;
}

std::string heldout_csv(const Scene& scene, const std::vector<HeldOutRow>& rows) {
  std::ostringstream csv;
  csv << "case,held_out,model,force_rmse_relative,peak_force_error_relative,puncture_depth_error_mm,"
         "puncture_layers_disagreeing";
  for (const Layer& l : scene.layers) csv << ',' << l.name << "_puncture_mm," << l.name << "_fem_puncture_mm";
  csv << ",deflection_rmse_relative,step_time_mean_ms,step_time_p99_ms,memory_MB,completed_fraction,"
         "inverted_share_max,first_inversion_depth_mm,min_volume_ratio,failure\n";
  for (const HeldOutRow& r : rows) {
    const ModelMetrics& m = r.metrics;
    csv << r.case_name << ',' << (r.held_out ? "true" : "false") << ',' << m.model << ',' << fmt(m.force_rmse_relative)
        << ',' << fmt(m.peak_force_error_relative) << ',' << fmt(m.puncture_depth_error_m / kMm) << ','
        << m.puncture_layers_disagreeing;
    for (const LayerPunctureComparison& p : m.punctures)
      csv << ',' << fmt(p.model_depth_m / kMm) << ',' << fmt(p.reference_depth_m / kMm);
    csv << ',' << fmt(m.deflection_rmse_relative) << ',' << fmt(m.step_time_mean_s * 1e3) << ','
        << fmt(m.step_time_p99_s * 1e3) << ',' << fmt(m.memory_bytes / 1e6) << ',' << fmt(m.completed_fraction)
        << ',' << fmt(m.inverted_share_max) << ',' << fmt(m.first_inversion_depth_m / kMm) << ','
        << fmt(m.min_volume_ratio) << ",\"" << r.failure << "\"\n";
  }
  return csv.str();
}

std::vector<ModelMetrics> aggregate_heldout(const std::vector<HeldOutRow>& rows, const std::vector<std::string>& models) {
  std::vector<ModelMetrics> out;
  for (const std::string& key : models) {
    std::vector<double> force, peak, depth, deflection, p99, mean_step, memory, completed;
    std::vector<LayerPunctureComparison> punctures;
    int disagreeing = 0;
    for (const HeldOutRow& r : rows) {
      if (!r.held_out || r.metrics.model != key) continue;
      force.push_back(r.metrics.force_rmse_relative);
      peak.push_back(std::abs(r.metrics.peak_force_error_relative));
      depth.push_back(r.metrics.puncture_depth_error_m);
      deflection.push_back(r.metrics.deflection_rmse_relative);
      p99.push_back(r.metrics.step_time_p99_s);
      mean_step.push_back(r.metrics.step_time_mean_s);
      memory.push_back(r.metrics.memory_bytes);
      completed.push_back(r.metrics.completed_fraction);
      punctures.insert(punctures.end(), r.metrics.punctures.begin(), r.metrics.punctures.end());
      disagreeing += r.metrics.puncture_layers_disagreeing;
    }
    if (force.empty()) continue;
    ModelMetrics m;
    m.model = key;
    m.punctures = punctures;  // every layer of every case: the ranking's puncture metric is their mean
    m.puncture_layers_disagreeing = disagreeing;
    m.force_rmse_relative = mean_of_finite(force);
    m.peak_force_error_relative = mean_of_finite(peak);
    m.puncture_depth_error_m = mean_of_finite(depth);
    m.deflection_rmse_relative = mean_of_finite(deflection);
    m.step_time_mean_s = mean_of_finite(mean_step);
    m.step_time_p99_s = *std::max_element(p99.begin(), p99.end(), [](double a, double b) {
      return std::isfinite(b) && (!std::isfinite(a) || a < b);
    });
    m.memory_bytes = *std::max_element(memory.begin(), memory.end());
    m.completed_fraction = *std::min_element(completed.begin(), completed.end());
    out.push_back(m);
  }
  return out;
}

}  // namespace puncture::validation::comparison_report_detail
