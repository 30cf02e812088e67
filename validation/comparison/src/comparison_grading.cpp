// comparison_grading.cpp: Sec. 3.3 grading of measured model metrics; see
// comparison_grading.hpp.
#include "puncture/validation/comparison_grading.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "puncture/validation/number_format.hpp"

namespace puncture::validation {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const std::set<std::string> kMetrics{"force_rmse_relative",     "peak_force_error_abs", "puncture_depth_error_mm",
                                     "deflection_rmse_relative", "step_time_p99_s",      "step_time_mean_s",
                                     "memory_bytes",             "completed_fraction"};

[[noreturn]] void fail(const std::string& file, const std::string& path, const std::string& what) {
  throw std::runtime_error(file + ": " + path + ": " + what);
}

double number(const nlohmann::json& j, const std::string& key, const std::string& file, const std::string& path) {
  if (!j.contains(key)) fail(file, path + "/" + key, "missing required field");
  if (!j[key].is_number()) fail(file, path + "/" + key, "must be a number");
  const double v = j[key].get<double>();
  if (!std::isfinite(v)) fail(file, path + "/" + key, "must be finite");
  return v;
}

std::string text(const nlohmann::json& j, const std::string& key, const std::string& file, const std::string& path,
                 const char* fallback = nullptr) {
  if (!j.contains(key)) {
    if (fallback) return fallback;
    fail(file, path + "/" + key, "missing required field");
  }
  if (!j[key].is_string()) fail(file, path + "/" + key, "must be a string");
  return j[key].get<std::string>();
}

std::string format(double v, int precision = 4) {
  if (!std::isfinite(v)) return "n/a";
  return validation::significant_digits(v, precision);
}

}  // namespace

DelphiWeights parse_delphi_weights(const std::string& json_text, const std::string& source) {
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::exception& e) {
    fail(source, "/", std::string("malformed JSON: ") + e.what());
  }
  if (!root.is_object()) fail(source, "/", "must be a JSON object");
  static const std::set<std::string> known{"schema", "notes", "mu", "indicators", "experts"};
  for (auto it = root.begin(); it != root.end(); ++it)
    if (!known.count(it.key())) fail(source, "/" + it.key(), "unknown key");
  DelphiWeights w;
  w.source = source;
  if (text(root, "schema", source, "") != "puncture-delphi-weights/1")
    fail(source, "/schema", "must be \"puncture-delphi-weights/1\"");
  w.notes = root.contains("notes") ? text(root, "notes", source, "") : "";
  w.mu = root.contains("mu") ? number(root, "mu", source, "") : kPaperPreferenceMu;
  if (!(w.mu > 0.0 && w.mu < 1.0)) fail(source, "/mu", "must be in (0, 1)");
  if (!root.contains("indicators") || !root["indicators"].is_array() || root["indicators"].empty())
    fail(source, "/indicators", "must be a non-empty array");
  const bool experts = root.contains("experts");
  for (std::size_t i = 0; i < root["indicators"].size(); ++i) {
    const nlohmann::json& j = root["indicators"][i];
    const std::string path = "/indicators/" + std::to_string(i);
    if (!j.is_object()) fail(source, path, "must be an object");
    static const std::set<std::string> keys{"name", "metric", "paper_indicator", "scale", "best", "worst", "weight"};
    for (auto it = j.begin(); it != j.end(); ++it)
      if (!keys.count(it.key())) fail(source, path + "/" + it.key(), "unknown key");
    IndicatorSpec spec;
    spec.name = text(j, "name", source, path);
    spec.metric = text(j, "metric", source, path);
    if (!kMetrics.count(spec.metric)) {
      std::string list;
      for (const auto& m : kMetrics) list += (list.empty() ? "" : ", ") + m;
      fail(source, path + "/metric", "unknown metric '" + spec.metric + "' (known: " + list + ")");
    }
    spec.paper_indicator = text(j, "paper_indicator", source, path, "");
    spec.scale = text(j, "scale", source, path, "linear");
    if (spec.scale != "linear" && spec.scale != "log") fail(source, path + "/scale", "must be \"linear\" or \"log\"");
    spec.best = number(j, "best", source, path);
    spec.worst = number(j, "worst", source, path);
    if (spec.best == spec.worst) fail(source, path + "/worst", "must differ from best");
    if (spec.scale == "log" && !(spec.best > 0.0 && spec.worst > 0.0)) fail(source, path, "a log scale needs best, worst > 0");
    if (!experts) {
      spec.weight = number(j, "weight", source, path);
      if (!(spec.weight >= 0.0)) fail(source, path + "/weight", "must be >= 0");
    }
    w.indicators.push_back(spec);
  }
  if (experts) {
    const nlohmann::json& e = root["experts"];
    if (!e.is_array() || e.empty()) fail(source, "/experts", "must be a non-empty array of weight rows");
    ScoreMatrix rows;
    for (std::size_t i = 0; i < e.size(); ++i) {
      if (!e[i].is_array() || e[i].size() != w.indicators.size())
        fail(source, "/experts/" + std::to_string(i), "must list one weight per indicator (" +
                                                          std::to_string(w.indicators.size()) + ")");
      std::vector<double> row;
      for (const auto& v : e[i]) {
        if (!v.is_number()) fail(source, "/experts/" + std::to_string(i), "weights must be numbers");
        row.push_back(v.get<double>());
      }
      rows.push_back(row);
    }
    try {
      w.delphi = run_delphi(rows);
    } catch (const std::exception& ex) {
      fail(source, "/experts", ex.what());
    }
    for (std::size_t j = 0; j < w.indicators.size(); ++j) w.indicators[j].weight = w.delphi.weights[j];
    w.from_experts = true;
  }
  double sum = 0.0;
  for (const IndicatorSpec& s : w.indicators) sum += s.weight;
  if (std::abs(sum - 1.0) > 1e-6) fail(source, "/indicators", "weights must sum to 1 (got " + format(sum, 10) + ")");
  return w;
}

DelphiWeights read_delphi_weights(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open the weights file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_delphi_weights(buffer.str(), path.string());
}

double metric_value(const ModelMetrics& m, const std::string& metric, const IndicatorSpec& spec) {
  if (metric == "force_rmse_relative") return m.force_rmse_relative;
  if (metric == "peak_force_error_abs") return std::abs(m.peak_force_error_relative);
  if (metric == "deflection_rmse_relative") return m.deflection_rmse_relative;
  if (metric == "step_time_p99_s") return m.step_time_p99_s;
  if (metric == "step_time_mean_s") return m.step_time_mean_s;
  if (metric == "completed_fraction") return m.completed_fraction;
  if (metric == "memory_bytes") return m.memory_bytes;
  if (metric == "puncture_depth_error_mm") {
    // Mean over the layers the reference breaks or the model breaks: |error|
    // in mm where both do, the mapping's worst value where only one does.
    double sum = 0.0;
    int n = 0;
    for (const LayerPunctureComparison& p : m.punctures) {
      if (!p.reference_punctured && !p.model_punctured) continue;
      sum += (p.reference_punctured && p.model_punctured) ? std::abs(p.model_depth_m - p.reference_depth_m) * 1e3
                                                          : spec.worst;
      ++n;
    }
    return n ? sum / n : kNaN;
  }
  throw std::invalid_argument("metric_value: unknown metric '" + metric + "'");
}

double indicator_score(const IndicatorSpec& spec, double value) {
  if (!std::isfinite(value)) return 0.0;
  double v = value, best = spec.best, worst = spec.worst;
  if (spec.scale == "log") {
    v = std::log10(std::max(value, 1e-300));
    best = std::log10(best);
    worst = std::log10(worst);
  }
  return std::clamp(10.0 * (worst - v) / (worst - best), 0.0, 10.0);
}

ComparisonGrade grade_models(const std::vector<ModelMetrics>& models, const DelphiWeights& weights) {
  if (models.empty()) throw std::invalid_argument("grade_models: no models");
  ComparisonGrade g;
  g.indicators = weights.indicators;
  g.mu = weights.mu;
  for (const IndicatorSpec& s : weights.indicators) g.alpha.push_back(s.weight);
  for (const ModelMetrics& m : models) {
    g.models.push_back(m.model);
    std::vector<double> values, scores;
    for (const IndicatorSpec& s : weights.indicators) {
      const double v = metric_value(m, s.metric, s);
      values.push_back(v);
      scores.push_back(indicator_score(s, v));
    }
    g.metric_values.push_back(values);
    g.scores.push_back(scores);
  }
  // Objective weights over the table of models; if every indicator scores the
  // same for all models (nothing to learn from the spread), beta = alpha.
  try {
    g.objective = mean_square_error_weights(g.scores);
  } catch (const std::invalid_argument&) {
    g.objective.beta = g.alpha;
    g.objective.mean.assign(g.alpha.size(), kNaN);
    g.objective.sigma.assign(g.alpha.size(), 0.0);
  }
  g.omega = comprehensive_weights(g.alpha, g.objective.beta, g.mu);
  g.final_scores = comprehensive_scores(g.scores, g.omega);
  std::vector<int> order(models.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return g.final_scores[static_cast<std::size_t>(a)] > g.final_scores[static_cast<std::size_t>(b)]; });
  g.rank.assign(models.size(), 0);
  for (std::size_t r = 0; r < order.size(); ++r) g.rank[static_cast<std::size_t>(order[r])] = static_cast<int>(r) + 1;
  return g;
}

std::string ranking_csv(const ComparisonGrade& g) {
  std::ostringstream csv;
  csv << "model,rank,final_score";
  for (const IndicatorSpec& s : g.indicators) csv << ',' << s.name << "_value," << s.name << "_score";
  csv << '\n';
  for (std::size_t i = 0; i < g.models.size(); ++i) {
    csv << g.models[i] << ',' << g.rank[i] << ',' << std::setprecision(10) << g.final_scores[i];
    for (std::size_t j = 0; j < g.indicators.size(); ++j)
      csv << ',' << (std::isfinite(g.metric_values[i][j]) ? format(g.metric_values[i][j], 10) : "nan") << ','
          << format(g.scores[i][j], 10);
    csv << '\n';
  }
  csv << "# weights: indicator,alpha_subjective,beta_objective,omega (mu = " << g.mu << ")\n";
  for (std::size_t j = 0; j < g.indicators.size(); ++j)
    csv << "# " << g.indicators[j].name << ',' << format(g.alpha[j], 6) << ',' << format(g.objective.beta[j], 6) << ','
        << format(g.omega[j], 6) << '\n';
  return csv.str();
}

std::string ranking_markdown(const ComparisonGrade& g, const DelphiWeights& w) {
  std::ostringstream md;
  md << "| indicator (paper) | metric | alpha (Delphi) | beta (MSE) | omega |";
  for (const std::string& m : g.models) md << ' ' << m << " |";
  md << "\n|---|---|---|---|---|";
  for (std::size_t i = 0; i < g.models.size(); ++i) md << "---|";
  md << '\n';
  for (std::size_t j = 0; j < g.indicators.size(); ++j) {
    const IndicatorSpec& s = g.indicators[j];
    md << "| " << s.name << (s.paper_indicator.empty() ? "" : " (" + s.paper_indicator + ")") << " | " << s.metric
       << " | " << format(g.alpha[j], 3) << " | " << format(g.objective.beta[j], 3) << " | " << format(g.omega[j], 3)
       << " |";
    for (std::size_t i = 0; i < g.models.size(); ++i) md << ' ' << std::fixed << std::setprecision(2) << g.scores[i][j] << " |";
    md.unsetf(std::ios::floatfield);
    md << '\n';
  }
  md << "| **comprehensive score** | | | | |";
  for (std::size_t i = 0; i < g.models.size(); ++i) md << " **" << std::fixed << std::setprecision(2) << g.final_scores[i] << "** |";
  md.unsetf(std::ios::floatfield);
  md << "\n| **rank** | | | | |";
  for (std::size_t i = 0; i < g.models.size(); ++i) md << ' ' << g.rank[i] << " |";
  md << "\n\nmu = " << g.mu << " (subjective share); subjective weights from " << w.source
     << (w.from_experts ? " (Delphi rounds over the experts' weights: " + std::to_string(w.delphi.rounds.size()) + " rounds)" : "")
     << ". Scores 0..10 per indicator: ";
  for (std::size_t j = 0; j < g.indicators.size(); ++j) {
    const IndicatorSpec& s = g.indicators[j];
    md << (j ? "; " : "") << s.name << " 10 at " << format(s.best) << ", 0 at " << format(s.worst) << " (" << s.scale << ")";
  }
  md << ".\n";
  return md.str();
}

}  // namespace puncture::validation
