// Comprehensive weighted grading (seed paper Sec. 3.3, Eq. 9-11) against
// values worked by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "puncture/io/output_session.hpp"
#include "puncture/validation/grading.hpp"

namespace pv = puncture::validation;

namespace {

// The hand-worked 3 x 2 example (3 schemes, 2 indicators):
//   x = [ 6  8 ]
//       [ 8  8 ]
//       [10  5 ]
// Eq. 9:  E(1) = (6 + 8 + 10) / 3 = 8,   E(2) = (8 + 8 + 5) / 3 = 7.
// Eq. 10: sigma(1) = sqrt((4 + 0 + 4) / 3) = sqrt(8/3) = 2 / sqrt(3) * sqrt(2),
//         sigma(2) = sqrt((1 + 1 + 4) / 3) = sqrt(2).
// Eq. 11: beta_1 = sqrt(8/3) / (sqrt(8/3) + sqrt(2)) = (2/sqrt3) / (2/sqrt3 + 1)
//                = 2 / (2 + sqrt3) = 4 - 2 sqrt3 = 0.5358983...
//         beta_2 = 1 - beta_1 = 2 sqrt3 - 3 = 0.4641016...
// With alpha = (0.3, 0.7) and mu = 0.4:
//   omega_1 = 0.12 + 0.6 (4 - 2 sqrt3) = 2.52 - 1.2 sqrt3 = 0.4415390...
//   omega_2 = 0.28 + 0.6 (2 sqrt3 - 3) = 1.2 sqrt3 - 1.52 = 0.5584609...
//   f_1 = 6 omega_1 + 8 omega_2  = 2.96 + 2.4 sqrt3 = 7.1169229...
//   f_2 = 8 (omega_1 + omega_2)  = 8
//   f_3 = 10 omega_1 + 5 omega_2 = 17.6 - 6 sqrt3  = 7.2076923...
//   mean = 9.52 - 1.2 sqrt3 = 7.4415390...
const pv::ScoreMatrix kExample{{6, 8}, {8, 8}, {10, 5}};
const std::vector<double> kAlpha{0.3, 0.7};
const double kSqrt3 = std::sqrt(3.0);

}  // namespace

TEST(Grading, MeanSquareErrorWeightsEq9To11ByHand) {
  const pv::MseWeights w = pv::mean_square_error_weights(kExample);
  ASSERT_EQ(w.beta.size(), 2u);
  EXPECT_NEAR(w.mean[0], 8.0, 1e-14);
  EXPECT_NEAR(w.mean[1], 7.0, 1e-14);
  EXPECT_NEAR(w.sigma[0], std::sqrt(8.0 / 3.0), 1e-14);
  EXPECT_NEAR(w.sigma[1], std::sqrt(2.0), 1e-14);
  EXPECT_NEAR(w.beta[0], 4.0 - 2.0 * kSqrt3, 1e-14);
  EXPECT_NEAR(w.beta[1], 2.0 * kSqrt3 - 3.0, 1e-14);
}

TEST(Grading, ComprehensiveWeightsAndScoresByHand) {
  const pv::ModelGrade g = pv::grade_model("ours", kExample, kAlpha, 0.4);
  EXPECT_NEAR(g.omega[0], 2.52 - 1.2 * kSqrt3, 1e-14);
  EXPECT_NEAR(g.omega[1], 1.2 * kSqrt3 - 1.52, 1e-14);
  ASSERT_EQ(g.scheme_scores.size(), 3u);
  EXPECT_NEAR(g.scheme_scores[0], 2.96 + 2.4 * kSqrt3, 1e-13);
  EXPECT_NEAR(g.scheme_scores[1], 8.0, 1e-13);
  EXPECT_NEAR(g.scheme_scores[2], 17.6 - 6.0 * kSqrt3, 1e-13);
  EXPECT_NEAR(g.mean_score, 9.52 - 1.2 * kSqrt3, 1e-13);
}

TEST(Grading, PaperSubjectiveWeightsSumToOne) {
  const auto& a = pv::paper_subjective_weights();
  ASSERT_EQ(a.size(), 7u);
  ASSERT_EQ(pv::paper_indicator_names().size(), 7u);
  double sum = 0.0;
  for (double v : a) sum += v;
  EXPECT_NEAR(sum, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(a[2], 0.24);  // puncture effect weighs most
}

TEST(Grading, PaperWeightsWithEqualSpreadGiveHandScores) {
  // Two schemes whose indicators all differ by 2, so sigma_j = 1 and
  // beta_j = 1/7 for every j; omega_j = 0.4 alpha_j + 0.6 / 7.
  //   r1 = (8,6,8,6,8,6,8): sum alpha x = 6.98, sum x = 50
  //        f1 = 0.4 * 6.98 + 0.6 / 7 * 50 = 2.792 + 30/7
  //   r2 = (6,8,6,8,6,8,6): sum alpha x = 7.02, sum x = 48
  //        f2 = 0.4 * 7.02 + 0.6 / 7 * 48 = 2.808 + 28.8/7
  //   mean = (5.6 + 58.8/7) / 2 = 2.8 + 4.2 = 7.0
  const pv::ScoreMatrix x{{8, 6, 8, 6, 8, 6, 8}, {6, 8, 6, 8, 6, 8, 6}};
  const pv::ModelGrade g = pv::grade_model("ours", x, pv::paper_subjective_weights());
  for (double b : g.objective.beta) EXPECT_NEAR(b, 1.0 / 7.0, 1e-14);
  EXPECT_NEAR(g.scheme_scores[0], 2.792 + 30.0 / 7.0, 1e-12);
  EXPECT_NEAR(g.scheme_scores[1], 2.808 + 28.8 / 7.0, 1e-12);
  EXPECT_NEAR(g.mean_score, 7.0, 1e-12);
}

TEST(Grading, RejectsInvalidInput) {
  EXPECT_THROW(pv::comprehensive_weights({0.3, 0.6}, {0.5, 0.5}, 0.4), std::invalid_argument);  // alpha sums to 0.9
  EXPECT_THROW(pv::comprehensive_weights(kAlpha, {0.5, 0.5}, 0.0), std::invalid_argument);
  EXPECT_THROW(pv::comprehensive_weights(kAlpha, {0.5, 0.5}, 1.0), std::invalid_argument);
  EXPECT_THROW(pv::comprehensive_weights(kAlpha, {0.2, 0.3, 0.5}, 0.4), std::invalid_argument);
  EXPECT_THROW(pv::mean_square_error_weights({{1, 2}, {3}}), std::invalid_argument);
  EXPECT_THROW(pv::mean_square_error_weights({}), std::invalid_argument);
  EXPECT_THROW(pv::mean_square_error_weights({{5, 5}, {5, 5}}), std::invalid_argument);  // sum sigma = 0
  EXPECT_THROW(pv::mean_square_error_weights({{5, NAN}, {5, 4}}), std::invalid_argument);
  EXPECT_THROW(pv::comprehensive_scores(kExample, {1.0}), std::invalid_argument);
  try {
    pv::comprehensive_weights({0.3, 0.6}, {0.5, 0.5}, 0.4);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sum to 1"), std::string::npos) << e.what();
  }
}

TEST(Grading, DelphiRoundsShrinkTheSpreadGeometrically) {
  // 4 experts, 2 indicators. Round 1: mean (0.5, 0.5), standard deviation
  // sqrt((0.16 + 0.16 + 0 + 0) / 4) = sqrt(0.08) = 0.2828 for both. Each
  // revision with factor 0.5 halves every deviation from the mean and keeps
  // the mean: round 2 0.1414, round 3 0.0707 <= 0.1 -> stop after 3 rounds.
  const pv::ScoreMatrix experts{{0.9, 0.1}, {0.1, 0.9}, {0.5, 0.5}, {0.5, 0.5}};
  pv::DelphiSettings s;
  s.std_dev_threshold = 0.1;
  s.revision_factor = 0.5;
  const pv::DelphiResult r = pv::run_delphi(experts, s);
  ASSERT_EQ(r.rounds.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_NEAR(r.rounds[k].std_dev[0], std::sqrt(0.08) * std::pow(0.5, static_cast<double>(k)), 1e-14);
    EXPECT_NEAR(r.rounds[k].mean[0], 0.5, 1e-14);
  }
  EXPECT_NEAR(r.weights[0], 0.5, 1e-14);
  EXPECT_NEAR(r.weights[1], 0.5, 1e-14);

  // Unequal experts: mean of the first round is the answer (revision keeps it).
  const pv::ScoreMatrix e2{{0.6, 0.3, 0.1}, {0.2, 0.5, 0.3}, {0.4, 0.4, 0.2}};
  const pv::DelphiResult r2 = pv::run_delphi(e2, {0.01, 0.3, 100});
  EXPECT_NEAR(r2.weights[0], 0.4, 1e-12);
  EXPECT_NEAR(r2.weights[1], 0.4, 1e-12);
  EXPECT_NEAR(r2.weights[2], 0.2, 1e-12);
  // std0 of indicator 1 = sqrt(0.08/3) = 0.1633; rounds = smallest r with 0.1633 * 0.7^(r-1) <= 0.01
  const int expected_rounds = 1 + static_cast<int>(std::ceil(std::log(0.01 / std::sqrt(0.08 / 3.0)) / std::log(0.7)));
  EXPECT_EQ(static_cast<int>(r2.rounds.size()), expected_rounds);

  s.max_rounds = 2;
  EXPECT_THROW(pv::run_delphi(experts, s), std::runtime_error);
  EXPECT_THROW(pv::run_delphi({{0.9, 0.2}}, {}), std::invalid_argument);  // expert weights sum to 1.1
  EXPECT_THROW(pv::run_delphi(experts, {0.1, 0.0, 10}), std::invalid_argument);
}

TEST(Grading, ScoresCsvPerModel) {
  // Model A: the hand example; model B: the hand example doubled (same beta,
  // so every score doubles). Rows interleaved on purpose.
  const std::string csv =
      "# scores from a hand-made example\n"
      "model,resident,texture,force\n"
      "A,r1,6,8\n"
      "B,r1,12,16\n"
      "A,r2,8,8\n"
      "B,r2,16,16\n"
      "A,r3,10,5\n"
      "B,r3,20,10\n";
  const pv::GradingResult r = pv::grade_scores_csv_text(csv, "scores.csv", kAlpha, 0.4);
  ASSERT_EQ(r.models.size(), 2u);
  EXPECT_EQ(r.models[0].model, "A");
  EXPECT_EQ(r.models[1].model, "B");
  EXPECT_EQ(r.indicators, (std::vector<std::string>{"texture", "force"}));
  EXPECT_NEAR(r.models[0].mean_score, 9.52 - 1.2 * kSqrt3, 1e-12);
  EXPECT_NEAR(r.models[1].mean_score, 2.0 * (9.52 - 1.2 * kSqrt3), 1e-12);
  EXPECT_EQ(r.models[0].scheme_labels, (std::vector<std::string>{"r1", "r2", "r3"}));

  // Summary CSV: the mean score of B is in row 3, column 3.
  std::istringstream summary(pv::grading_summary_csv(r));
  std::string header, row_a, row_b;
  std::getline(summary, header), std::getline(summary, row_a), std::getline(summary, row_b);
  EXPECT_EQ(header.rfind("model,n_schemes,mean_score,min_score,max_score,omega_texture,omega_force,beta_texture", 0), 0u);
  EXPECT_EQ(row_b.rfind("B,3,", 0), 0u);
  EXPECT_NEAR(std::stod(row_b.substr(4)), 2.0 * (9.52 - 1.2 * kSqrt3), 1e-9);

  const auto dir = std::filesystem::temp_directory_path() / "puncture_test_grading";
  std::filesystem::remove_all(dir);
  {
    puncture::io::OutputSession session(dir);
    pv::write_grading_csv(session, "grading", r);
    session.commit();
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "grading_summary.csv"));
  std::ifstream schemes(dir / "grading_schemes.csv");
  std::string line;
  int lines = 0;
  while (std::getline(schemes, line)) ++lines;
  EXPECT_EQ(lines, 7);  // header + 6 schemes
  std::filesystem::remove_all(dir);
}

TEST(Grading, ScoresCsvErrorsNameTheLine) {
  try {
    pv::grade_scores_csv_text("model,resident,a,b\nA,r1,6,8\nA,r2,x,8\n", "s.csv", kAlpha);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("s.csv:3"), std::string::npos) << m;
    EXPECT_NE(m.find("(a)"), std::string::npos) << m;
  }
  EXPECT_THROW(pv::grade_scores_csv_text("model,resident,a,b\nA,r1,6\n", "s.csv", kAlpha), std::runtime_error);
  EXPECT_THROW(pv::grade_scores_csv_text("name,a,b\nA,6,8\n", "s.csv", kAlpha), std::runtime_error);
  // No alpha given and not 7 indicators: the paper's weights do not apply.
  EXPECT_THROW(pv::grade_scores_csv_text("model,resident,a,b\nA,r1,6,8\nA,r2,7,9\n", "s.csv"), std::invalid_argument);
  EXPECT_THROW(pv::grade_scores_csv("/nonexistent/scores.csv"), std::runtime_error);
}
