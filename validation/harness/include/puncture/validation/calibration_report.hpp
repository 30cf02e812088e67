// calibration_report.hpp: the report files of `puncture calibrate` beside the
// tuned preset (calibration.hpp writes the preset and its provenance).
//
// calibration_metrics_table(result): markdown table, per layer force RMSE and
//   puncture-depth error before and after, against the first reference.
// calibration_curves_csv(curves, provenance): curve,time_s,depth_mm,force_N
//   rows of the insertion phase of each named curve (reference, before,
//   after), with the provenance header; read by scripts/plot_calibration.py.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "puncture/io/provenance.hpp"
#include "puncture/validation/calibration.hpp"
#include "puncture/validation/metrics.hpp"

namespace puncture::validation {

std::string calibration_metrics_table(const CalibrationResult& result);

std::string calibration_curves_csv(const std::vector<std::pair<std::string, const InsertionCurve*>>& curves,
                                   const io::Provenance& provenance);

}  // namespace puncture::validation
