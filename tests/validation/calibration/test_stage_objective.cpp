// The best point of a calibration stage does not depend on the order in which
// parallel evaluations are booked (stage_objective.hpp): equal objectives are
// decided by the smaller parameter vector, a lower objective always wins.
#include <gtest/gtest.h>

#include "stage_objective.hpp"

namespace pc = puncture::validation::calibration_detail;

namespace {

pc::StageObjective two_parameter_stage() {
  pc::StageObjective s(pc::StageInputs{}, "test");
  s.parameters.resize(2);
  return s;
}

}  // namespace

TEST(StageObjective, EqualObjectivesAreDecidedByTheSmallerPointWhateverTheOrder) {
  const double a[2] = {1.0, 2.0}, b[2] = {0.5, 3.0}, c[2] = {5.0, 5.0};
  pc::StageObjective first_a = two_parameter_stage(), first_b = two_parameter_stage();
  first_a.record(a, 0.5);
  first_a.record(b, 0.5);
  first_b.record(b, 0.5);
  first_b.record(a, 0.5);
  EXPECT_EQ(first_a.best_x(), std::vector<double>({0.5, 3.0}));
  EXPECT_EQ(first_b.best_x(), first_a.best_x());
  // A lower objective wins over a smaller point.
  first_a.record(c, 0.4);
  EXPECT_EQ(first_a.best_x(), std::vector<double>({5.0, 5.0}));
  EXPECT_EQ(first_a.best(), 0.4);
  first_b.offer({5.0, 5.0}, 0.4);
  EXPECT_EQ(first_b.best_x(), first_a.best_x());
  EXPECT_EQ(first_a.evaluations(), 3);
}
