// calibration_report.cpp: see calibration_report.hpp.
#include "puncture/validation/calibration_report.hpp"

#include <iomanip>
#include <sstream>

#include "puncture/io/csv_writer.hpp"

namespace puncture::validation {

std::string calibration_metrics_table(const CalibrationResult& r) {
  std::ostringstream s;
  s << "| layer | force RMSE before (N) | after (N) | after (% of reference peak) | puncture depth error before (mm) "
       "| after (mm) |\n"
       "|---|---|---|---|---|---|\n";
  if (r.before.empty() || r.after.empty()) return s.str();
  for (const auto& before : r.before.front().layers) {
    const LayerMetrics* after = r.after.front().layer(before.layer);
    s << "| " << before.layer << " | " << std::setprecision(4) << before.force_rmse_N << " | "
      << (after ? after->force_rmse_N : 0.0) << " | " << std::setprecision(3)
      << (after ? 100.0 * after->force_rmse_relative : 0.0) << " | " << std::setprecision(4)
      << before.puncture_depth_error_m * 1e3 << " | " << (after ? after->puncture_depth_error_m * 1e3 : 0.0)
      << " |\n";
  }
  return s.str();
}

std::string calibration_curves_csv(const std::vector<std::pair<std::string, const InsertionCurve*>>& curves,
                                   const io::Provenance& provenance) {
  io::CsvWriter csv({"curve", "time_s", "depth_mm", "force_N"});
  csv.add_provenance(provenance);
  for (const auto& [name, c] : curves)
    for (std::size_t i = 0; i < c->size(); ++i) {
      if (i > 0 && c->velocity_m_per_s[i] < 0.0) break;  // withdrawal: not compared
      csv.text(name).number(c->time_s[i], 9).number(c->depth_m[i] * 1e3, 9).number(c->force_N[i], 9).end_row();
    }
  return csv.str();
}

}  // namespace puncture::validation
