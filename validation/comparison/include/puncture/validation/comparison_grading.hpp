// comparison_grading.hpp: the seed paper's comprehensive weighted grading
// (Sec. 3.3) applied to the objective metrics of `puncture compare`.
//
// The paper grades five systems on seven indicators scored 0..10 by
// residents. Here each model is one experimental scheme and its indicator
// scores come from its measured metrics (model_comparison.hpp), mapped onto
// 0..10 by a documented rule per indicator:
//   linear: score = 10 (worst - v) / (worst - best), clamped to [0, 10]
//   log:    the same in log10(v)
// (a metric that could not be computed scores 0). The weights file (JSON,
// scenes/delphi_weights.json by default) lists the indicators: name, the
// metric, the paper indicator it stands for, the mapping and the subjective
// (Delphi) weight alpha_j, given directly ("weight") or as the experts'
// first-round weights ("experts": rows of weights, one per expert, run through
// the Delphi rounds of grading.hpp). mu (preference coefficient) too.
// Objective weights beta_j by the mean-square-error method (Eq. 9-11) over the
// table of models (an indicator on which all models score alike gets none),
// omega_j = mu alpha_j + (1 - mu) beta_j, final score f_i = sum_j omega_j x_ij;
// models ranked by f_i.
//
// Metrics (ModelMetrics fields; mm for lengths):
//   force_rmse_relative, peak_force_error_abs (|peak error| / reference peak),
//   puncture_depth_error_mm (a layer broken by only one of model and
//   reference counts as the mapping's worst value), deflection_rmse_relative,
//   step_time_p99_s, step_time_mean_s, memory_bytes, completed_fraction.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "puncture/validation/grading.hpp"
#include "puncture/validation/model_comparison.hpp"

namespace puncture::validation {

struct IndicatorSpec {
  std::string name;             ///< column name in the ranking table
  std::string metric;           ///< one of the metrics above
  std::string paper_indicator;  ///< the seed paper's indicator it stands for
  std::string scale = "linear"; ///< "linear" or "log"
  double best = 0.0;            ///< value scoring 10
  double worst = 1.0;           ///< value scoring 0
  double weight = 0.0;          ///< subjective weight alpha_j (after the Delphi rounds when experts are given)
};

struct DelphiWeights {
  std::string source;  ///< file it was read from
  std::string notes;
  double mu = kPaperPreferenceMu;
  std::vector<IndicatorSpec> indicators;
  DelphiResult delphi;  ///< rounds, when the file gives experts' weights
  bool from_experts = false;
};

/// Reads and validates the weights file; throws std::runtime_error naming the
/// file and the JSON path of a bad field (unknown metric or scale, best ==
/// worst, weights not summing to 1 within 1e-6, mu outside (0, 1), ...).
DelphiWeights read_delphi_weights(const std::filesystem::path& path);
DelphiWeights parse_delphi_weights(const std::string& json_text, const std::string& source_name);

/// The metric's value for one model (NaN when not available).
double metric_value(const ModelMetrics& metrics, const std::string& metric, const IndicatorSpec& spec);
/// 0..10 score of a value under the spec's mapping (0 for NaN).
double indicator_score(const IndicatorSpec& spec, double value);

struct ComparisonGrade {
  std::vector<std::string> models;
  std::vector<IndicatorSpec> indicators;
  ScoreMatrix metric_values;  ///< [model][indicator]
  ScoreMatrix scores;         ///< 0..10
  std::vector<double> alpha;
  MseWeights objective;       ///< beta over the models
  std::vector<double> omega;
  std::vector<double> final_scores;
  std::vector<int> rank;      ///< 1 = best
  double mu = kPaperPreferenceMu;
};
ComparisonGrade grade_models(const std::vector<ModelMetrics>& models, const DelphiWeights& weights);

/// ranking.csv: model, rank, final score, then per indicator the metric value and score.
std::string ranking_csv(const ComparisonGrade& grade);
/// The paper-style table (markdown): indicators x models (scores), weights, final scores and ranks.
std::string ranking_markdown(const ComparisonGrade& grade, const DelphiWeights& weights);

}  // namespace puncture::validation
