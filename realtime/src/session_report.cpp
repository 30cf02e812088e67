#include "puncture/realtime/session_report.hpp"

#include <fstream>

namespace puncture::realtime {

nlohmann::json haptic_statistics_json(const LoopStatistics& s, double target_rate_Hz) {
  auto us = [](double seconds) { return seconds * 1e6; };
  const double rate = s.achieved_rate_Hz();
  return {{"target_rate_Hz", target_rate_Hz},
          {"achieved_rate_Hz", rate},
          {"rate_error_percent", target_rate_Hz > 0 ? 100.0 * (rate - target_rate_Hz) / target_rate_Hz : 0.0},
          {"ticks", s.count},
          {"duration_s", s.last_start_s - s.first_start_s},
          {"tick_period_us",
           {{"p50", us(s.period.quantile_s(0.5))},
            {"p99", us(s.period.quantile_s(0.99))},
            {"p999", us(s.period.quantile_s(0.999))},
            {"max", us(s.period.max_s())},
            {"min", us(s.period.min_s())},
            {"mean", us(s.period.mean_s())}}},
          {"tick_compute_us",
           {{"p50", us(s.work.quantile_s(0.5))},
            {"p99", us(s.work.quantile_s(0.99))},
            {"max", us(s.work.max_s())},
            {"mean", us(s.work.mean_s())}}},
          {"missed_deadlines", s.missed_deadlines},
          {"skipped_periods", s.skipped_periods},
          {"histogram_bin_us", us(s.period.bin_s())}};
}

nlohmann::json view_statistics_json(const ViewStatistics& s, double target_fps) {
  auto ms = [](double seconds) { return seconds * 1e3; };
  return {{"target_fps", target_fps},
          {"frames", s.count},
          {"achieved_fps", s.achieved_rate_Hz()},
          {"frame_period_ms",
           {{"p50", ms(s.period.quantile_s(0.5))},
            {"p99", ms(s.period.quantile_s(0.99))},
            {"max", ms(s.period.max_s())}}},
          {"render_ms",
           {{"p50", ms(s.work.quantile_s(0.5))},
            {"p99", ms(s.work.quantile_s(0.99))},
            {"max", ms(s.work.max_s())}}}};
}

nlohmann::json load_average_json() {
  std::ifstream in("/proc/loadavg");
  double a = 0, b = 0, c = 0;
  if (!(in >> a >> b >> c)) return nlohmann::json::array();
  return {a, b, c};
}

}  // namespace puncture::realtime
