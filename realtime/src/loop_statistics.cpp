#include "puncture/realtime/loop_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace puncture::realtime {

DurationHistogram::DurationHistogram(double bin_s, double range_s) : bin_s_(bin_s), range_s_(range_s) {
  if (!(bin_s > 0.0) || !(range_s > bin_s)) throw std::invalid_argument("DurationHistogram: need 0 < bin < range");
  bins_.assign(static_cast<std::size_t>(std::ceil(range_s / bin_s)), 0);
}

void DurationHistogram::add(double d) noexcept {
  if (!(d >= 0.0)) d = 0.0;  // a clock that stood still (or NaN) counts as zero
  if (count_ == 0) min_ = max_ = d;
  min_ = std::min(min_, d);
  max_ = std::max(max_, d);
  sum_ += d;
  ++count_;
  const auto i = static_cast<std::size_t>(d / bin_s_);
  if (i < bins_.size())
    ++bins_[i];
  else
    ++overflow_;
}

void DurationHistogram::clear() noexcept {
  std::fill(bins_.begin(), bins_.end(), 0);
  count_ = overflow_ = 0;
  min_ = max_ = sum_ = 0.0;
}

double DurationHistogram::quantile_s(double q) const {
  if (count_ == 0) return 0.0;
  q = std::clamp(q, 0.0, 1.0);
  // Smallest bin edge below which at least ceil(q * count) samples lie.
  const auto needed = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(q * static_cast<double>(count_))));
  std::int64_t seen = 0;
  for (std::size_t i = 0; i < bins_.size(); ++i) {
    seen += bins_[i];
    if (seen >= needed) return std::min(max_, static_cast<double>(i + 1) * bin_s_);
  }
  return max_;
}

std::int64_t DurationHistogram::count_above(double threshold_s) const {
  std::int64_t n = overflow_;
  const auto first = static_cast<std::size_t>(std::max(0.0, std::ceil(threshold_s / bin_s_)));
  for (std::size_t i = first; i < bins_.size(); ++i) n += bins_[i];
  return n;
}

void PeriodicTiming::add(double start_s, double end_s) noexcept {
  if (count == 0)
    first_start_s = start_s;
  else
    period.add(start_s - last_start_s);
  last_start_s = start_s;
  work.add(end_s - start_s);
  ++count;
}

double PeriodicTiming::achieved_rate_Hz() const {
  if (count < 2 || !(last_start_s > first_start_s)) return 0.0;
  return static_cast<double>(count - 1) / (last_start_s - first_start_s);
}

void LoopStatistics::add_tick(double start_s, double end_s, double deadline_s) noexcept {
  add(start_s, end_s);
  if (end_s > deadline_s) ++missed_deadlines;
}

}  // namespace puncture::realtime
