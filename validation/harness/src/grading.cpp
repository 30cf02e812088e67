#include "puncture/validation/grading.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "puncture/io/output_session.hpp"
#include "puncture/io/atomic_file.hpp"
#include "puncture/io/csv_reader.hpp"
#include "puncture/io/csv_writer.hpp"

namespace puncture::validation {

namespace {

constexpr double kSumTolerance = 1e-6;

/// Checks a non-empty rectangular matrix of finite numbers; returns m.
std::size_t check_matrix(const ScoreMatrix& x, const char* what) {
  if (x.empty()) throw std::invalid_argument(std::string(what) + ": no rows");
  const std::size_t m = x.front().size();
  if (m == 0) throw std::invalid_argument(std::string(what) + ": no columns");
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (x[i].size() != m)
      throw std::invalid_argument(std::string(what) + ": row " + std::to_string(i + 1) + " has " +
                                  std::to_string(x[i].size()) + " values, row 1 has " + std::to_string(m));
    for (std::size_t j = 0; j < m; ++j)
      if (!std::isfinite(x[i][j]))
        throw std::invalid_argument(std::string(what) + ": non-finite value in row " + std::to_string(i + 1) +
                                    ", column " + std::to_string(j + 1));
  }
  return m;
}

void check_weights(const std::vector<double>& w, const char* what) {
  if (w.empty()) throw std::invalid_argument(std::string(what) + ": empty weight vector");
  double sum = 0.0;
  for (double v : w) {
    if (!std::isfinite(v) || v < 0.0) throw std::invalid_argument(std::string(what) + ": weights must be finite and >= 0");
    sum += v;
  }
  if (std::abs(sum - 1.0) > kSumTolerance) {
    std::ostringstream s;
    s << what << ": weights must sum to 1 (sum = " << std::setprecision(10) << sum << ")";
    throw std::invalid_argument(s.str());
  }
}

}  // namespace

const std::vector<double>& paper_subjective_weights() {
  static const std::vector<double> w{0.09, 0.17, 0.24, 0.13, 0.10, 0.21, 0.06};
  return w;
}
const std::vector<std::string>& paper_indicator_names() {
  static const std::vector<std::string> n{"tissue_texture",       "force_feedback",         "puncture_effect",
                                          "training_environment", "real_time_performance",  "training_effectiveness",
                                          "system_stability"};
  return n;
}

MseWeights mean_square_error_weights(const ScoreMatrix& scores) {
  const std::size_t m = check_matrix(scores, "mean_square_error_weights");
  const double n = static_cast<double>(scores.size());
  MseWeights w;
  w.mean.assign(m, 0.0);
  w.sigma.assign(m, 0.0);
  for (const auto& row : scores)
    for (std::size_t j = 0; j < m; ++j) w.mean[j] += row[j] / n;
  for (const auto& row : scores)
    for (std::size_t j = 0; j < m; ++j) w.sigma[j] += (row[j] - w.mean[j]) * (row[j] - w.mean[j]) / n;
  double total = 0.0;
  for (double& s : w.sigma) total += (s = std::sqrt(s));
  if (!(total > 0.0))
    throw std::invalid_argument(
        "mean_square_error_weights: every indicator has the same score in all schemes (sum of sigma = 0), "
        "Eq. 11 is undefined");
  w.beta.resize(m);
  for (std::size_t j = 0; j < m; ++j) w.beta[j] = w.sigma[j] / total;
  return w;
}

std::vector<double> comprehensive_weights(const std::vector<double>& alpha, const std::vector<double>& beta, double mu) {
  if (!(mu > 0.0 && mu < 1.0)) throw std::invalid_argument("comprehensive_weights: mu must lie in (0, 1)");
  check_weights(alpha, "comprehensive_weights (alpha)");
  check_weights(beta, "comprehensive_weights (beta)");
  if (alpha.size() != beta.size())
    throw std::invalid_argument("comprehensive_weights: alpha has " + std::to_string(alpha.size()) +
                                " indicators, beta has " + std::to_string(beta.size()));
  std::vector<double> omega(alpha.size());
  for (std::size_t j = 0; j < alpha.size(); ++j) omega[j] = mu * alpha[j] + (1.0 - mu) * beta[j];
  return omega;
}

std::vector<double> comprehensive_scores(const ScoreMatrix& scores, const std::vector<double>& omega) {
  const std::size_t m = check_matrix(scores, "comprehensive_scores");
  check_weights(omega, "comprehensive_scores (omega)");
  if (omega.size() != m)
    throw std::invalid_argument("comprehensive_scores: " + std::to_string(omega.size()) + " weights for " +
                                std::to_string(m) + " indicators");
  std::vector<double> f(scores.size(), 0.0);
  for (std::size_t i = 0; i < scores.size(); ++i)
    for (std::size_t j = 0; j < m; ++j) f[i] += omega[j] * scores[i][j];
  return f;
}

ModelGrade grade_model(const std::string& model, const ScoreMatrix& scores, const std::vector<double>& alpha, double mu) {
  ModelGrade g;
  g.model = model;
  g.objective = mean_square_error_weights(scores);
  g.omega = comprehensive_weights(alpha, g.objective.beta, mu);
  g.scheme_scores = comprehensive_scores(scores, g.omega);
  double sum = 0.0;
  for (double f : g.scheme_scores) sum += f;
  g.mean_score = sum / static_cast<double>(g.scheme_scores.size());
  return g;
}

DelphiResult run_delphi(const ScoreMatrix& expert_weights, const DelphiSettings& settings) {
  const std::size_t m = check_matrix(expert_weights, "run_delphi");
  for (std::size_t e = 0; e < expert_weights.size(); ++e)
    check_weights(expert_weights[e], ("run_delphi (expert " + std::to_string(e + 1) + ")").c_str());
  if (!(settings.revision_factor > 0.0 && settings.revision_factor <= 1.0))
    throw std::invalid_argument("run_delphi: revision_factor must lie in (0, 1]");
  if (!(settings.std_dev_threshold > 0.0)) throw std::invalid_argument("run_delphi: std_dev_threshold must be > 0");
  if (settings.max_rounds < 1) throw std::invalid_argument("run_delphi: max_rounds must be >= 1");

  ScoreMatrix w = expert_weights;
  const double n = static_cast<double>(w.size());
  DelphiResult result;
  for (int round = 1; round <= settings.max_rounds; ++round) {
    DelphiRound r{std::vector<double>(m, 0.0), std::vector<double>(m, 0.0)};
    for (const auto& row : w)
      for (std::size_t j = 0; j < m; ++j) r.mean[j] += row[j] / n;
    for (const auto& row : w)
      for (std::size_t j = 0; j < m; ++j) r.std_dev[j] += (row[j] - r.mean[j]) * (row[j] - r.mean[j]) / n;
    double worst = 0.0;
    for (double& s : r.std_dev) worst = std::max(worst, s = std::sqrt(s));
    result.rounds.push_back(r);
    if (worst <= settings.std_dev_threshold) {
      result.weights = r.mean;
      return result;
    }
    for (auto& row : w)
      for (std::size_t j = 0; j < m; ++j) row[j] += settings.revision_factor * (r.mean[j] - row[j]);
  }
  throw std::runtime_error("run_delphi: the experts' weights did not converge to a standard deviation <= " +
                           std::to_string(settings.std_dev_threshold) + " within " +
                           std::to_string(settings.max_rounds) + " rounds");
}

GradingResult grade_scores_csv_text(const std::string& text, const std::string& source_name, std::vector<double> alpha,
                                    double mu) {
  std::vector<std::string> order;
  std::vector<ScoreMatrix> matrices;
  std::vector<std::vector<std::string>> labels;
  io::CsvDocument doc;
  try {
    doc = io::parse_csv(text, source_name);
  } catch (const io::CsvFormatError& e) {
    throw std::runtime_error(e.what());
  }
  const std::vector<std::string>& header = doc.header;
  int line_no = doc.header_line;
  auto fail = [&](const std::string& what) {
    throw std::runtime_error(source_name + ":" + std::to_string(line_no) + ": " + what);
  };
  if (header.size() < 3 || header[0] != "model" || header[1] != "resident")
    fail("header must be `model,resident,<indicator>,...` with at least one indicator");
  for (const io::CsvRecord& record : doc.records) {
    line_no = record.line;
    const std::vector<std::string>& fields = record.fields;
    if (fields[0].empty()) fail("column 1 (model): empty model name");
    std::vector<double> row(header.size() - 2);
    for (std::size_t j = 2; j < fields.size(); ++j)
      if (!io::parse_finite_number(fields[j], row[j - 2]))
        fail("column " + std::to_string(j + 1) + " (" + header[j] + "): not a finite number: '" + fields[j] + "'");
    auto it = std::find(order.begin(), order.end(), fields[0]);
    std::size_t k = static_cast<std::size_t>(it - order.begin());
    if (it == order.end()) {
      order.push_back(fields[0]);
      matrices.emplace_back();
      labels.emplace_back();
    }
    matrices[k].push_back(std::move(row));
    labels[k].push_back(fields[1]);
  }
  if (order.empty()) throw std::runtime_error(source_name + ": no score rows");

  GradingResult result;
  result.indicators.assign(header.begin() + 2, header.end());
  if (alpha.empty()) {
    if (result.indicators.size() != paper_subjective_weights().size())
      throw std::invalid_argument(source_name + ": no subjective weights given and the file has " +
                                  std::to_string(result.indicators.size()) +
                                  " indicators (the paper's Delphi weights are for 7)");
    alpha = paper_subjective_weights();
  }
  if (alpha.size() != result.indicators.size())
    throw std::invalid_argument(source_name + ": " + std::to_string(alpha.size()) + " subjective weights for " +
                                std::to_string(result.indicators.size()) + " indicators");
  result.alpha = alpha;
  result.mu = mu;
  for (std::size_t k = 0; k < order.size(); ++k) {
    try {
      result.models.push_back(grade_model(order[k], matrices[k], alpha, mu));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(source_name + ": model '" + order[k] + "': " + e.what());
    }
    result.models.back().scheme_labels = labels[k];
  }
  return result;
}

GradingResult grade_scores_csv(const std::filesystem::path& path, std::vector<double> alpha, double mu) {
  return grade_scores_csv_text(io::read_text_file(path), path.string(), std::move(alpha), mu);
}

std::string grading_summary_csv(const GradingResult& result, const io::Provenance* provenance) {
  std::vector<std::string> columns{"model", "n_schemes", "mean_score", "min_score", "max_score"};
  for (const auto& ind : result.indicators) columns.push_back("omega_" + ind);
  for (const auto& ind : result.indicators) columns.push_back("beta_" + ind);
  io::CsvWriter csv(columns);
  if (provenance) csv.add_provenance(*provenance);
  for (const ModelGrade& g : result.models) {
    const auto [lo, hi] = std::minmax_element(g.scheme_scores.begin(), g.scheme_scores.end());
    csv.text(g.model).integer(static_cast<long long>(g.scheme_scores.size()));
    csv.number(g.mean_score, 12).number(*lo, 12).number(*hi, 12);
    for (double w : g.omega) csv.number(w, 12);
    for (double b : g.objective.beta) csv.number(b, 12);
    csv.end_row();
  }
  return csv.str();
}

std::string grading_scheme_scores_csv(const GradingResult& result, const io::Provenance* provenance) {
  io::CsvWriter csv({"model", "resident", "comprehensive_score"});
  if (provenance) csv.add_provenance(*provenance);
  for (const ModelGrade& g : result.models)
    for (std::size_t i = 0; i < g.scheme_scores.size(); ++i)
      csv.text(g.model)
          .text(i < g.scheme_labels.size() ? g.scheme_labels[i] : std::to_string(i + 1))
          .number(g.scheme_scores[i], 12)
          .end_row();
  return csv.str();
}

void write_grading_csv(io::OutputSession& session, const std::string& prefix, const GradingResult& result,
                       const io::Provenance* provenance) {
  session.write_text(prefix + "_summary.csv", grading_summary_csv(result, provenance));
  session.write_text(prefix + "_schemes.csv", grading_scheme_scores_csv(result, provenance));
}

}  // namespace puncture::validation
