// loop_statistics.hpp: timing statistics of the haptic loop, gathered in the
// haptic thread without allocation.
//
// DurationHistogram: fixed bins of width `bin_s` from 0 to `range_s`, plus an
// overflow count; exact minimum, maximum and mean. quantile(q) returns the
// upper edge of the bin holding the q-quantile (so it errs high by at most
// one bin; an overflowing quantile returns the exact maximum).
// PeriodicTiming: a periodic activity's timing (the haptic loop's ticks, the
// view's frames): per occurrence, the period (its start minus the previous
// start) and its work (start to end); the count; achieved rate = (count - 1) /
// (start of the last - start of the first).
// LoopStatistics: the haptic ticks' PeriodicTiming (work = compute time), the
// number of missed deadlines (a tick whose work ended after the next tick's
// scheduled start) and of skipped periods (whole periods lost when the loop
// fell more than one period behind and re-synchronised instead of bursting).
// Units: seconds in, seconds out.
#pragma once

#include <cstdint>
#include <vector>

namespace puncture::realtime {

class DurationHistogram {
 public:
  DurationHistogram(double bin_s, double range_s);
  void add(double duration_s) noexcept;
  void clear() noexcept;

  std::int64_t count() const { return count_; }
  std::int64_t overflow() const { return overflow_; }
  double min_s() const { return count_ ? min_ : 0.0; }
  double max_s() const { return count_ ? max_ : 0.0; }
  double mean_s() const { return count_ ? sum_ / static_cast<double>(count_) : 0.0; }
  /// q in [0, 1]; 0 with no samples.
  double quantile_s(double q) const;
  /// Samples strictly above `threshold_s` (to bin resolution: counts whole bins above it, plus overflow).
  std::int64_t count_above(double threshold_s) const;
  double bin_s() const { return bin_s_; }

 private:
  double bin_s_, range_s_;
  std::vector<std::int64_t> bins_;
  std::int64_t count_ = 0, overflow_ = 0;
  double min_ = 0.0, max_ = 0.0, sum_ = 0.0;
};

struct PeriodicTiming {
  PeriodicTiming(double bin_s, double range_s) : period(bin_s, range_s), work(bin_s, range_s) {}
  DurationHistogram period;  ///< start-to-start interval between consecutive occurrences (s)
  DurationHistogram work;    ///< start to end of each (s)
  std::int64_t count = 0;
  double first_start_s = 0.0;  ///< steady-clock time of the first one's start
  double last_start_s = 0.0;

  /// Records one occurrence; `start_s`/`end_s` on the steady clock.
  void add(double start_s, double end_s) noexcept;
  /// (count - 1) / (last start - first start); 0 below two occurrences.
  double achieved_rate_Hz() const;
};

/// The haptic loop: ticks binned at 0.25 us up to 20 ms.
struct LoopStatistics : PeriodicTiming {
  LoopStatistics() : PeriodicTiming(0.25e-6, 20e-3) {}
  std::int64_t missed_deadlines = 0;
  std::int64_t skipped_periods = 0;

  /// Records one tick; `start_s`/`end_s` on the steady clock, `deadline_s` = scheduled start of the next tick.
  void add_tick(double start_s, double end_s, double deadline_s) noexcept;
};

}  // namespace puncture::realtime
