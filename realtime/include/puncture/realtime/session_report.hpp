// session_report.hpp: the loop statistics of a session as JSON (the
// --stats file of puncture-app) and as a one-line summary.
//   haptic: target and achieved rate (Hz), tick period and compute time
//           quantiles (us), missed deadlines, skipped periods, scheduling;
//   view:   frames, achieved frame rate, frame time quantiles (ms).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "puncture/realtime/loop_statistics.hpp"

namespace puncture::realtime {

struct ViewStatistics {
  ViewStatistics() : frame_period(10e-6, 1.0), render(10e-6, 1.0) {}
  DurationHistogram frame_period;  ///< start-to-start interval between frames (s)
  DurationHistogram render;        ///< time to update and render one frame (s)
  std::int64_t frames = 0;
  double first_s = 0.0, last_s = 0.0;
  void add_frame(double start_s, double end_s);
  double achieved_fps() const;
};

nlohmann::json haptic_statistics_json(const LoopStatistics& stats, double target_rate_Hz);
nlohmann::json view_statistics_json(const ViewStatistics& stats, double target_fps);

/// The 1-minute, 5-minute and 15-minute load averages from /proc/loadavg ([] if unreadable).
nlohmann::json load_average_json();

}  // namespace puncture::realtime
