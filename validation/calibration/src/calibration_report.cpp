// calibration_report.cpp: see calibration_report.hpp.
#include "puncture/validation/calibration_report.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "puncture/io/csv_writer.hpp"
#include "puncture/validation/number_format.hpp"

namespace puncture::validation {

namespace {

std::string num(double x, int precision = 4) { return significant_digits(x, precision); }

}  // namespace

std::string calibration_terms_table(const CalibrationResult& r) {
  std::ostringstream s;
  if (r.trajectory_before.empty() || r.trajectory_after.empty()) return s.str();
  const TrajectoryComparison& before = r.trajectory_before.front();
  const TrajectoryComparison& after = r.trajectory_after.front();
  s << "| term | before | after | error after | weight | reference samples | note |\n|---|---|---|---|---|---|---|\n";
  auto value = [](const ObjectiveTerm* t) { return t && t->available ? num(t->value, 3) : std::string("n/a"); };
  for (const ObjectiveTerm& t : after.terms) {
    const ObjectiveTerm* b = before.term(t.name, t.layer);
    std::string error = "n/a";
    if (t.available) error = t.name == "puncture_depth" ? num(t.raw * 1e3, 3) + " mm"
                             : t.name == "missing_puncture" ? num(t.value, 1)
                                                            : num(t.raw, 3) + " N";
    s << "| " << t.label() << " | " << value(b) << " | " << value(&t) << " | " << error << " | " << num(t.weight, 3)
      << " | " << t.samples << " | " << t.note << " |\n";
  }
  s << "\nValues are dimensionless: force RMSEs over the reference's peak force ("
    << num(after.reference_peak_force_N, 4) << " N), puncture force errors over the reference's puncture force, "
       "depth errors over min(L, layer thickness); the objective is the sum of weight x value^2 over the available "
       "terms: "
    << num(before.objective, 4) << " before, " << num(after.objective, 4) << " after.\n";
  return s.str();
}

std::string calibration_parameters_table(const CalibrationResult& r) {
  std::ostringstream s;
  s << "| layer | parameter | start | tuned | physical bounds | at a bound |\n|---|---|---|---|---|---|\n";
  for (const TunedParameterRecord& p : r.parameters)
    s << "| " << p.layer << " | " << p.name << " (" << p.unit << ") | " << num(p.start)
      << (p.start_moved_inside ? " (outside: moved in)" : "") << " | " << num(p.tuned) << " | [" << num(p.lower)
      << ", " << num(p.upper) << "] | " << (p.at_bound.empty() ? "no" : "**" + p.at_bound + "**") << " |\n";
  return s.str();
}

std::string calibration_punctures_table(const CalibrationResult& r, const Scene& scene) {
  std::ostringstream s;
  if (r.reference_events.empty() || r.trajectory_after.empty()) return s.str();
  const ReferenceEvents& ev = r.reference_events.front();
  s << "Reference punctures: " << ev.note
    << ".\n\n| layer | reference depth (mm) | reference force (N) | model depth after (mm) | model force after (N) "
       "|\n|---|---|---|---|---|\n";
  const auto& model = r.trajectory_after.front().model_punctures;
  for (std::size_t k = 0; k < scene.layers.size() && k < ev.punctures.size(); ++k) {
    const auto& p = ev.punctures[k];
    const bool m_found = k < model.size() && model[k].found;
    s << "| " << scene.layers[k].name << " | " << (p.found ? num(p.depth_m * 1e3) : "n/a") << " | "
      << (p.found ? num(p.force_N) : "n/a") << " | " << (m_found ? num(model[k].depth_m * 1e3) : "n/a") << " | "
      << (m_found ? num(model[k].force_N) : "n/a") << " |\n";
  }
  return s.str();
}

std::string calibration_identifiability_table(const CalibrationResult& r) {
  const IdentifiabilityReport& rep = r.identifiability;
  std::ostringstream s;
  s << "| layer | parameter | value | sensitivity | standard error | status | reason |\n|---|---|---|---|---|---|---|\n";
  for (const ParameterIdentifiability& p : rep.parameters) {
    const bool tuned = p.status != "not identifiable" || p.reason.find("kept at its start value") == std::string::npos;
    s << "| " << p.layer << " | " << p.name << " (" << p.unit << ") | " << num(p.value) << " | "
      << (tuned ? num(p.sensitivity, 3) : "-") << " | "
      << (std::isfinite(p.standard_error) ? num(p.standard_error, 2) : (tuned ? "not determined" : "-")) << " | "
      << (p.status == "identified" ? p.status : "**" + p.status + "**") << " | " << p.reason << " |\n";
  }
  if (!rep.note.empty()) s << "\n" << rep.note << "; residual variance " << num(rep.residual_variance, 3) << ".\n";
  s << "\nCorrelated pairs (|r| > 0.95): ";
  if (rep.correlated_names.empty()) s << "none.\n";
  for (std::size_t i = 0; i < rep.correlated_names.size(); ++i)
    s << (i ? "; " : "") << rep.correlated_names[i].first << " and " << rep.correlated_names[i].second << " ("
      << num(rep.correlated_values[i], 3) << ")" << (i + 1 == rep.correlated_names.size() ? ".\n" : "");
  if (rep.correlation.rows() > 0) {
    s << "\nCorrelation matrix (tuned parameters in the order above):\n\n";
    for (Eigen::Index i = 0; i < rep.correlation.rows(); ++i) {
      s << "    ";
      for (Eigen::Index k = 0; k < rep.correlation.cols(); ++k) {
        const double c = rep.correlation(i, k);
        std::ostringstream cell;
        cell << std::fixed << std::setprecision(2) << c;
        s << std::setw(6) << (std::isfinite(c) ? cell.str() : "n/a");
      }
      s << "\n";
    }
  }
  return s.str();
}

std::string calibration_identifiability_report(const CalibrationResult& r, const std::string& name) {
  std::ostringstream s;
  s << "# Identifiability of " << name << "\n\n"
    << "What the reference determines of each parameter of `" << name << ".json`: the Jacobian of the calibration's "
    << "residuals at the tuned values gives each parameter's sensitivity (|d r / d x|, x = ln p for scale "
    << "parameters, so per relative change) and approximate standard error (Gauss-Newton covariance "
    << "sigma^2 (J^T J)^-1, in the parameter's unit); a parameter is identified when it is inside its bounds, "
    << "the objective changes with it, and its standard error is below its value (scale). Parameters the "
    << "reference cannot identify before any fit (no puncture of the layer, too few samples, d without "
    << "rate-dependent references at two or more speeds) keep their start values.\n\n"
    << calibration_identifiability_table(r);
  return s.str();
}

std::string calibration_summary_markdown(const CalibrationResult& result, const Scene& scene,
                                        const ReferenceCurve& reference, const io::Provenance& provenance,
                                        const std::string& method, double seconds, const std::string& name) {
  std::ostringstream md;
  md << "# Calibration of " << scene.name << "\n\nMade by `" << provenance.command << "` on " << provenance.machine
     << ", " << provenance.date_utc << " (program " << provenance.program_version << ", git " << provenance.git_revision
     << ").\n\nReference: " << reference.kind << " (" << reference.curve.source << "). Method: " << method << ", "
     << result.evaluations << " model runs in " << num(seconds) << " s (wall, reference already available). Objective "
     << num(result.objective_before) << " -> " << num(result.objective_after) << ".\n\n"
     << "## Objective, term by term\n\n" << calibration_terms_table(result) << "\n## Punctures\n\n"
     << calibration_punctures_table(result, scene) << "\n## Tuned parameters\n\n" << calibration_parameters_table(result)
     << "\n## Identifiability\n\n" << calibration_identifiability_table(result) << "\nTuned preset: `" << name
     << ".json` (a scene `puncture run` accepts), provenance: `" << name << ".provenance.json`, identifiability: `"
     << name << ".identifiability.md`.\n";
  if (!result.damping_note.empty()) md << "\nDamping d: " << result.damping_note << "\n";
  if (!result.critical_force_note.empty())
    md << "\nCritical forces started at (then tuned): " << result.critical_force_note << ".\n";
  if (!result.warnings.empty()) {
    md << "\n## Warnings\n\n";
    for (const std::string& w : result.warnings) md << "- " << w << "\n";
  }
  return md.str();
}

std::string calibration_curves_csv(const std::vector<std::pair<std::string, const InsertionCurve*>>& curves,
                                   const io::Provenance& provenance) {
  io::CsvWriter csv({"curve", "time_s", "depth_mm", "force_N", "phase"});
  csv.add_provenance(provenance);
  for (const auto& [name, c] : curves) {
    const std::vector<CurvePhase> phase =
        c->phase.size() == c->size() ? c->phase : std::vector<CurvePhase>(c->size(), CurvePhase::Insertion);
    for (std::size_t i = 0; i < c->size(); ++i)
      csv.text(name)
          .number(c->time_s[i], 9)
          .number(c->depth_m[i] * 1e3, 9)
          .number(c->force_N[i], 9)
          .text(to_string(phase[i]))
          .end_row();
  }
  return csv.str();
}

}  // namespace puncture::validation
