// comparison_tables.hpp (internal to the comparison report): the text files
// of `puncture compare`, each a pure function of what was computed.
//
// fmt(x, precision): x with `precision` significant digits, "nan" when not
//   finite; shown(x): the same for tables people read, "n/a" when not finite.
// curve_csv: curves/<model>.csv, every haptic step (time s, depth mm,
//   velocity mm/s, compared force N = contact (+ post-puncture when
//   with_post), its parts N, step wall time us, layer states).
// comparison_csv: one row per model (memory MB, forces N, depths mm,
//   deflection mm, step times ms, build/run wall time s).
// deflection_profiles_csv: the skin's deflection (mm, > 0 into the tissue) at
//   the FEM's depths, FEM first, then every model run.
// identification_record: one mass-spring identification as JSON (factors,
//   objectives, puncture depths in mm, evaluations, wall time s, history).
// summary_json / comparison_markdown: comparison_summary.json and
//   comparison.md from ComparisonContent; the markdown lists `plots`.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "comparison_heldout.hpp"
#include "comparison_runs.hpp"
#include "puncture/scene.hpp"
#include "puncture/validation/comparison_grading.hpp"
#include "puncture/validation/comparison_report.hpp"
#include "puncture/validation/mass_spring_identification.hpp"
#include "puncture/validation/model_comparison.hpp"

namespace puncture::validation::comparison_report_detail {

std::string fmt(double x, int precision = 6);
std::string shown(double x, int precision = 3);

std::string curve_csv(const Scene& scene, const ModelRun& run, bool with_post);
std::string comparison_csv(const Scene& scene, const ComparisonRows& rows);
std::string deflection_profiles_csv(const ReferenceData& reference, const std::vector<std::unique_ptr<ModelRun>>& runs);
nlohmann::json identification_record(const std::string& method, const IdentificationResult& result, double step_m);

/// Everything comparison_summary.json and comparison.md are made of.
struct ComparisonContent {
  const Scene& scene;
  const ComparisonReportOptions& options;
  const ComparisonFemReference& fem_entry;
  const ComparisonReference& reference;
  const ComparisonMesh& mesh;
  const nlohmann::json& provenance;
  const std::vector<std::unique_ptr<ModelRun>>& runs;
  const nlohmann::json& identification;  ///< array of identification_record
  const nlohmann::json& model_identification;  ///< per model: its identified stiffness factors and critical forces
  const ComparisonRows& rows;
  const ComparisonGrade& grade;
  const std::vector<HeldOutRow>& heldout;  ///< empty without held-out cases
  const ComparisonOutcome& outcome;        ///< heldout_metrics, heldout_grade
  const DelphiWeights& weights;
  double wall_time_s;                 ///< the whole command, s
  double identification_wall_time_s;  ///< the models' identifications (two models at a time), s
  /// The runs two at a time: the volumetric models' on the calibration
  /// trajectory (run_beside_others) and the held-out runs, s.
  double pool_wall_time_s;
  const std::vector<std::string>& run_beside_others;  ///< models whose calibration-trajectory run was in that phase
};

/// Where the command's wall time went: one entry per phase (FEM references,
/// mesh, each model's identification and calibration-trajectory run, the
/// volumetric runs and held-out phase, the rest), in seconds; they add up to the total.
struct TimeBudgetEntry {
  std::string phase;
  double wall_time_s;
  std::string note;
};
std::vector<TimeBudgetEntry> time_budget(const ComparisonContent& content);

nlohmann::json summary_json(const ComparisonContent& content);
std::string comparison_markdown(const ComparisonContent& content, const std::vector<std::string>& plots);

}  // namespace puncture::validation::comparison_report_detail
