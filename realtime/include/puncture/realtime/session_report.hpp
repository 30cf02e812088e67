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

/// The view's frames (work: update and render one frame), binned at 10 us up to 1 s.
struct ViewStatistics : PeriodicTiming {
  ViewStatistics() : PeriodicTiming(10e-6, 1.0) {}
};

nlohmann::json haptic_statistics_json(const LoopStatistics& stats, double target_rate_Hz);
nlohmann::json view_statistics_json(const ViewStatistics& stats, double target_fps);

/// The 1-minute, 5-minute and 15-minute load averages from /proc/loadavg ([] if unreadable).
nlohmann::json load_average_json();

}  // namespace puncture::realtime
