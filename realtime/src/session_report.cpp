#include "puncture/realtime/session_report.hpp"

#include <fstream>

namespace puncture::realtime {

void ViewStatistics::add_frame(double start_s, double end_s) {
  if (frames == 0)
    first_s = start_s;
  else
    frame_period.add(start_s - last_s);
  last_s = start_s;
  render.add(end_s - start_s);
  ++frames;
}

double ViewStatistics::achieved_fps() const {
  return frames >= 2 && last_s > first_s ? static_cast<double>(frames - 1) / (last_s - first_s) : 0.0;
}

nlohmann::json haptic_statistics_json(const LoopStatistics& s, double target_rate_Hz) {
  auto us = [](double seconds) { return seconds * 1e6; };
  const double rate = s.achieved_rate_Hz();
  return {{"target_rate_Hz", target_rate_Hz},
          {"achieved_rate_Hz", rate},
          {"rate_error_percent", target_rate_Hz > 0 ? 100.0 * (rate - target_rate_Hz) / target_rate_Hz : 0.0},
          {"ticks", s.ticks},
          {"duration_s", s.last_start_s - s.first_start_s},
          {"tick_period_us",
           {{"p50", us(s.period.quantile_s(0.5))},
            {"p99", us(s.period.quantile_s(0.99))},
            {"p999", us(s.period.quantile_s(0.999))},
            {"max", us(s.period.max_s())},
            {"min", us(s.period.min_s())},
            {"mean", us(s.period.mean_s())}}},
          {"tick_compute_us",
           {{"p50", us(s.compute.quantile_s(0.5))},
            {"p99", us(s.compute.quantile_s(0.99))},
            {"max", us(s.compute.max_s())},
            {"mean", us(s.compute.mean_s())}}},
          {"missed_deadlines", s.missed_deadlines},
          {"skipped_periods", s.skipped_periods},
          {"histogram_bin_us", us(s.period.bin_s())}};
}

nlohmann::json view_statistics_json(const ViewStatistics& s, double target_fps) {
  auto ms = [](double seconds) { return seconds * 1e3; };
  return {{"target_fps", target_fps},
          {"frames", s.frames},
          {"achieved_fps", s.achieved_fps()},
          {"frame_period_ms",
           {{"p50", ms(s.frame_period.quantile_s(0.5))},
            {"p99", ms(s.frame_period.quantile_s(0.99))},
            {"max", ms(s.frame_period.max_s())}}},
          {"render_ms",
           {{"p50", ms(s.render.quantile_s(0.5))},
            {"p99", ms(s.render.quantile_s(0.99))},
            {"max", ms(s.render.max_s())}}}};
}

nlohmann::json load_average_json() {
  std::ifstream in("/proc/loadavg");
  double a = 0, b = 0, c = 0;
  if (!(in >> a >> b >> c)) return nlohmann::json::array();
  return {a, b, c};
}

}  // namespace puncture::realtime
