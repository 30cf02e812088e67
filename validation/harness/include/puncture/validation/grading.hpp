// grading.hpp: the comprehensive weighted grading of seed paper Sec. 3.3.
//
// n experimental schemes (one resident operating one model) score m
// indicators; x_ij is the score of scheme i on indicator j (any common unit,
// the paper uses 0..10). The method combines
//   * subjective weights alpha_j (Delphi method, sum alpha = 1), and
//   * objective weights beta_j by the mean-square-error method:
//       E(j)     = 1/n sum_i x_ij                                    (Eq. 9)
//       sigma(j) = sqrt(1/n sum_i (x_ij - E(j))^2)                   (Eq. 10)
//       beta_j   = sigma(j) / sum_k sigma(k)                         (Eq. 11)
//     (population standard deviation, 1/n, as printed in the paper),
// into omega_j = mu alpha_j + (1 - mu) beta_j (0 < mu < 1, paper: mu = 0.4)
// and the comprehensive score f_i = sum_j omega_j x_ij of every scheme; the
// model's grade is the mean of f_i over its schemes. Objective weights are
// computed per model (the paper's Tab. 3 has one column per model).
//
// Every function validates its input and throws std::invalid_argument with a
// message naming the problem (empty matrix, unequal row lengths, non-finite
// score, weights that do not sum to 1 within 1e-6, mu outside (0, 1), all
// indicators constant so that Eq. 11 divides by zero).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "puncture/io/provenance.hpp"

namespace puncture::io {
class OutputSession;
}

namespace puncture::validation {

/// Scores: rows = schemes (n), columns = indicators (m).
using ScoreMatrix = std::vector<std::vector<double>>;

/// The paper's Delphi weights (Sec. 3.3): tissue texture 0.09, force feedback
/// 0.17, puncture effect 0.24, training environment 0.13, real-time
/// performance 0.10, training effectiveness 0.21, system stability 0.06.
const std::vector<double>& paper_subjective_weights();
const std::vector<std::string>& paper_indicator_names();
constexpr double kPaperPreferenceMu = 0.4;

/// Eq. 9-11 step by step.
struct MseWeights {
  std::vector<double> mean;    ///< E(j), Eq. 9
  std::vector<double> sigma;   ///< sigma(j), Eq. 10 (1/n)
  std::vector<double> beta;    ///< beta_j, Eq. 11 (sums to 1)
};
MseWeights mean_square_error_weights(const ScoreMatrix& scores);

/// omega_j = mu alpha_j + (1 - mu) beta_j. alpha and beta must each sum to 1.
std::vector<double> comprehensive_weights(const std::vector<double>& alpha, const std::vector<double>& beta, double mu);

/// f_i = sum_j omega_j x_ij, one per scheme.
std::vector<double> comprehensive_scores(const ScoreMatrix& scores, const std::vector<double>& omega);

/// Everything for one model: its score matrix graded with alpha and mu.
struct ModelGrade {
  std::string model;
  MseWeights objective;
  std::vector<double> omega;         ///< comprehensive weights
  std::vector<double> scheme_scores; ///< f_i
  std::vector<std::string> scheme_labels;  ///< e.g. resident ids (may be empty)
  double mean_score = 0.0;           ///< mean of f_i
};
ModelGrade grade_model(const std::string& model, const ScoreMatrix& scores, const std::vector<double>& alpha,
                       double mu = kPaperPreferenceMu);

// ---------------------------------------------------------------------------
// Delphi rounds (Sec. 3.3 (2), steps 3-5). Each expert e holds a weight vector
// w_e (sums to 1). A round computes per indicator the mean and the standard
// deviation over the experts (1/n_experts); if every standard deviation is
// <= threshold the means are the subjective weights. Otherwise every expert
// revises toward the round mean, w_e <- w_e + revision_factor (mean - w_e)
// (our model of "modify the weights according to the calculation results";
// it keeps sum w_e = 1, leaves the mean unchanged and multiplies every
// standard deviation by (1 - revision_factor)).
struct DelphiSettings {
  double std_dev_threshold = 0.1;  ///< paper: 0.1
  double revision_factor = 0.5;    ///< in (0, 1]
  int max_rounds = 100;            ///< throws std::runtime_error if not converged
};
struct DelphiRound {
  std::vector<double> mean;
  std::vector<double> std_dev;
};
struct DelphiResult {
  std::vector<double> weights;      ///< alpha: the means of the final round
  std::vector<DelphiRound> rounds;  ///< round 1 = the experts' first answers
};
/// expert_weights: rows = experts, columns = indicators; each row sums to 1.
DelphiResult run_delphi(const ScoreMatrix& expert_weights, const DelphiSettings& settings = {});

// ---------------------------------------------------------------------------
// Scores from a CSV file: header `model,resident,<indicator 1>,...,<indicator m>`,
// one row per (model, resident); lines starting with '#' are comments.
struct GradingResult {
  std::vector<std::string> indicators;
  std::vector<double> alpha;
  double mu = kPaperPreferenceMu;
  std::vector<ModelGrade> models;  ///< in order of first appearance in the file
};
/// alpha empty: the paper's weights (then the file must have 7 indicators).
/// Throws std::runtime_error naming file and line for a malformed file.
GradingResult grade_scores_csv(const std::filesystem::path& path, std::vector<double> alpha = {},
                               double mu = kPaperPreferenceMu);
GradingResult grade_scores_csv_text(const std::string& text, const std::string& source_name,
                                    std::vector<double> alpha = {}, double mu = kPaperPreferenceMu);

/// Per-model comprehensive scores: columns model, n_schemes, mean_score,
/// min_score, max_score, then omega_<indicator> and beta_<indicator>.
std::string grading_summary_csv(const GradingResult& result, const io::Provenance* provenance = nullptr);
/// Per-scheme scores: columns model, resident, comprehensive_score.
std::string grading_scheme_scores_csv(const GradingResult& result, const io::Provenance* provenance = nullptr);
/// Writes <prefix>_summary.csv and <prefix>_schemes.csv into the session.
/// Both tables, each with the provenance header when given.
void write_grading_csv(io::OutputSession& session, const std::string& prefix, const GradingResult& result,
                       const io::Provenance* provenance = nullptr);

}  // namespace puncture::validation
