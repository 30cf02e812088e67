// Loop statistics: histogram quantiles agree with the exact order statistics
// of the same samples to one bin; missed deadlines and the achieved rate are
// counted as defined.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "puncture/realtime/loop_statistics.hpp"
#include "puncture/realtime/session_report.hpp"

namespace puncture::realtime {
namespace {

TEST(DurationHistogram, QuantilesMatchSortedSamplesToOneBin) {
  DurationHistogram h(0.25e-6, 5e-3);
  std::mt19937 rng(7);
  std::lognormal_distribution<double> dist(std::log(1e-3), 0.05);
  std::vector<double> samples(20000);
  for (double& s : samples) {
    s = dist(rng);
    h.add(s);
  }
  std::sort(samples.begin(), samples.end());
  for (double q : {0.5, 0.9, 0.99, 0.999}) {
    const double exact = samples[static_cast<std::size_t>(std::ceil(q * samples.size())) - 1];
    EXPECT_GE(h.quantile_s(q), exact) << q;
    EXPECT_LE(h.quantile_s(q), exact + h.bin_s()) << q;
  }
  EXPECT_DOUBLE_EQ(h.max_s(), samples.back());
  EXPECT_DOUBLE_EQ(h.min_s(), samples.front());
  EXPECT_EQ(h.count(), 20000);
}

TEST(DurationHistogram, OverflowKeepsTheExactMaximum) {
  DurationHistogram h(1e-6, 1e-3);
  for (int i = 0; i < 98; ++i) h.add(0.5e-3);
  h.add(7e-3);
  h.add(9e-3);
  EXPECT_EQ(h.overflow(), 2);
  EXPECT_DOUBLE_EQ(h.max_s(), 9e-3);
  EXPECT_DOUBLE_EQ(h.quantile_s(1.0), 9e-3);
  EXPECT_NEAR(h.quantile_s(0.5), 0.5e-3, 1e-6 + 1e-12);
  EXPECT_EQ(h.count_above(0.6e-3), 2);
  EXPECT_NEAR(h.mean_s(), (98 * 0.5e-3 + 16e-3) / 100.0, 1e-15);
}

TEST(LoopStatistics, CountsMissedDeadlinesAndRate) {
  LoopStatistics s;
  const double T = 1e-3;
  // 1001 ticks exactly 1 ms apart, each computing 10 us; ticks 100 and 500 overrun.
  for (int n = 0; n <= 1000; ++n) {
    const double start = 5.0 + n * T;
    const double end = start + ((n == 100 || n == 500) ? 1.2e-3 : 10e-6);
    s.add_tick(start, end, start + T);
  }
  EXPECT_EQ(s.count, 1001);
  EXPECT_EQ(s.missed_deadlines, 2);
  EXPECT_NEAR(s.achieved_rate_Hz(), 1000.0, 1e-6);
  EXPECT_EQ(s.period.count(), 1000);
  EXPECT_NEAR(s.period.quantile_s(0.5), T, s.period.bin_s());
  EXPECT_NEAR(s.work.quantile_s(0.99), 10e-6, s.work.bin_s());
  EXPECT_NEAR(s.work.max_s(), 1.2e-3, 1e-12);
}

TEST(ViewStatistics, FramesAtSixtyHertzGiveTheirRateAndRenderTimesInTheReport) {
  ViewStatistics v;
  // 121 frames 1/60 s apart, each rendered in 4 ms but the last in 30 ms.
  for (int n = 0; n <= 120; ++n) {
    const double start = 2.0 + n / 60.0;
    v.add(start, start + (n == 120 ? 30e-3 : 4e-3));
  }
  const nlohmann::json j = view_statistics_json(v, 60.0);
  EXPECT_EQ(j.at("frames").get<std::int64_t>(), 121);
  EXPECT_NEAR(j.at("achieved_fps").get<double>(), 60.0, 1e-9);
  EXPECT_NEAR(j.at("frame_period_ms").at("p50").get<double>(), 1e3 / 60.0, 1.01e-2);  // a quantile is its bin's upper edge (10 us)
  EXPECT_NEAR(j.at("render_ms").at("p50").get<double>(), 4.0, 1.01e-2);
  EXPECT_NEAR(j.at("render_ms").at("max").get<double>(), 30.0, 1e-9);
}

}  // namespace
}  // namespace puncture::realtime
