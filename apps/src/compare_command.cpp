// `puncture compare`: the comparison models of both seed papers and the
// real-time model on the identical insertion (same scene: slab, needle,
// trajectory), measured against the FEM reference (cached), graded by the
// paper's Sec. 3.3 method.
//
// This file parses and checks the options and calls the library; the report
// itself (mesh, model runs, identification, metrics, grading, every output
// file) is validation/comparison's write_model_comparison
// (puncture/validation/comparison_report.hpp).
//
// Algorithm (top-down):
//   1. check the options; load the scene and the Delphi weights file;
//   2. obtain the FEM reference (cache or solve; MPI ranks other than 0 stop
//      after it);
//   3. with --cases, the FEM reference of every case (the scene with the
//      case's overrides);
//   4. write_model_comparison: the tetrahedral mesh if a volumetric model
//      needs it, every model's critical forces identified against the FEM,
//      every model run, the optional mass-spring identification, the held-out
//      cases, metrics against the FEM, grading and the report files;
//   5. one summary line per model on `out`.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <set>

#include "command_errors.hpp"
#include "measured_reference.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/comparison/model_factory.hpp"
#include "puncture/io/atomic_file.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/comparison_report.hpp"
#include "puncture/validation/fem_reference.hpp"
#include "puncture/validation/number_format.hpp"
#include "puncture/validation/validation_cases.hpp"

namespace puncture::apps {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string shown(double x) { return std::isfinite(x) ? validation::significant_digits(x, 3) : "n/a"; }

std::string joined(const std::vector<std::string>& v, const std::string& separator) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : separator) + x;
  return s;
}

/// Every model's key: the comparison models and the FEM reference.
std::vector<std::string> all_model_names() {
  std::vector<std::string> names = comparison::comparison_model_names();
  names.push_back("fem");
  return names;
}

/// Bad --models, --identify or --frames: UsageError (exit 2) naming the option.
void check_options(const CompareOptions& options, const std::vector<std::string>& models) {
  const std::vector<std::string> known = all_model_names();
  std::set<std::string> seen;
  for (const std::string& m : models) {
    if (std::find(known.begin(), known.end(), m) == known.end())
      throw UsageError("--models: unknown model '" + m + "' (known: " + joined(known, ", ") + ")");
    if (!seen.insert(m).second) throw UsageError("--models: '" + m + "' listed twice");
  }
  for (const std::string& method : options.identify)
    if (method != "simulated_annealing" && method != "isres")
      throw UsageError("--identify: unknown method '" + method + "' (known: simulated_annealing, isres)");
  if (options.frames < 0) throw UsageError("--frames must be >= 0");
}

/// --cases: each case's FEM reference (the scene with the case's overrides;
/// cache or solve). Every case is checked before the first FEM runs.
std::vector<validation::ComparisonCase> case_references(const std::filesystem::path& scene_path,
                                                        const std::filesystem::path& cases_path,
                                                        const validation::FemReferenceOptions& fem_options,
                                                        std::ostream& out) {
  validation::ValidationCases cases;
  std::vector<Scene> scenes;
  try {
    cases = validation::read_validation_cases(cases_path);
    const std::string scene_text = io::read_text_file(scene_path);
    for (const validation::ValidationCase& c : cases.cases)
      scenes.push_back(validation::case_scene(scene_text, scene_path.string(), c).scene);
  } catch (const std::invalid_argument& e) {  // SceneError is a runtime_error: it passes through
    throw InputError(e.what());
  }
  std::vector<validation::ComparisonCase> references;
  for (std::size_t i = 0; i < cases.cases.size(); ++i) {
    out << "[compare] FEM reference of case " << i + 1 << "/" << cases.cases.size() << ": " << cases.cases[i].name
        << "\n" << std::flush;
    const auto start = std::chrono::steady_clock::now();
    const validation::FemReference fem = validation::obtain_fem_reference(scenes[i], fem_options, out);
    references.push_back({cases.cases[i], {fem.dir, fem.hash, fem.from_cache, seconds_since(start)}});
  }
  return references;
}

/// The command as given: every option that changes the outputs (provenance).
std::string compare_command_line(const CompareOptions& options, const std::filesystem::path& scene_path,
                                 const std::filesystem::path& dir) {
  std::string command_line = "puncture compare " + scene_path.string();
  if (!options.models.empty()) command_line += " --models " + joined(options.models, ",");
  command_line += " -o " + dir.string();
  if (!options.cache_dir.empty()) command_line += " --cache " + options.cache_dir.string();
  if (!options.weights.empty()) command_line += " --weights " + options.weights.string();
  if (!options.identify.empty())
    command_line += " --identify " + joined(options.identify, ",") + " --identify-evaluations " +
                    std::to_string(options.identify_evaluations);
  if (options.scene_parameters) command_line += " --scene-parameters";
  if (options.critical_forces_only) command_line += " --critical-forces-only";
  if (!options.cases.empty()) command_line += " --cases " + options.cases.string();
  if (options.frames != CompareOptions{}.frames) command_line += " --frames " + std::to_string(options.frames);
  if (!options.write_vtk) command_line += " --no-vtk";
  return command_line;
}

void print_summary(const validation::ComparisonOutcome& outcome, const CompareOptions& options,
                   const std::filesystem::path& dir, std::ostream& out) {
  out << "\nModel comparison against the FEM (" << (outcome.has_shaft_forces ? "total force" : "contact force")
      << "):\n";
  for (std::size_t i = 0; i < outcome.metrics.size(); ++i)
    out << "  " << std::left << std::setw(26) << outcome.metrics[i].model << std::right << " force RMSE "
        << std::setw(8) << shown(outcome.metrics[i].force_rmse_relative) << " of the FEM peak, step p99 "
        << std::setw(9) << shown(outcome.metrics[i].step_time_p99_s * 1e3) << " ms, score "
        << shown(outcome.grade.final_scores[i]) << " (rank " << outcome.grade.rank[i] << ")\n";
  if (!outcome.heldout_metrics.empty()) {
    out << "Ranking on the held-out cases:\n";
    for (std::size_t i = 0; i < outcome.heldout_metrics.size(); ++i)
      out << "  " << std::left << std::setw(26) << outcome.heldout_metrics[i].model << std::right << " force RMSE "
          << std::setw(8) << shown(outcome.heldout_metrics[i].force_rmse_relative) << " of the FEM peak, score "
          << shown(outcome.heldout_grade.final_scores[i]) << " (rank " << outcome.heldout_grade.rank[i] << ")\n";
  }
  out << "Outputs in " << dir.string() << "/ (comparison.md, comparison.csv, ranking.csv"
      << (options.write_vtk ? ", comparison.pvd" : "") << ")\n";
}

}  // namespace

std::filesystem::path default_delphi_weights_path() {
  return default_scene_path().parent_path() / "delphi_weights.json";
}

int compare_command(const CompareOptions& options, std::ostream& out, std::ostream& err) {
  const std::filesystem::path scene_path = options.scene.empty() ? default_scene_path() : options.scene;
  return report_errors(err, scene_path.string(), [&]() -> int {
    validation::ComparisonReportOptions report;
    report.wall_start = std::chrono::steady_clock::now();
    const Scene scene = load_scene(scene_path);
    require_axial_for_fem(scene, scene_path.string(), "the comparison (its FEM reference and models)");
    report.models = options.models.empty() ? all_model_names() : options.models;
    check_options(options, report.models);
    report.weights_path = options.weights.empty() ? default_delphi_weights_path() : options.weights;
    const validation::DelphiWeights weights = [&] {
      try {  // a missing or malformed weights file is bad input (exit 2); the message names it
        return validation::read_delphi_weights(report.weights_path);
      } catch (const std::exception& e) {
        throw InputError(e.what());
      }
    }();
    report.output_dir =
        options.output_dir.empty() ? std::filesystem::path("out") / (scene.name + "_comparison") : options.output_dir;

    // The FEM reference (all MPI ranks help; only rank 0 goes on).
    validation::FemReferenceOptions fem_options;
    if (!options.cache_dir.empty()) fem_options.cache_dir = options.cache_dir;
    fem_options.verbose = !options.quiet;
    fem_options.on_step = options.fem_step;
    // The FEM's fields are needed for the ParaView output only: with --no-vtk
    // a cached reference without them is used as it is (as validate does).
    fem_options.write_vtu = options.write_vtk;
    const auto reference_start = std::chrono::steady_clock::now();
    const validation::FemReference reference = validation::obtain_fem_reference(scene, fem_options, out);
    const double reference_wall_time_s = seconds_since(reference_start);
    if (!options.cases.empty()) {
      report.cases = case_references(scene_path, options.cases, fem_options, out);
      report.cases_file = options.cases.string();
    }
    if (!validation::is_mpi_root()) return 0;

    report.identify = options.identify;
    report.identify_evaluations = options.identify_evaluations;
    report.identify_models = !options.scene_parameters;
    report.identify_stiffness = !options.critical_forces_only;
    report.frames = options.frames;
    report.write_vtk = options.write_vtk;
    report.quiet = options.quiet;
    report.check_interrupt = options.model_step;
    report.command_line = compare_command_line(options, scene_path, report.output_dir);
    const validation::ComparisonOutcome outcome = validation::write_model_comparison(
        scene, weights, {reference.dir, reference.hash, reference.from_cache, reference_wall_time_s}, report, out, err);
    print_summary(outcome, options, report.output_dir, out);
    return 0;
  });
}

}  // namespace puncture::apps
