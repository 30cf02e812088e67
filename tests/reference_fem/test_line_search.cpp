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
