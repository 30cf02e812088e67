// The tuned preset and its provenance (calibration.hpp, write_tuned_preset).
#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "puncture/io/output_session.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/calibration.hpp"
#include "puncture/validation/calibration_report.hpp"

namespace puncture::validation {

namespace {

constexpr double kMm = 1e-3;

nlohmann::json comparison_json(const CurveComparison& c) {
  nlohmann::json j;
  j["n_compared"] = c.n_compared;
  j["compared_depth_range_mm"] = {c.compared_from_depth_m / kMm, c.compared_to_depth_m / kMm};
  j["reference_peak_force_N"] = c.reference_peak_force_N;
  j["force_rmse_N"] = c.force_rmse_N;
  j["force_rmse_relative"] = c.force_rmse_relative;
  nlohmann::json layers = nlohmann::json::array();
  for (const LayerMetrics& l : c.layers) {
    nlohmann::json lj{{"layer", l.layer},
                      {"pressed_samples", l.n_samples},
                      {"force_rmse_N", l.force_rmse_N},
                      {"force_rmse_relative", l.force_rmse_relative},
                      {"reference_punctured", l.reference_puncture.found},
                      {"model_punctured", l.model_puncture.found}};
    if (l.has_pressed_interval) lj["pressed_interval_mm"] = {l.pressed_from_depth_m / kMm, l.pressed_to_depth_m / kMm};
    if (l.reference_puncture.found)
      lj["reference_puncture"] = {{"depth_mm", l.reference_puncture.depth_m / kMm}, {"force_N", l.reference_puncture.force_N}};
    if (l.model_puncture.found)
      lj["model_puncture"] = {{"depth_mm", l.model_puncture.depth_m / kMm}, {"force_N", l.model_puncture.force_N}};
    if (l.reference_puncture.found && l.model_puncture.found) {
      lj["puncture_depth_error_mm"] = l.puncture_depth_error_m / kMm;
      lj["puncture_force_error_N"] = l.puncture_force_error_N;
    }
    layers.push_back(lj);
  }
  j["layers"] = layers;
  return j;
}

nlohmann::json parameters_json(const std::vector<LayerParameters>& ps) {
  nlohmann::json a = nlohmann::json::array();
  for (const LayerParameters& p : ps)
    a.push_back({{"layer", p.layer},
                 {"K_N_per_mm", p.virtual_stiffness_N_per_m * kMm},
                 {"damping_d_N_s_per_m2", p.damping_N_s_per_m2},
                 {"w", p.rings_w},
                 {"L_mm", p.spacing_L_m / kMm},
                 {"surface_stiffness_N_per_mm", p.surface_stiffness_N_per_m * kMm},
                 {"deformed_threshold_mm", p.deformed_threshold_m / kMm},
                 {"breakthrough", p.breakthrough},
                 {"critical_force_N", p.critical_force_N},
                 {"critical_energy_mJ", p.critical_energy_J * 1e3},
                 {"cutting_force_N", p.cutting_force_N},
                 {"friction_dynamic_N_per_mm", p.friction_dynamic_N_per_m * kMm},
                 {"friction_static_N_per_mm", p.friction_static_N_per_m * kMm},
                 {"stiffening_quadratic_N_per_mm2", p.stiffening_quadratic_N_per_m2 * kMm * kMm},
                 {"stiffening_cubic_N_per_mm3", p.stiffening_cubic_N_per_m3 * kMm * kMm * kMm},
                 {"stiffening_exponential_N_per_mm", p.stiffening_exponential_N_per_m * kMm}});
  return a;
}

/// Every term; an unavailable one has value null ("n/a") and its reason.
nlohmann::json terms_json(const TrajectoryComparison& c) {
  nlohmann::json j;
  j["objective"] = c.objective;
  j["reference_peak_force_N"] = c.reference_peak_force_N;
  nlohmann::json terms = nlohmann::json::array();
  for (const ObjectiveTerm& t : c.terms) {
    nlohmann::json tj{{"term", t.name}, {"weight", t.weight}, {"samples", t.samples}, {"note", t.note}};
    if (!t.layer.empty()) tj["layer"] = t.layer;
    tj["value"] = t.available ? nlohmann::json(t.value) : nlohmann::json(nullptr);
    tj["contribution"] = t.available ? nlohmann::json(t.contribution()) : nlohmann::json(nullptr);
    const bool depth = t.name == "puncture_depth";
    tj[depth ? "error_mm" : "error_N"] = t.available ? nlohmann::json(depth ? t.raw / kMm : t.raw) : nlohmann::json(nullptr);
    terms.push_back(tj);
  }
  j["terms"] = terms;
  j["warnings"] = c.warnings;
  return j;
}

nlohmann::json events_json(const ReferenceEvents& ev, const std::vector<std::string>& names) {
  nlohmann::json j{{"source", to_string(ev.source)}, {"note", ev.note}};
  nlohmann::json p = nlohmann::json::array();
  for (std::size_t k = 0; k < ev.punctures.size() && k < names.size(); ++k) {
    nlohmann::json e{{"layer", names[k]}, {"found", ev.punctures[k].found}};
    if (ev.punctures[k].found) e["depth_mm"] = ev.punctures[k].depth_m / kMm, e["force_N"] = ev.punctures[k].force_N;
    p.push_back(e);
  }
  j["punctures"] = p;
  nlohmann::json drops = nlohmann::json::array();
  for (const ForceDrop& d : ev.drops)
    drops.push_back({{"depth_mm", d.depth_m / kMm}, {"peak_force_N", d.peak_force_N}, {"drop_N", d.drop_N},
                     {"marginal", d.marginal}});
  j["force_drops"] = drops;
  j["noise_N"] = ev.noise_N;
  j["contact_onset_mm"] = ev.has_contact_onset ? nlohmann::json(ev.contact_onset_m / kMm) : nlohmann::json(nullptr);
  j["doubts"] = ev.doubts;
  return j;
}

/// Standard errors and correlations: null where not determined.
nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json identifiability_json(const IdentifiabilityReport& rep) {
  nlohmann::json j{{"note", rep.note}, {"residuals", rep.residuals}, {"residual_variance", rep.residual_variance}};
  nlohmann::json ps = nlohmann::json::array();
  for (const ParameterIdentifiability& p : rep.parameters)
    ps.push_back({{"layer", p.layer},
                  {"parameter", p.name},
                  {"unit", p.unit},
                  {"value", p.value},
                  {"sensitivity", p.sensitivity},
                  {"standard_error", finite_or_null(p.standard_error)},
                  {"status", p.status},
                  {"reason", p.reason}});
  j["parameters"] = ps;
  nlohmann::json corr = nlohmann::json::array();
  for (Eigen::Index i = 0; i < rep.correlation.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index k = 0; k < rep.correlation.cols(); ++k) row.push_back(finite_or_null(rep.correlation(i, k)));
    corr.push_back(row);
  }
  j["correlation"] = corr;
  nlohmann::json pairs = nlohmann::json::array();
  for (std::size_t i = 0; i < rep.correlated_names.size(); ++i)
    pairs.push_back({{"first", rep.correlated_names[i].first},
                     {"second", rep.correlated_names[i].second},
                     {"correlation", rep.correlated_values[i]}});
  j["correlated_above_0.95"] = pairs;
  return j;
}

/// Each reference: what it is, its trajectory as the model ran it, metrics and terms before and after.
nlohmann::json references_json(const CalibrationResult& result, const std::vector<ReferenceCurve>& references,
                               const CalibrationOptions& options) {
  nlohmann::json refs = nlohmann::json::array();
  for (std::size_t r = 0; r < references.size(); ++r) {
    const InsertionCurve& c = references[r].curve;
    const Scene s = calibration_run_scene(result.tuned_scene, references[r], options);
    nlohmann::json rj{{"kind", references[r].kind},
                      {"source", c.source},
                      {"hash", c.content_hash.empty() ? nlohmann::json(nullptr) : nlohmann::json("fnv1a64:" + c.content_hash)},
                      {"samples", c.size()},
                      {"metadata", c.metadata},
                      {"rate_dependent", reference_is_rate_dependent(c)},
                      {"trajectory",
                       {{"start_height_mm", s.insertion.start_height_m / kMm},
                        {"speed_mm_per_s", s.insertion.speed_m_per_s / kMm},
                        {"target_depth_mm", s.insertion.target_depth_m / kMm},
                        {"dwell_s", s.insertion.dwell_s},
                        {"withdrawal_speed_mm_per_s", s.insertion.withdrawal_speed_m_per_s / kMm},
                        {"compared", "insertion, dwell and withdrawal, term by term (objective_terms_*)"}}}};
    if (r < result.before.size()) rj["metrics_before"] = comparison_json(result.before[r]);
    if (r < result.after.size()) rj["metrics_after"] = comparison_json(result.after[r]);
    if (r < result.trajectory_before.size()) rj["objective_terms_before"] = terms_json(result.trajectory_before[r]);
    if (r < result.trajectory_after.size()) rj["objective_terms_after"] = terms_json(result.trajectory_after[r]);
    std::vector<std::string> names;
    for (const Layer& l : result.tuned_scene.layers) names.push_back(l.name);
    if (r < result.reference_events.size()) rj["reference_punctures"] = events_json(result.reference_events[r], names);
    refs.push_back(rj);
  }
  return refs;
}

nlohmann::json tuned_parameters_json(const CalibrationResult& result) {
  nlohmann::json tuned = nlohmann::json::array();
  for (const TunedParameterRecord& p : result.parameters)
    tuned.push_back({{"layer", p.layer},
                     {"parameter", p.name},
                     {"unit", p.unit},
                     {"start", p.start},
                     {"tuned", p.tuned},
                     {"bounds", {p.lower, p.upper}},
                     {"at_bound", p.at_bound.empty() ? nlohmann::json(nullptr) : nlohmann::json(p.at_bound)},
                     {"start_moved_inside_bounds", p.start_moved_inside}});
  return tuned;
}

/// The optimiser, its settings and its stages.
nlohmann::json optimiser_json(const CalibrationResult& result, const CalibrationOptions& options) {
  const TunedParameterSet& t = options.parameters;
  const CalibrationWeights& w = options.weights;
  nlohmann::json opt{{"method", to_string(options.method)},
                     {"sequential", "layers top to bottom, then d of all layers if tuned"},
                     {"tuned",
                      {{"K", t.virtual_stiffness},
                       {"breakthrough_parameter", t.deformed_threshold},
                       {"cutting", t.cutting},
                       {"friction", t.friction},
                       {"stiffening", t.stiffening},
                       {"surface_stiffness", t.surface_stiffness},
                       {"L", t.spacing},
                       {"w", t.rings},
                       {"K_and_stiffening_kept_for", t.mesh_identified_layers}}},
                     {"joint_polish", options.joint_polish},
                     {"passes", options.passes},
                     {"puncture_depths_mm", [&] {
                        nlohmann::json d = nlohmann::json::array();
                        for (double x : options.puncture_depths_m) d.push_back(x / kMm);
                        return d;
                      }()},
                     {"bound_factor", options.bound_factor},
                     {"rings_search_radius", options.rings_search_radius},
                     {"max_evaluations_per_stage", options.max_evaluations_per_stage},
                     {"evaluations_per_parameter", options.evaluations_per_parameter},
                     {"log_x_tolerance", options.log_x_tolerance},
                     {"threads", options.threads},
                     {"lm_max_iterations", options.lm_max_iterations},
                     {"lm_difference_step", options.lm_difference_step},
                     {"lm_difference_step_min", options.lm_difference_step_min},
                     {"stage_turn_margin_mm", options.stage_turn_margin_m / kMm},
                     {"keep_unidentifiable_at_start", options.keep_unidentifiable_at_start},
                     {"integrator", options.integrator},
                     {"objective_depth_step_mm", options.objective_depth_step_m / kMm},
                     {"depth_margin_mm", options.depth_margin_m / kMm},
                     {"weights",
                      {{"overall_rmse", w.overall_rmse},
                       {"pressing", w.pressing},
                       {"after_puncture", w.after_puncture},
                       {"puncture_depth", w.puncture_depth},
                       {"puncture_force", w.puncture_force},
                       {"missing_puncture", w.missing_puncture},
                       {"withdrawal", w.withdrawal},
                       {"dwell", w.dwell},
                       {"parts", w.parts}}},
                     {"evaluations", result.evaluations}};
  if (options.method == CalibrationMethod::SimulatedAnnealing) {
    const AnnealingSettings& a = options.annealing;
    opt["annealing"] = {{"iters_fixed_T", a.iters_fixed_T}, {"step_size", a.step_size}, {"t_initial", a.t_initial},
                        {"mu_t", a.mu_t},                   {"t_min", a.t_min},         {"seed", a.seed},
                        {"polish_locally", a.polish_locally}};
  }
  nlohmann::json stages = nlohmann::json::array();
  for (const CalibrationStageRecord& s : result.stages)
    stages.push_back({{"stage", s.stage},
                      {"evaluations", s.evaluations},
                      {"objective_start", s.objective_start},
                      {"objective_best", s.objective_best},
                      {"optimiser_result", s.nlopt_result}});
  opt["stages"] = stages;
  return opt;
}

}  // namespace

std::vector<CalibratedValue> calibrated_values(const CalibrationResult& result,
                                               const std::vector<CalibratedValue>& surface_fit) {
  std::vector<CalibratedValue> values = surface_fit;
  for (const ParameterIdentifiability& p : result.identifiability.parameters)
    for (const std::string& pointer : p.preset_pointers) {
      const double relative = std::abs(p.standard_error / p.value);
      const CalibratedValue v{p.layer, pointer, p.status, p.reason, "stages",
                              std::isfinite(relative) ? relative : std::numeric_limits<double>::quiet_NaN()};
      const auto same = std::find_if(values.begin(), values.end(), [&](const CalibratedValue& o) {
        return o.layer == v.layer && o.pointer == v.pointer;
      });
      if (same != values.end()) *same = v;
      else values.push_back(v);
    }
  return values;
}

std::string tuned_preset_provenance_json(const std::string& name, const CalibrationResult& result,
                                         const std::vector<ReferenceCurve>& references,
                                         const CalibrationOptions& options,
                                         const std::vector<CalibratedValue>& surface_fit) {
  nlohmann::json j;
  j["preset"] = name;
  j["scene_file"] = name + ".json";
  j["references"] = references_json(result, references, options);
  j["calibrated_layers"] = result.calibrated_layers;
  j["parameters_before"] = parameters_json(result.initial);
  j["parameters_after"] = parameters_json(result.tuned);
  j["objective_before"] = result.objective_before;
  j["objective_after"] = result.objective_after;
  j["damping"] = {{"tuned", result.damping_tuned}, {"note", result.damping_note}};
  j["critical_force_start"] = result.critical_force_note;
  j["tuned_parameters"] = tuned_parameters_json(result);
  j["identifiability"] = identifiability_json(result.identifiability);
  nlohmann::json values = nlohmann::json::array();
  for (const CalibratedValue& v : calibrated_values(result, surface_fit))
    values.push_back({{"layer", v.layer},
                      {"pointer", v.pointer},
                      {"status", v.status},
                      {"reason", v.reason},
                      {"step", v.step},
                      {"relative_standard_error", finite_or_null(v.relative_standard_error)}});
  j["calibrated_values"] = values;
  j["warnings"] = result.warnings;
  j["optimiser"] = optimiser_json(result, options);
  j["date_utc"] = io::utc_timestamp();
  j["project_version"] = io::program_version();
  j["git_revision"] = io::git_revision();
  j["machine"] = io::machine_summary();
  return j.dump(2) + "\n";
}

void write_tuned_preset(io::OutputSession& session, const std::string& name, const CalibrationResult& result,
                        const std::vector<ReferenceCurve>& references, const CalibrationOptions& options,
                        const std::vector<CalibratedValue>& surface_fit) {
  if (name.empty() || name.find('/') != std::string::npos)
    throw std::invalid_argument("write_tuned_preset: preset name must be a plain file stem (got '" + name + "')");
  Scene preset = result.tuned_scene;
  preset.name = name;
  preset.description = (preset.description.empty() ? std::string() : preset.description + " ") +
                       "Force-mesh parameters calibrated (see " + name + ".provenance.json).";
  const std::string text = scene_to_json_text(preset);
  parse_scene(text, name + ".json");  // the preset must load: fail before writing anything
  session.write_text(name + ".json", text);
  session.write_text(name + ".provenance.json", tuned_preset_provenance_json(name, result, references, options, surface_fit));
  session.write_text(name + ".identifiability.md", calibration_identifiability_report(result, name));
}

}  // namespace puncture::validation
