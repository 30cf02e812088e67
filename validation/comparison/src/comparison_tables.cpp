// The text files of `puncture compare` (see comparison_tables.hpp).
#include "comparison_tables.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "puncture/comparison/sparse_spd_factor.hpp"
#include "puncture/meshing/tet_mesh.hpp"
#include "puncture/validation/number_format.hpp"

namespace puncture::validation::comparison_report_detail {

namespace {

constexpr double kMm = 1e-3;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// comparison.md: title, command and machine, the FEM reference, the mesh.
void markdown_header(std::ostringstream& md, const ComparisonContent& c) {
  const nlohmann::json& provenance = c.provenance;
  const FemResultFiles& fem = c.reference.fem;
  md << "# Model comparison: " << c.scene.name << "\n\n"
     << "Made by `" << c.options.command_line << "` on " << provenance["machine"].get<std::string>() << ", "
     << provenance["date_utc"].get<std::string>() << " (puncture " << provenance["program_version"].get<std::string>()
     << ", git " << provenance["git_revision"].get<std::string>() << "); wall time " << shown(c.wall_time_s, 4)
     << " s.\n\n"
     << "FEM reference: cache key `" << c.fem_entry.hash << "` ("
     << (c.fem_entry.from_cache ? "from the cache" : "computed now") << "), " << fem.summary.value("n_dofs", 0L)
     << " dofs, " << fem.summary.value("load_steps", 0L) << " load steps in "
     << shown(fem.summary.value("wall_time_s", kNaN), 4) << " s. "
     << (c.reference.data.has_shaft_forces
             ? "Its curve has cutting/friction columns: every model's force includes the same shaft forces (cutting, Karnopp friction and Table 1's d h v)."
             : "Its curve is quasi-static and frictionless (no cutting/friction columns): the "
               "models' contact force is compared, without Table 1's post-puncture d h v.")
     << "\n\n";
  if (c.mesh.mesh)
    md << "Tetrahedral mesh (" << c.mesh.report.kind << ": " << c.mesh.report.description
       << "): " << c.mesh.report.vertices << " vertices, " << c.mesh.report.tetrahedra
       << " tetrahedra; " << meshing::describe(c.mesh.report.quality) << ".\n\n";
}

/// The inverted-tetrahedra cell: "n/a" without a tetrahedral mesh, "0 (J >=
/// 0.31)" when none inverted, else "4.4 % (3.0; J >= -1.7)" (with_depth) or
/// "4.4 % (J >= -1.7)".
std::string inversion_cell(const ModelMetrics& m, bool with_depth) {
  if (!std::isfinite(m.inverted_share_max)) return "n/a";
  const std::string j = "J >= " + shown(m.min_volume_ratio, 2);
  if (m.inverted_share_max == 0.0) return "0 (" + j + ")";
  return shown(100.0 * m.inverted_share_max, 2) + " % (" +
         (with_depth ? shown(m.first_inversion_depth_m / kMm, 3) + "; " : std::string()) + j + ")";
}

/// comparison.md: one row per model, then the ranking.
void markdown_metrics(std::ostringstream& md, const ComparisonContent& c) {
  md << "| model | dofs | memory MB | force RMSE / FEM peak | peak force error | puncture depth error mm | "
        "skin deflection RMSE / max | inverted tetrahedra, most (first at depth mm) | step mean ms | step p99 ms |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const ModelMetrics& m : c.rows.metrics)
    md << "| " << m.model << " | " << m.dofs << " | " << shown(m.memory_bytes / 1e6) << " | "
       << shown(m.force_rmse_relative) << " | " << shown(m.peak_force_error_relative) << " | "
       << shown(m.puncture_depth_error_m / kMm)
       << (m.puncture_layers_disagreeing
               ? " (" + std::to_string(m.puncture_layers_disagreeing) + " layer(s) broken by one only)"
               : "")
       << " | " << shown(m.deflection_rmse_relative) << " | " << inversion_cell(m, true) << " | "
       << shown(m.step_time_mean_s * 1e3) << " | " << shown(m.step_time_p99_s * 1e3) << " |\n";
  md << "\nTimes per step are over the steps with the tip in the tissue; the FEM's is its wall time per load step. "
        "Inverted tetrahedra: the largest share of the volumetric models' remaining tetrahedra with J = V / V0 <= 0 "
        "(turned inside out; sampled every " << kInversionSampleSteps << " haptic steps), the needle depth where the "
        "first appeared and the smallest J; no elastic body passes through such a state, and the FEM's Newton "
        "rejects one (n/a: no tetrahedral mesh).\n\n";
  if (c.heldout.empty()) {
    md << "## Ranking (seed paper Sec. 3.3)\n\n" << ranking_markdown(c.grade, c.weights) << "\n";
  } else {
    md << "## Ranking on the calibration trajectory (in sample, seed paper Sec. 3.3)\n\nNot the ranking: every "
          "model's critical forces were identified on this trajectory. The ranking is the held-out one below.\n\n"
       << ranking_markdown(c.grade, c.weights) << "\n";
  }
}

/// comparison.md: one row per held-out case and model, then the ranking on
/// the held-out metrics (nothing without cases).
void markdown_heldout(std::ostringstream& md, const ComparisonContent& c) {
  if (c.heldout.empty()) return;
  md << "## Held-out cases\n\nEvery model as identified on the calibration trajectory, run without retuning on the "
        "held-out cases of `" << c.options.cases_file << "` against each case's FEM (the calibration trajectory is the "
        "table above).\n\n"
        "| case | held out | model | force RMSE / FEM peak | peak force error | puncture depth error mm | ";
  for (const Layer& l : c.scene.layers) md << l.name << " puncture mm (FEM) | ";
  md << "skin deflection RMSE / max | inverted tetrahedra, most | step p99 ms |\n|---|---|---|---|---|---|";
  for (std::size_t k = 0; k < c.scene.layers.size(); ++k) md << "---|";
  md << "---|---|---|\n";
  for (const HeldOutRow& r : c.heldout) {
    const ModelMetrics& m = r.metrics;
    md << "| " << r.case_name << " | " << (r.held_out ? "yes" : "no") << " | " << m.model << " | "
       << shown(m.force_rmse_relative) << " | " << shown(m.peak_force_error_relative) << " | "
       << shown(m.puncture_depth_error_m / kMm) << " | ";
    for (const LayerPunctureComparison& p : m.punctures)
      md << shown(p.model_depth_m / kMm, 4) << " (" << shown(p.reference_depth_m / kMm, 4) << ") | ";
    md << shown(m.deflection_rmse_relative) << " | " << inversion_cell(m, false) << " | "
       << shown(m.step_time_p99_s * 1e3) << " |\n";
  }
  md << "\n## Ranking on the held-out cases (seed paper Sec. 3.3)\n\nPer model the mean over the held-out cases of "
        "the force RMSE, |peak force error|, puncture depth error (every layer of every case) and deflection RMSE, "
        "the largest step p99 and the smallest completed fraction; the FEM's row is the reference (no error by "
        "definition, its in-sample time per load step).\n\n"
     << ranking_markdown(c.outcome.heldout_grade, c.weights) << "\n";
}

/// The window RMSE column: "before -> after", or why the factor was not
/// fitted (fewer than two reference samples while the FEM presses the layer).
std::string window_rmse_cell(const nlohmann::json& layer) {
  const auto samples = layer.value("window_samples", std::size_t{0});
  if (samples < 2) return "not fitted (" + std::to_string(samples) + " FEM samples while pressed)";
  return shown(layer.value("window_rmse_before_N", kNaN)) + " -> " + shown(layer.value("window_rmse_after_N", kNaN));
}

/// comparison.md: the identified stiffness factors and critical forces, one row per model and layer.
void markdown_model_identification(std::ostringstream& md, const nlohmann::json& identification) {
  if (identification.empty()) return;
  md << "## Every model identified against the FEM\n\nEvery model but the real-time one (which `puncture calibrate` "
        "tunes) gets, layer by layer on the calibration trajectory, a factor on its Young's modulus (least squares "
        "on the force while the FEM presses the layer, bottom up, then jointly) and the critical contact force at which it breaks the layer "
        "(its force where the FEM punctures it); one or two partial runs of the full model per layer "
        "(model_identification.hpp). On this trajectory the punctures then agree with the FEM's by construction; "
        "the held-out cases test them.\n\n| model | layer | FEM puncture depth mm | stiffness factor | force RMSE "
        "while pressed N (factor 1 -> identified) | critical force N | model runs | wall time s |\n"
        "|---|---|---|---|---|---|---|---|\n";
  for (const auto& [model, record] : identification.items())
    for (const auto& layer : record["layers"]) {
      md << "| " << model << " | " << layer["layer"].get<std::string>() << " | "
         << shown(layer.value("reference_depth_mm", kNaN), 4) << " | ";
      if (layer.value("identified", false))
        md << shown(layer["stiffness_scale"].get<double>(), 4)
           << (layer.contains("stiffness_scale_near_bound")
                   ? " (near the search's bound " + shown(layer["stiffness_scale_near_bound"].get<double>(), 4) +
                         ": the factor absorbs what the model lacks)"
                   : std::string())
           << " | " << window_rmse_cell(layer) << " | "
           << shown(layer["critical_force_N"].get<double>(), 4);
      else
        md << "- | - | not identified: " << layer.value("note", std::string());
      md << " | " << record["model_runs"].get<int>() << " | " << shown(record["wall_time_s"].get<double>()) << " |\n";
    }
  md << "\n";
  bool any_joint = false;
  for (const auto& [model, record] : identification.items())
    if (record.contains("joint_fit")) {
      if (!any_joint)
        md << "Where two or more factors were fitted, the joint fit on all their windows after the bottom-up pass "
              "(where it ran, the factors and the \"after\" column above are its result; it stops after one run "
              "when no window moved with the other layers' factors):\n\n";
      any_joint = true;
      md << "- " << model << ": " << record["joint_fit"].get<std::string>() << "\n";
    }
  if (any_joint) md << "\n";
}

/// comparison.md: one row per identification method (nothing without one).
void markdown_identification(std::ostringstream& md, const nlohmann::json& identification) {
  if (identification.empty()) return;
  md << "## Mass-spring identification\n\n| method | factors before | factors after | objective before | "
        "objective after | force RMSE before | after | evaluations | wall time s |\n|---|---|---|---|---|---|---|---|---|\n";
  auto list = [](const nlohmann::json& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + fmt(x.get<double>(), 3);
    return s;
  };
  for (const auto& j : identification)
    md << "| " << j["library"].get<std::string>() << " | " << list(j["scale_before"]) << " | " << list(j["scale_after"])
       << " | " << shown(j["objective_before"].get<double>()) << " | " << shown(j["objective_after"].get<double>())
       << " | " << shown(j["force_rmse_relative_before"].get<double>()) << " | "
       << shown(j["force_rmse_relative_after"].get<double>()) << " | " << j["evaluations"].get<int>() << " | "
       << shown(j["wall_time_s"].get<double>(), 4) << " |\n";
  md << "\n";
}

/// comparison.md: where the wall time went (time_budget).
void markdown_time_budget(std::ostringstream& md, const ComparisonContent& c) {
  const std::string limit = comparison::concurrent_solver_limit();
  md << "## Where the time goes\n\nWall time of this command by phase ("
     << (limit.empty() ? "the identifications two models at a time, each optimiser's runs two at a time; the "
                         "volumetric models' calibration-trajectory runs and the held-out runs two at a time; "
                         "everything else on one core"
                       : "every model run one at a time: " + limit)
     << ").\n\n| phase | wall time s | share | note |\n|---|---|---|---|\n";
  for (const TimeBudgetEntry& e : time_budget(c))
    md << "| " << e.phase << " | " << shown(e.wall_time_s, 4) << " | " << shown(100.0 * e.wall_time_s / c.wall_time_s, 2)
       << " % | " << e.note << " |\n";
  md << "| **total** | **" << shown(c.wall_time_s, 4) << "** | 100 % | |\n\n";
}

/// comparison.md: the models' descriptions, the plots, the files.
void markdown_models_and_files(std::ostringstream& md, const ComparisonContent& c,
                               const std::vector<std::string>& plots) {
  md << "## Models\n\n";
  for (std::size_t i = 0; i < c.rows.metrics.size(); ++i)
    md << "- **" << c.rows.metrics[i].model << "**: " << c.rows.descriptions[i] << "\n";
  for (const auto& run : c.runs)
    if (!run->integrator_report.empty()) md << "- " << run->model << " integration: " << run->integrator_report << "\n";
  md << "\n";
  for (const std::string& png : plots) md << "![" << png << "](" << png << ")\n\n";
  md << "Files: `comparison.csv` (one row per model), `ranking.csv`, `curves/<model>.csv` (every step), "
        "`deflection_profiles.csv`, `fem_curve.csv`, `comparison_summary.json`"
     << (c.options.write_vtk ? ", `mesh.vtu`, `comparison.pvd` (every model side by side in ParaView, shifted along x)"
                             : "")
     << ".\n";
}

}  // namespace

std::string fmt(double x, int precision) {
  if (!std::isfinite(x)) return "nan";
  return significant_digits(x, precision);
}

std::string shown(double x, int precision) { return std::isfinite(x) ? fmt(x, precision) : "n/a"; }

std::string curve_csv(const Scene& scene, const ModelRun& run, bool with_post) {
  std::ostringstream csv;
  csv << "# model: " << run.model << "\n# description: " << run.description << "\n# force: "
      << (with_post ? "contact + post-puncture (compared with the FEM's total)"
                    : "contact (compared with the quasi-static FEM)")
      << "\ntime_s,depth_mm,velocity_mm_per_s,force_N,contact_force_N,post_puncture_force_N,step_wall_time_us";
  for (const Layer& l : scene.layers) csv << ',' << l.name << "_state";
  csv << '\n';
  for (std::size_t i = 0; i < run.steps(); ++i) {
    const double force = run.contact_force_N[i] + (with_post ? run.post_puncture_force_N[i] : 0.0);
    csv << fmt(run.time_s[i], 10) << ',' << fmt(run.depth_m[i] / kMm, 10) << ','
        << fmt(run.velocity_m_per_s[i] / kMm, 10) << ',' << fmt(force, 10) << ',' << fmt(run.contact_force_N[i], 10)
        << ',' << fmt(run.post_puncture_force_N[i], 10) << ',' << fmt(run.step_wall_time_s[i] * 1e6, 6);
    for (LayerState s : run.states[i]) csv << ',' << to_string(s);
    csv << '\n';
  }
  return csv.str();
}

std::string comparison_csv(const Scene& scene, const ComparisonRows& rows) {
  std::ostringstream csv;
  csv << "model,dofs,nodes,memory_MB,force_rmse_N,force_rmse_relative,peak_force_N,reference_peak_force_N,"
         "peak_force_error_relative,puncture_depth_error_mm,puncture_layers_disagreeing";
  for (const Layer& l : scene.layers) csv << ',' << l.name << "_puncture_mm";
  csv << ",deflection_rmse_mm,deflection_rmse_relative,deflection_depths,withdrawal_force_rmse_N,"
         "step_time_mean_ms,step_time_p99_ms,step_time_max_ms,build_s,run_s,completed_fraction,recovered_steps,"
         "inverted_share_max,first_inversion_depth_mm,min_volume_ratio,description\n";
  for (std::size_t i = 0; i < rows.metrics.size(); ++i) {
    const ModelMetrics& m = rows.metrics[i];
    const ModelRun* run = rows.runs[i];
    csv << m.model << ',' << m.dofs << ',' << (run ? std::to_string(run->size.nodes) : "nan") << ','
        << fmt(m.memory_bytes / 1e6) << ',' << fmt(m.force_rmse_N) << ',' << fmt(m.force_rmse_relative) << ','
        << fmt(m.model_peak_force_N) << ',' << fmt(m.reference_peak_force_N) << ',' << fmt(m.peak_force_error_relative)
        << ',' << fmt(m.puncture_depth_error_m / kMm) << ',' << m.puncture_layers_disagreeing;
    for (const auto& p : m.punctures) csv << ',' << fmt(p.model_depth_m / kMm);
    csv << ',' << fmt(m.deflection_rmse_m / kMm) << ',' << fmt(m.deflection_rmse_relative) << ',' << m.deflection_depths
        << ',' << fmt(m.withdrawal_force_rmse_N) << ',' << fmt(m.step_time_mean_s * 1e3) << ','
        << fmt(m.step_time_p99_s * 1e3) << ',' << fmt(m.step_time_max_s * 1e3) << ','
        << (run ? fmt(run->build_wall_time_s) : "nan") << ',' << (run ? fmt(run->run_wall_time_s) : "nan") << ','
        << fmt(m.completed_fraction) << ',' << (run ? std::to_string(run->recovered_steps) : "0") << ','
        << fmt(m.inverted_share_max) << ',' << fmt(m.first_inversion_depth_m / kMm) << ',' << fmt(m.min_volume_ratio)
        << ",\""
        << rows.descriptions[i] << "\"\n";
  }
  return csv.str();
}

std::string deflection_profiles_csv(const ReferenceData& reference, const std::vector<std::unique_ptr<ModelRun>>& runs) {
  std::ostringstream csv;
  csv << "model,depth_mm,r_mm,deflection_mm\n";
  for (const RadialProfile& p : reference.skin_profiles)
    for (std::size_t i = 0; i < p.r_m.size(); ++i)
      csv << "fem," << fmt(p.depth_m / kMm) << ',' << fmt(p.r_m[i] / kMm) << ',' << fmt(-p.uz_m[i] / kMm) << '\n';
  for (const auto& run : runs)
    for (const SurfaceSnapshot& s : run->skin_profiles)
      for (std::size_t i = 0; i < s.r_m.size(); ++i)
        csv << run->model << ',' << fmt(s.depth_m / kMm) << ',' << fmt(s.r_m[i] / kMm) << ','
            << fmt(s.deflection_m[i] / kMm) << '\n';
  return csv.str();
}

nlohmann::json identification_record(const std::string& method, const IdentificationResult& r, double step_m) {
  nlohmann::json j;
  j["method"] = method;
  j["library"] = method == "isres" ? "NLopt GN_ISRES (evolution strategy)" : "GSL gsl_siman (simulated annealing)";
  j["scale_before"] = r.scale_before;
  j["scale_after"] = r.scale_after;
  j["objective_before"] = r.before.objective;
  j["objective_after"] = r.after.objective;
  j["force_rmse_relative_before"] = r.before.force_rmse_relative;
  j["force_rmse_relative_after"] = r.after.force_rmse_relative;
  nlohmann::json punctures = nlohmann::json::array();
  for (std::size_t k = 0; k < r.punctures_after.size(); ++k)
    punctures.push_back({{"layer", r.punctures_after[k].layer},
                         {"reference_mm", fmt(r.punctures_after[k].reference_depth_m / kMm)},
                         {"before_mm", fmt(r.punctures_before[k].model_depth_m / kMm)},
                         {"after_mm", fmt(r.punctures_after[k].model_depth_m / kMm)}});
  j["puncture_depths"] = punctures;
  j["evaluations"] = r.evaluations;
  j["wall_time_s"] = r.wall_time_s;
  j["seconds_per_evaluation"] = r.seconds_per_evaluation;
  j["model_runs"] = "quasi-static mass-spring on the comparison mesh, steps of " + fmt(step_m / kMm) + " mm";
  nlohmann::json history = nlohmann::json::array();
  for (const auto& e : r.history) history.push_back({{"scale", e.scale}, {"objective", e.objective}});
  j["history"] = history;
  return j;
}

std::vector<TimeBudgetEntry> time_budget(const ComparisonContent& c) {
  std::vector<TimeBudgetEntry> budget;
  const auto fem_note = [](const ComparisonFemReference& f) { return f.from_cache ? "from the cache" : "solved"; };
  budget.push_back({"FEM reference, calibration trajectory", c.fem_entry.wall_time_s, fem_note(c.fem_entry)});
  if (!c.options.cases.empty()) {
    double seconds = 0.0;
    int solved = 0;
    for (const ComparisonCase& k : c.options.cases) seconds += k.fem.wall_time_s, solved += !k.fem.from_cache;
    budget.push_back({"FEM references, " + std::to_string(c.options.cases.size()) + " cases", seconds,
                      std::to_string(solved) + " solved, the others from the cache"});
  }
  if (c.mesh.mesh) budget.push_back({"tetrahedral mesh", c.mesh.report.wall_time_s, c.mesh.report.kind});
  const bool two_at_a_time = comparison::concurrent_solver_threads(2) == 2;
  if (!c.model_identification.empty()) {
    std::string note = two_at_a_time ? "two models at a time, each optimiser's runs two at a time; per model:"
                                     : "one model run at a time; per model:";
    for (const auto& run : c.runs)
      if (c.model_identification.contains(run->model)) {
        const nlohmann::json& id = c.model_identification[run->model];
        note += " " + run->model + " " + shown(id["wall_time_s"].get<double>(), 4) + " s (" +
                std::to_string(id["model_runs"].get<int>()) + " runs),";
      }
    note.pop_back();
    budget.push_back({"identifications against the FEM", c.identification_wall_time_s, note});
  }
  std::string beside;  // the calibration-trajectory runs in the phase of runs two at a time
  for (const auto& run : c.runs) {
    const double seconds = run->build_wall_time_s + run->run_wall_time_s;
    if (std::find(c.run_beside_others.begin(), c.run_beside_others.end(), run->model) != c.run_beside_others.end())
      beside += " " + run->model + " " + shown(seconds, 4) + " s,";
    else
      budget.push_back({run->model + ": calibration-trajectory run", seconds, "build " + shown(run->build_wall_time_s) + " s"});
  }
  for (const auto& j : c.identification)
    budget.push_back({"mass-spring identification, " + j["library"].get<std::string>(), j["wall_time_s"].get<double>(),
                      std::to_string(j["evaluations"].get<int>()) + " evaluations of the quasi-static surrogate"});
  if (!c.heldout.empty() || !beside.empty()) {
    std::map<std::string, double> per_model;
    for (const HeldOutRow& r : c.heldout) per_model[r.metrics.model] += r.wall_time_s;
    std::string note = two_at_a_time ? "two at a time:" : "one at a time:";
    if (!beside.empty()) note += " the calibration-trajectory runs of" + beside;
    if (!c.heldout.empty()) {
      note += " " + std::to_string(c.heldout.size()) + " held-out runs, run time per model:";
      for (const auto& [model, seconds] : per_model) note += " " + model + " " + shown(seconds, 4) + " s,";
    }
    note.pop_back();
    budget.push_back({c.heldout.empty() ? "volumetric runs" : "volumetric runs and held-out phase", c.pool_wall_time_s,
                      note});
  }
  double accounted = 0.0;
  for (const TimeBudgetEntry& e : budget) accounted += e.wall_time_s;
  budget.push_back({"the rest", c.wall_time_s - accounted, "reading the references, metrics, tables and files (the plots come after)"});
  return budget;
}

nlohmann::json summary_json(const ComparisonContent& c) {
  const Scene& scene = c.scene;
  nlohmann::json summary;
  summary["provenance"] = c.provenance;
  summary["scene"] = scene.name;
  summary["fem_reference"] = {{"hash", c.fem_entry.hash},
                              {"from_cache", c.fem_entry.from_cache},
                              {"summary", c.reference.fem.summary},
                              {"has_cutting_or_friction_columns", c.reference.data.has_shaft_forces}};
  summary["compared_force"] = c.reference.data.has_shaft_forces ? "total (contact + post-puncture)" : "contact force only";
  if (c.mesh.mesh)
    summary["mesh"] = {{"kind", c.mesh.report.kind},
                       {"vertices", c.mesh.report.vertices},
                       {"tetrahedra", c.mesh.report.tetrahedra},
                       {"wall_time_s", c.mesh.report.wall_time_s},
                       {"min_dihedral_deg", c.mesh.report.quality.min_dihedral_deg},
                       {"max_radius_edge_ratio", c.mesh.report.quality.max_radius_edge_ratio},
                       {"options", {{"size_at_axis_mm", scene.comparison.mesh.size_at_axis_m / kMm},
                                    {"size_far_mm", scene.comparison.mesh.size_far_m / kMm},
                                    {"grading", scene.comparison.mesh.grading}}}};
  nlohmann::json integrators = nlohmann::json::object();
  for (const auto& run : c.runs) {
    integrators[run->model] = {{"description", run->description}, {"integrator", run->integrator_report}};
    if (run->inverted_elements_max >= 0)
      integrators[run->model]["inverted_tetrahedra"] = {
          {"most", run->inverted_elements_max},
          {"share_at_most", run->inverted_share_max},
          {"first_at_depth_mm", std::isfinite(run->first_inversion_depth_m) ? nlohmann::json(run->first_inversion_depth_m / kMm)
                                                                             : nlohmann::json(nullptr)},
          {"min_volume_ratio", run->min_volume_ratio},
          {"sampled_every_steps", kInversionSampleSteps}};
    if (run->failed()) integrators[run->model]["failure"] = run->failure;
  }
  summary["models"] = integrators;
  summary["identification"] = c.identification;
  summary["model_identification"] = c.model_identification;
  if (!c.heldout.empty()) {
    summary["cases_file"] = c.options.cases_file;
    nlohmann::json cases = nlohmann::json::array();
    for (const ComparisonCase& k : c.options.cases)
      cases.push_back({{"name", k.validation_case.name}, {"held_out", k.validation_case.held_out},
                       {"fem_hash", k.fem.hash}, {"fem_from_cache", k.fem.from_cache}});
    summary["cases"] = cases;
  }
  summary["weights_file"] = c.options.weights_path.string();
  summary["wall_time_s"] = c.wall_time_s;
  nlohmann::json budget = nlohmann::json::array();
  for (const TimeBudgetEntry& e : time_budget(c))
    budget.push_back({{"phase", e.phase}, {"wall_time_s", e.wall_time_s}, {"note", e.note}});
  summary["time_budget"] = budget;
  return summary;
}

std::string comparison_markdown(const ComparisonContent& content, const std::vector<std::string>& plots) {
  std::ostringstream md;
  markdown_header(md, content);
  markdown_metrics(md, content);
  markdown_heldout(md, content);
  markdown_model_identification(md, content.model_identification);
  markdown_identification(md, content.identification);
  markdown_time_budget(md, content);
  markdown_models_and_files(md, content, plots);
  return md.str();
}

}  // namespace puncture::validation::comparison_report_detail
