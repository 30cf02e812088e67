// graded_divisions / geometric_intervals against the closed-form geometric sum.
#include <puncture/meshing/graded_divisions.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace {

using puncture::meshing::geometric_intervals;
using puncture::meshing::graded_divisions;

TEST(GradedDivisions, GeometricIntervalsMatchClosedForm) {
  const double L = 0.0294, g = 1.25;
  const int n = 7;
  const auto s = geometric_intervals(L, n, g);
  ASSERT_EQ(s.size(), 7u);
  const double first = L * (g - 1) / (std::pow(g, n) - 1);  // first term of the geometric sum
  for (int k = 0; k < n; ++k) EXPECT_NEAR(s[k], first * std::pow(g, k), 1e-15);
}

TEST(GradedDivisions, CountMakesFirstSizeClosestToTarget) {
  // L = h (g^n - 1)/(g - 1) exactly for n = 10: the target is met exactly.
  const double h = 1e-3, g = 1.2;
  const double L = h * (std::pow(g, 10) - 1) / (g - 1);
  const auto s = graded_divisions(L, h, g);
  ASSERT_EQ(s.size(), 10u);
  EXPECT_NEAR(s.front(), h, 1e-15);
  // Uniform: round(L / h).
  EXPECT_EQ(graded_divisions(1.0, 0.26, 1.0).size(), 4u);
  // A length shorter than the target gives one interval; min_count is honoured.
  EXPECT_EQ(graded_divisions(0.1, 1.0, 1.3).size(), 1u);
  EXPECT_EQ(graded_divisions(0.1, 1.0, 1.3, 3).size(), 3u);
}

TEST(GradedDivisions, RejectsBadInput) {
  EXPECT_THROW(geometric_intervals(0.0, 3, 1.2), std::invalid_argument);
  EXPECT_THROW(geometric_intervals(1.0, 0, 1.2), std::invalid_argument);
  EXPECT_THROW(geometric_intervals(1.0, 3, 0.5), std::invalid_argument);
  EXPECT_THROW(graded_divisions(1.0, -1.0, 1.2), std::invalid_argument);
}

}  // namespace
