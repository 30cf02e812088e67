// calibration_report.hpp: the report files of `puncture calibrate` beside the
// tuned preset (calibration.hpp writes the preset and its provenance).
//
// calibration_terms_table(result): markdown table of every objective term
//   against the first reference, before and after ("n/a" where a term could
//   not be computed), with its error, weight, reference samples and note, then
//   a line stating the normalisation and the objective before and after.
// calibration_punctures_table(result, scene): how the reference's punctures
//   were found and, per layer, their depth (mm) and force (N) beside the
//   calibrated model's; empty when there is no reference event.
// calibration_parameters_table(result): every tuned parameter with its start,
//   tuned value, physical bounds and whether it ended at one.
// calibration_identifiability_table(result): per parameter (tuned, then
//   withheld) its value, sensitivity, standard error, status and reason, then
//   the correlated pairs (|r| > 0.95) and the correlation matrix.
// calibration_identifiability_report(result, name): that table as the page
//   <name>.identifiability.md written beside every tuned preset.
// calibration_summary_markdown(result, scene, reference, provenance, method,
//   seconds, preset_name): calibration_summary.md: the command, machine and
//   date, the reference, method, model runs and wall time, the objective
//   before and after, then the tables above, d's note and the warnings.
// calibration_curves_csv(curves, provenance): curve,time_s,depth_mm,force_N,phase
//   rows of the whole trajectory of each named curve (reference, before,
//   after; phase insertion, dwell or withdrawal), with the provenance header;
//   read by scripts/plot_calibration.py.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "puncture/io/provenance.hpp"
#include "puncture/scene.hpp"
#include "puncture/validation/calibration.hpp"
#include "puncture/validation/metrics.hpp"

namespace puncture::validation {

std::string calibration_terms_table(const CalibrationResult& result);

std::string calibration_punctures_table(const CalibrationResult& result, const Scene& scene);

std::string calibration_parameters_table(const CalibrationResult& result);

std::string calibration_identifiability_table(const CalibrationResult& result);

std::string calibration_identifiability_report(const CalibrationResult& result, const std::string& preset_name);

std::string calibration_summary_markdown(const CalibrationResult& result, const Scene& scene,
                                        const ReferenceCurve& reference, const io::Provenance& provenance,
                                        const std::string& method, double seconds, const std::string& preset_name);

std::string calibration_curves_csv(const std::vector<std::pair<std::string, const InsertionCurve*>>& curves,
                                   const io::Provenance& provenance);

}  // namespace puncture::validation
