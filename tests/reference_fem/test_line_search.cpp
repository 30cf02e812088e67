// backtracking_line_search (reference_fem/src/backtracking_line_search.hpp): the
// line search both FEM solvers' Newton steps use, on scripted trial residuals.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <optional>
#include <vector>

#include "../../reference_fem/src/backtracking_line_search.hpp"

using puncture::fem::backtracking_line_search;
using puncture::fem::LineSearchResult;

namespace {

/// try_step that returns residuals[h] (nullopt: inadmissible) and records the alphas tried.
struct Script {
  std::vector<std::optional<double>> residuals;
  std::vector<double> tried;
  std::optional<double> operator()(double alpha, int h) {
    tried.push_back(alpha);
    return residuals.at(static_cast<std::size_t>(h));
  }
};

}  // namespace

TEST(BacktrackingLineSearch, TakesTheFirstStepWithASufficientDecrease) {
  Script s{{1.1, std::nullopt, 0.99999, 0.5, 0.1}, {}};
  // alpha = 1/4: 0.99999 is not below (1 - 1e-4 / 4) = 0.999975; alpha = 1/8: 0.5 is.
  const LineSearchResult r = backtracking_line_search(1.0, false, 1e-12, 4, std::ref(s));
  EXPECT_TRUE(r.accepted);
  EXPECT_DOUBLE_EQ(r.alpha, 0.125);
  EXPECT_EQ(r.halvings, 3);
  EXPECT_EQ(s.tried, (std::vector<double>{1.0, 0.5, 0.25, 0.125}));  // stops there
}

TEST(BacktrackingLineSearch, ArmijoBoundAndAbsoluteFloor) {
  Script just_below{{1.0 - 1.01e-4}, {}}, just_above{{1.0 - 0.99e-4}, {}};
  EXPECT_TRUE(backtracking_line_search(1.0, false, 0.0, 0, std::ref(just_below)).accepted);
  EXPECT_FALSE(backtracking_line_search(1.0, false, 0.0, 0, std::ref(just_above)).accepted);
  Script floor{{2.0}, {}};  // no decrease, but at the absolute floor
  EXPECT_TRUE(backtracking_line_search(1.0, false, 2.0, 0, std::ref(floor)).accepted);
}

TEST(BacktrackingLineSearch, AnyAdmissibleStepWhileAGapCloses) {
  Script s{{std::nullopt, 5.0, 0.1}, {}};
  const LineSearchResult r = backtracking_line_search(1.0, true, 0.0, 2, std::ref(s));
  EXPECT_TRUE(r.accepted);
  EXPECT_DOUBLE_EQ(r.alpha, 0.5);  // larger residual, but admissible
}

TEST(BacktrackingLineSearch, WithoutDecreaseTheLeastBadAdmissibleStep) {
  Script s{{3.0, std::nullopt, 1.5, NAN, 2.0}, {}};
  const LineSearchResult r = backtracking_line_search(1.0, false, 0.0, 4, std::ref(s));
  EXPECT_FALSE(r.accepted);
  EXPECT_DOUBLE_EQ(r.alpha, 0.25);
  EXPECT_EQ(r.halvings, 2);
  EXPECT_EQ(s.tried.size(), 5u);  // every halving tried
  Script none{{std::nullopt, NAN}, {}};
  EXPECT_LT(backtracking_line_search(1.0, false, 0.0, 1, std::ref(none)).alpha, 0.0);
}

// energy_line_search (reference_fem/src/energy_line_search.hpp): the 3D
// solver's fallback, on potentials whose minimiser along the step is known.
#include "../../reference_fem/src/energy_line_search.hpp"

using puncture::fem::energy_line_search;

TEST(EnergyLineSearch, FindsTheMinimumOfAQuadraticPotentialInOneSecant) {
  // E(a) = (a - 0.3)^2: g(a) = 2 (a - 0.3), slope0 = -0.6; regula falsi on a linear g is exact.
  int calls = 0;
  const auto g = [&](double a) -> std::optional<double> { ++calls; return 2.0 * (a - 0.3); };
  const std::optional<double> a = energy_line_search(g(0.0).value(), 8, g);
  ASSERT_TRUE(a);
  EXPECT_NEAR(*a, 0.3, 1e-14);
  EXPECT_EQ(calls, 1 + 2);  // slope0, the full step, one secant
}

TEST(EnergyLineSearch, StrongCurvatureTheResidualNormWouldReject) {
  // The 3D spring-back's pattern: |R| rises ~12x at the full step while the
  // potential has its minimum inside. E(a) = -a + 5 a^4 / 4: g(a) = 5 a^3 - 1,
  // minimiser a* = 5^(-1/3) = 0.585; backtracking on |R| would stop at 1/8.
  const auto g = [](double a) -> std::optional<double> { return 5.0 * a * a * a - 1.0; };
  const std::optional<double> a = energy_line_search(-1.0, 8, g);
  ASSERT_TRUE(a);
  EXPECT_LE(std::abs(5.0 * *a * *a * *a - 1.0), 0.5);  // the acceptance: |g| <= |g(0)| / 2
  EXPECT_GT(*a, 0.4);
  EXPECT_LT(*a, 0.7);
}

TEST(EnergyLineSearch, TheWholeStepWhileThePotentialStillFalls) {
  const auto g = [](double a) -> std::optional<double> { return -1.0 + 0.2 * a; };
  EXPECT_EQ(energy_line_search(-1.0, 8, g), std::optional<double>(1.0));
}

TEST(EnergyLineSearch, InadmissibleStatesShortenTheStep) {
  // Inverted beyond 0.3 (nullopt); the minimiser 0.5 lies beyond: the longest admissible halving.
  std::vector<double> tried;
  const auto g = [&](double a) -> std::optional<double> {
    tried.push_back(a);
    if (a > 0.3) return std::nullopt;
    return 2.0 * (a - 0.5);
  };
  EXPECT_EQ(energy_line_search(-1.0, 8, g), std::optional<double>(0.25));
  EXPECT_EQ(tried, (std::vector<double>{1.0, 0.5, 0.25}));
}

TEST(EnergyLineSearch, NoDescentNoStep) {
  const auto up = [](double) -> std::optional<double> { return 1.0; };
  EXPECT_FALSE(energy_line_search(0.5, 8, up));   // not a descent direction
  EXPECT_FALSE(energy_line_search(0.0, 8, up));
  const auto never = [](double) -> std::optional<double> { return std::nullopt; };
  EXPECT_FALSE(energy_line_search(-1.0, 4, never));  // nothing admissible
  const auto nan = [](double) -> std::optional<double> { return NAN; };
  EXPECT_FALSE(energy_line_search(-1.0, 4, nan));
}

TEST(EnergyLineSearch, OutOfTrialsTheLongestDescendingStep) {
  // A slope that jumps from -1 to +1 at a = 0.37: regula falsi never meets |g| <= 1/2;
  // with the trials spent it returns the longest step on the descending side.
  const auto g = [](double a) -> std::optional<double> { return a < 0.37 ? -1.0 : 1.0; };
  const std::optional<double> a = energy_line_search(-1.0, 8, g);
  ASSERT_TRUE(a);
  EXPECT_LT(*a, 0.37);
  EXPECT_GT(*a, 0.2);
}
