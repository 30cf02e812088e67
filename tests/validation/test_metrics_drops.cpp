// A quasi-static reference records a breakthrough as two samples at the same
// time and depth (force before and after the drop). The reader accepts that;
// the comparison leaves the drop samples out, so a curve compared with itself
// has zero error and a model that drops at the same depth is not penalised.
#include <gtest/gtest.h>

#include "puncture/validation/metrics.hpp"
#include "puncture/validation/recording.hpp"

namespace puncture::validation {
namespace {

const std::string kHeader = "time_s,depth_mm,velocity_mm_per_s,force_N,skin_state\n";

TEST(CurveDrops, RepeatedInstantIsAcceptedOnlyAtTheSameDepth) {
  const InsertionCurve c = parse_insertion_curve(kHeader +
                                                     "0,0,1,0,pressed\n"
                                                     "1,1,1,2,pressed\n"
                                                     "1,1,1,0.5,punctured\n"
                                                     "2,2,1,0.6,punctured\n",
                                                 "drop.csv");
  EXPECT_EQ(c.size(), 4u);
  EXPECT_EQ(insertion_phase(c).size(), 4u);
  EXPECT_THROW(parse_insertion_curve(kHeader + "0,0,1,0,pressed\n0,1,1,2,pressed\n", "jump.csv"), CurveFormatError);
}

TEST(CurveDrops, ACurveWithADropMatchesItselfExactly) {
  const std::string text = kHeader +
                           "0,0,1,0,pressed\n"
                           "0.5,0.5,1,1,pressed\n"
                           "1,1,1,2,pressed\n"
                           "1,1,1,0.5,punctured\n"
                           "1.5,1.5,1,0.55,punctured\n"
                           "2,2,1,0.6,punctured\n";
  const InsertionCurve c = parse_insertion_curve(text, "ref.csv");
  const CurveComparison self = compare_curves(c, c);
  EXPECT_EQ(self.force_rmse_N, 0.0);
  EXPECT_EQ(self.n_compared, 4u);  // the two drop samples are left out
  // A model 0.1 N above the reference everywhere (same drop depth): RMSE 0.1 exactly.
  const InsertionCurve shifted = parse_insertion_curve(kHeader +
                                                           "0,0,1,0.1,pressed\n"
                                                           "0.5,0.5,1,1.1,pressed\n"
                                                           "1,1,1,2.1,pressed\n"
                                                           "1,1,1,0.6,punctured\n"
                                                           "1.5,1.5,1,0.65,punctured\n"
                                                           "2,2,1,0.7,punctured\n",
                                                       "model.csv");
  EXPECT_NEAR(compare_curves(shifted, c).force_rmse_N, 0.1, 1e-12);
}

}  // namespace
}  // namespace puncture::validation
