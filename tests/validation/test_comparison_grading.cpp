// Sec. 3.3 grading of measured model metrics (validation/comparison): score
// mappings, the objective weights and final scores against a table worked by
// hand, the weights file reader, and the metrics of a model run against a
// reference built by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "puncture/scene_io.hpp"
#include "puncture/validation/comparison_grading.hpp"
#include "puncture/validation/model_comparison.hpp"

namespace puncture::validation {
namespace {

TEST(ComparisonGrading, ScoreMappings) {
  IndicatorSpec linear{"x", "force_rmse_relative", "", "linear", 0.0, 2.0, 1.0};
  EXPECT_DOUBLE_EQ(indicator_score(linear, 0.0), 10.0);
  EXPECT_DOUBLE_EQ(indicator_score(linear, 0.5), 7.5);
  EXPECT_DOUBLE_EQ(indicator_score(linear, 3.0), 0.0);
  EXPECT_DOUBLE_EQ(indicator_score(linear, std::nan("")), 0.0);
  IndicatorSpec log{"t", "step_time_p99_s", "", "log", 1e-5, 1.0, 1.0};
  EXPECT_NEAR(indicator_score(log, 1e-3), 6.0, 1e-12);  // 2 of 5 decades lost
  EXPECT_DOUBLE_EQ(indicator_score(log, 1e-7), 10.0);
  IndicatorSpec inverted{"s", "completed_fraction", "", "linear", 1.0, 0.0, 1.0};
  EXPECT_DOUBLE_EQ(indicator_score(inverted, 0.25), 2.5);
}

TEST(ComparisonGrading, FinalScoresOfAHandWorkedTable) {
  // Two indicators, three models. Scores (linear, 10 at 0, 0 at 1):
  //   A: rmse 0.1 -> 9, p99 0.2 -> 8;  B: 0.5 -> 5, 0.2 -> 8;  C: 0.3 -> 7, 0.8 -> 2.
  // MSE weights over the models: column 1 mean 7, sigma sqrt(8/3); column 2
  // mean 6, sigma sqrt(8) -> beta = (sqrt(8/3), sqrt(8)) / sum = (0.3660, 0.6340).
  // alpha = (0.7, 0.3), mu = 0.4: omega = 0.4 alpha + 0.6 beta = (0.5016, 0.4984).
  DelphiWeights w;
  w.mu = 0.4;
  w.indicators = {{"accuracy", "force_rmse_relative", "", "linear", 0.0, 1.0, 0.7},
                  {"speed", "step_time_mean_s", "", "linear", 0.0, 1.0, 0.3}};
  auto model = [](const char* name, double rmse, double t) {
    ModelMetrics m;
    m.model = name;
    m.force_rmse_relative = rmse;
    m.step_time_mean_s = t;
    return m;
  };
  const ComparisonGrade g = grade_models({model("A", 0.1, 0.2), model("B", 0.5, 0.2), model("C", 0.3, 0.8)}, w);
  const double s1 = std::sqrt(8.0 / 3.0), s2 = std::sqrt(8.0);
  const double b1 = s1 / (s1 + s2), b2 = s2 / (s1 + s2);
  const double o1 = 0.4 * 0.7 + 0.6 * b1, o2 = 0.4 * 0.3 + 0.6 * b2;
  EXPECT_NEAR(g.objective.beta[0], b1, 1e-12);
  EXPECT_NEAR(g.omega[1], o2, 1e-12);
  EXPECT_NEAR(g.final_scores[0], 9 * o1 + 8 * o2, 1e-9);
  EXPECT_NEAR(g.final_scores[1], 5 * o1 + 8 * o2, 1e-9);
  EXPECT_NEAR(g.final_scores[2], 7 * o1 + 2 * o2, 1e-9);
  EXPECT_EQ(g.rank, (std::vector<int>{1, 2, 3}));
  EXPECT_NE(ranking_csv(g).find("A,1,"), std::string::npos);
  EXPECT_NE(ranking_markdown(g, w).find("**rank**"), std::string::npos);
}

TEST(ComparisonGrading, PunctureDepthCountsOneSidedLayersAsWorst) {
  IndicatorSpec spec{"p", "puncture_depth_error_mm", "", "linear", 0.0, 10.0, 1.0};
  ModelMetrics m;
  m.punctures = {{"skin", true, true, 2e-3, 3e-3}, {"fat", true, false, 4e-3, std::nan("")},
                 {"muscle", false, false, std::nan(""), std::nan("")}};
  EXPECT_NEAR(metric_value(m, spec.metric, spec), (1.0 + 10.0) / 2.0, 1e-12);
}

TEST(ComparisonGrading, TheShippedWeightsFileAndBadFiles) {
  const DelphiWeights w = read_delphi_weights(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/delphi_weights.json");
  EXPECT_DOUBLE_EQ(w.mu, 0.4);
  double sum = 0.0;
  for (const IndicatorSpec& s : w.indicators) sum += s.weight;
  EXPECT_NEAR(sum, 1.0, 1e-9);
  // The paper's Delphi weights rescaled: force feedback 0.17 / 0.66.
  EXPECT_NEAR(w.indicators.front().weight, 0.17 / 0.66, 1e-9);
  auto error_of = [](const std::string& text) {
    try {
      parse_delphi_weights(text, "w.json");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string head = R"({"schema": "puncture-delphi-weights/1", "indicators": [)";
  EXPECT_NE(error_of(head + R"({"name": "x", "metric": "colour", "best": 0, "worst": 1, "weight": 1}]})")
                .find("w.json: /indicators/0/metric: unknown metric 'colour'"),
            std::string::npos);
  EXPECT_NE(error_of(head + R"({"name": "x", "metric": "force_rmse_relative", "best": 1, "worst": 1, "weight": 1}]})")
                .find("/indicators/0/worst"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"schema": "puncture-delphi-weights/1", "mu": 1.5, "indicators": []})").find("/mu"),
            std::string::npos);
  EXPECT_NE(error_of("{").find("malformed JSON"), std::string::npos);
  // Experts' first-round weights go through the Delphi rounds (std-dev <= 0.1).
  const DelphiWeights delphi = parse_delphi_weights(
      head + R"({"name": "a", "metric": "force_rmse_relative", "best": 0, "worst": 1},
                {"name": "b", "metric": "step_time_mean_s", "best": 0, "worst": 1}],
         "experts": [[0.9, 0.1], [0.3, 0.7], [0.6, 0.4]]})",
      "w.json");
  EXPECT_TRUE(delphi.from_experts);
  EXPECT_NEAR(delphi.indicators[0].weight, 0.6, 1e-12);  // the revisions keep the mean
  EXPECT_GT(delphi.delphi.rounds.size(), 1u);
}

TEST(ModelComparisonMetrics, HandBuiltRunAgainstAHandBuiltReference) {
  Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  // Reference: F = 0.02 d (N, d in mm) for d in [0, 2], skin broken at 2 mm.
  ReferenceData ref;
  ref.curve.layer_names = {"skin", "fat", "muscle"};
  ref.curve.layer_states.resize(3);
  for (int i = 0; i <= 4; ++i) {
    const double d = 0.5e-3 * i;
    ref.curve.time_s.push_back(d / 0.01);
    ref.curve.depth_m.push_back(d);
    ref.curve.velocity_m_per_s.push_back(0.01);
    ref.curve.force_N.push_back(i < 4 ? 20.0 * d : 0.0);
    ref.curve.layer_states[0].push_back(i < 4 ? LayerState::Pressed : LayerState::Punctured);
    ref.curve.layer_states[1].push_back(LayerState::Untouched);
    ref.curve.layer_states[2].push_back(LayerState::Untouched);
  }
  // Model: 10 % stiffer, skin broken at 1.5 mm (steps of 0.1 mm), no withdrawal.
  ModelRun run;
  run.model = "toy";
  for (int i = 0; i <= 20; ++i) {
    const double d = 0.1e-3 * i;
    run.time_s.push_back(d / 0.01);
    run.depth_m.push_back(d);
    run.velocity_m_per_s.push_back(0.01);
    run.contact_force_N.push_back(d < 1.5e-3 ? 22.0 * d : 0.0);
    run.post_puncture_force_N.push_back(0.0);
    run.states.push_back({d < 1.5e-3 ? LayerState::Pressed : LayerState::Punctured, LayerState::Untouched,
                          LayerState::Untouched});
    run.step_wall_time_s.push_back(i == 20 ? 1e-3 : 1e-6);
  }
  run.size.memory_bytes = 1000;
  const ModelMetrics m = metrics_against_reference(scene, run, ref, 21);
  EXPECT_NEAR(m.punctures[0].model_depth_m, 1.5e-3, 1e-12);
  EXPECT_NEAR(m.punctures[0].reference_depth_m, 2.0e-3, 1e-12);
  EXPECT_NEAR(m.puncture_depth_error_m, 0.5e-3, 1e-12);
  EXPECT_EQ(m.puncture_layers_disagreeing, 0);
  EXPECT_NEAR(m.reference_peak_force_N, 0.03, 1e-12);
  EXPECT_NEAR(m.peak_force_error_relative, (22.0 * 1.4e-3 - 0.03) / 0.03, 1e-9);
  EXPECT_TRUE(std::isnan(m.withdrawal_force_rmse_N));
  EXPECT_TRUE(std::isnan(m.deflection_rmse_m));  // no profiles
  EXPECT_DOUBLE_EQ(m.completed_fraction, 1.0);
  // 20 steps in the tissue: 19 of 1 us, one of 1 ms; the 0.99 quantile lies
  // 0.81 of the way from the 19th to the 20th order statistic.
  EXPECT_NEAR(m.step_time_p99_s, 1e-6 + 0.81 * (1e-3 - 1e-6), 1e-12);
  EXPECT_NEAR(m.step_time_mean_s, (19 * 1e-6 + 1e-3) / 20, 1e-15);
  EXPECT_GT(m.force_rmse_relative, 0.0);
  EXPECT_DOUBLE_EQ(quantile({1.0, 2.0, 3.0, 4.0, 5.0}, 0.5), 3.0);
  EXPECT_DOUBLE_EQ(quantile({1.0, 2.0}, 0.99), 1.99);
}

}  // namespace
}  // namespace puncture::validation
