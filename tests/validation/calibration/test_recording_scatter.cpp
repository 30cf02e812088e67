// The scatter of repeats (recording_scatter.hpp) on curves with known
// spreads: grouping by speed, the punctures' mean, SD and range, the band of
// the insertion forces and the model's place in it, against closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "puncture/validation/recording.hpp"
#include "puncture/validation/recording_scatter.hpp"

namespace pv = puncture::validation;

namespace {

/// A straight insertion curve F = slope x depth, 0 to 10 mm in 0.05 mm steps, at `speed_mm_per_s`.
pv::InsertionCurve ramp(double slope_N_per_mm, double speed_mm_per_s) {
  std::ostringstream csv;
  csv << "# speed_mm_per_s: " << speed_mm_per_s << "\ndepth_mm,force_N\n";
  for (int i = 0; i <= 200; ++i) csv << 0.05 * i << ',' << slope_N_per_mm * 0.05 * i << '\n';
  return pv::parse_insertion_curve(csv.str(), "ramp_" + std::to_string(slope_N_per_mm));
}

/// A recording (a ramp) with one puncture of layer 0 and the model (another ramp) with its own.
pv::JudgedRecording recording(double slope, double speed_mm_per_s, double puncture_N, double model_slope,
                              double model_puncture_N) {
  pv::JudgedRecording j;
  j.reference.curve = ramp(slope, speed_mm_per_s);
  j.reference.kind = "measured";
  j.speed_m_per_s = speed_mm_per_s * 1e-3;
  j.events.punctures.resize(1);
  j.events.punctures[0] = {true, puncture_N / slope * 1e-3, puncture_N};
  j.model_after = ramp(model_slope, speed_mm_per_s);
  j.after.model_punctures = {{true, model_puncture_N / model_slope * 1e-3, model_puncture_N}};
  return j;
}

}  // namespace

TEST(RecordingScatter, SpreadIsMeanSampleDeviationAndRange) {
  const pv::Spread s = pv::spread_of({1.0, 2.0, 3.0, 6.0});
  EXPECT_EQ(s.n, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 3.0);
  EXPECT_DOUBLE_EQ(s.sd, std::sqrt(14.0 / 3.0));
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 6.0);
  EXPECT_DOUBLE_EQ(pv::spread_of({2.5}).sd, 0.0);
}

TEST(RecordingScatter, RepeatsOfASpeedGiveTheBandAndTheModelInsideIt) {
  // Two repeats at 2 and 2.05 mm/s (within 5 %: one condition), slopes 1.0 and
  // 1.2 N/mm, punctures at 2.0 and 2.4 N; one recording at 3 mm/s. The model
  // (slope 1.1, puncture 2.2 N) lies between the repeats everywhere.
  const std::vector<pv::JudgedRecording> inside{recording(1.0, 2.0, 2.0, 1.1, 2.2), recording(1.2, 2.05, 2.4, 1.1, 2.2),
                                                recording(1.0, 3.0, 2.0, 1.1, 2.2)};
  pv::RepeatScatterOptions o;
  const std::vector<pv::RepeatGroup> groups = pv::repeat_scatter(inside, o);
  ASSERT_EQ(groups.size(), 2u);
  ASSERT_EQ(groups[0].members, (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(groups[1].members, (std::vector<std::size_t>{2}));
  EXPECT_TRUE(groups[1].depth_m.empty());  // one recording: no band
  const pv::RepeatGroup& g = groups[0];
  EXPECT_NEAR(g.speed_m_per_s, 2.025e-3, 1e-12);
  ASSERT_EQ(g.layers.size(), 1u);
  EXPECT_DOUBLE_EQ(g.layers[0].force_N.mean, 2.2);
  EXPECT_NEAR(g.layers[0].force_N.sd, std::sqrt(0.08), 1e-12);
  EXPECT_NEAR(g.layers[0].depth_m.min, 2e-3, 1e-12);
  EXPECT_TRUE(g.layers[0].force_inside);
  EXPECT_TRUE(g.layers[0].depth_inside);  // 2.2 N / 1.1 N/mm = 2 mm, the repeats' 2 mm
  // Band: 0 to 10 mm; width 0.2 d, mean over the grid 1 mm; the model is the
  // repeats' mean (RMSE 0); the repeats lie 0.1 d from it:
  // RMS 0.1 sqrt(mean d^2) with mean d^2 = 100 (2N + 1) / (6 N) mm^2 on the
  // N + 1 = 200 points d_i = 10 i / N mm, over the mean's peak 11 N.
  ASSERT_EQ(g.depth_m.size(), 200u);
  EXPECT_NEAR(g.band_width_N, 1.0, 1e-9);
  EXPECT_NEAR(g.peak_N, 11.0, 1e-9);
  EXPECT_NEAR(g.model_rmse_relative, 0.0, 1e-12);
  const double n = 199.0, mean_d2 = 100.0 * (2 * n + 1) / (6 * n);
  EXPECT_NEAR(g.repeats_rms_relative, 0.1 * std::sqrt(mean_d2) / 11.0, 1e-9);
  EXPECT_DOUBLE_EQ(g.model_inside_fraction, 1.0);
  EXPECT_TRUE(g.model_inside);

  // A model stiffer than both repeats (slope 1.5, puncture 3 N) is outside:
  // only at depth 0, where all three are 0, does it touch the band.
  std::vector<pv::JudgedRecording> outside = inside;
  outside[0] = recording(1.0, 2.0, 2.0, 1.5, 3.0);
  const pv::RepeatGroup h = pv::repeat_scatter(outside, o)[0];
  EXPECT_DOUBLE_EQ(h.model_inside_fraction, 1.0 / 200.0);
  EXPECT_FALSE(h.model_inside);
  EXPECT_FALSE(h.layers[0].force_inside);
  EXPECT_NEAR(h.model_rmse_relative, 0.4 * std::sqrt(mean_d2) / 11.0, 1e-9);
  const puncture::Scene scene = [] {
    puncture::Scene s;
    s.layers.resize(1);
    s.layers[0].name = "skin";
    return s;
  }();
  const std::string md = pv::repeat_scatter_markdown(outside, {h}, scene, o);
  EXPECT_NE(md.find("| skin (2 of 2) | 2.2 +- 0.28 [2, 2.4] | 3 | **no** |"), std::string::npos) << md;
  EXPECT_NE(md.find("**it does not sit inside the scatter.**"), std::string::npos) << md;
}
