// recording_scatter.hpp: several recordings of one tissue in one calibration
// report: the recordings left out of the fit judged with the tuned model
// (held out), and the scatter of the repeats of a condition beside the
// model's error.
//
// judge_recordings(start, result, fitted, held_out, options): every
//   recording, fitted (the calibration's references, in order) and held out,
//   with the model before (the start scene) and after (the tuned scene) run
//   on its trajectory (calibration_run_scene: its speed, depth, dwell and
//   withdrawal), its punctures (the fitted ones as the calibration found
//   them, the held-out ones from their force drops, doubts noted, never an
//   error) and the whole-trajectory objective of each model against it
//   (compare_trajectory, the calibration's weights).
// repeat_scatter(recordings, options): the recordings grouped by insertion
//   speed (a recording joins a group when its speed is within
//   speed_tolerance of the group's slowest; fitted and held-out together),
//   and for each group:
//   * per layer, the punctures of the recordings that show one: force and
//     depth mean, sample standard deviation, min and max, beside the tuned
//     model's puncture at that speed, and whether the model's lies inside
//     [min, max];
//   * the curve band: on a grid of grid_points depths from 0 (contact) to the
//     shallowest of the members' deepest insertion samples, each member's
//     insertion force (linear between its samples), their pointwise min and
//     max and mean, and the tuned model's force (the group's first member's
//     model run); the band's mean width; the fraction of grid depths where
//     the model lies inside the band; the model's RMSE from the repeats' mean
//     beside the repeats' own RMS deviation from it (the scatter the fit
//     should sit in), both over the mean's peak; the model "sits inside" the
//     band when that fraction is at least inside_fraction. The band holds the
//     sensor noise too (each recording's noise sigma is listed).
//   A group of one recording has no scatter (listed, no band).
// recordings_markdown / repeat_scatter_markdown / repeat_scatter_csv: the
//   report's sections and the band's CSV (group, speed, depth, min, max,
//   mean, model), read by scripts/plot_calibration.py.
#pragma once

#include <string>
#include <vector>

#include "puncture/io/provenance.hpp"
#include "puncture/validation/calibration.hpp"

namespace puncture::validation {

/// One recording with the model before and after run on its trajectory.
struct JudgedRecording {
  ReferenceCurve reference;
  bool held_out = false;
  double speed_m_per_s = 0.0;
  ReferenceEvents events;
  InsertionCurve model_before, model_after;
  TrajectoryComparison before, after;
};

/// fitted: the references calibrate() was given (result's events and model
/// curves are reused); held_out: recordings not in the fit.
std::vector<JudgedRecording> judge_recordings(const Scene& start, const CalibrationResult& result,
                                              const std::vector<ReferenceCurve>& fitted,
                                              const std::vector<ReferenceCurve>& held_out,
                                              const CalibrationOptions& options);

struct RepeatScatterOptions {
  double speed_tolerance = 0.05;  ///< relative: same condition within 5 % of the speed
  int grid_points = 200;
  double inside_fraction = 0.9;   ///< the model sits inside the band at >= 90 % of the grid depths
};

/// Mean, sample standard deviation (0 for one value), min and max.
struct Spread {
  std::size_t n = 0;
  double mean = 0.0, sd = 0.0, min = 0.0, max = 0.0;
};
Spread spread_of(const std::vector<double>& values);

struct LayerScatter {
  std::size_t layer = 0;     ///< index into the scene's layers
  Spread force_N, depth_m;   ///< over the members that show the layer's puncture
  bool model_found = false;
  double model_force_N = 0.0, model_depth_m = 0.0;
  bool force_inside = false, depth_inside = false;  ///< the model's within [min, max]
};

struct RepeatGroup {
  double speed_m_per_s = 0.0;             ///< mean of the members'
  std::vector<std::size_t> members;       ///< indices into the recordings
  std::vector<LayerScatter> layers;       ///< every layer a member punctures
  std::vector<double> depth_m, band_min_N, band_max_N, mean_N, model_N;  ///< the band's grid (empty for one member)
  double band_width_N = 0.0;              ///< mean of max - min over the grid
  double peak_N = 0.0;                    ///< the mean curve's largest force
  double model_inside_fraction = 0.0;
  double model_rmse_relative = 0.0;       ///< model - mean, RMS over the grid, / peak_N
  double repeats_rms_relative = 0.0;      ///< members - mean, RMS over members and grid, / peak_N
  bool model_inside = false;              ///< model_inside_fraction >= options.inside_fraction
};

std::vector<RepeatGroup> repeat_scatter(const std::vector<JudgedRecording>& recordings,
                                        const RepeatScatterOptions& options = {});

/// "## Recordings": every recording (fitted or held out), speed, objective before and after, force RMSE and punctures.
std::string recordings_markdown(const std::vector<JudgedRecording>& recordings, const Scene& scene);
/// "## Scatter of repeats": per group its spread beside the model's error and the verdict.
/// model_label names the model judged ("calibrated model"; `validate` judges the scene's own).
std::string repeat_scatter_markdown(const std::vector<JudgedRecording>& recordings,
                                    const std::vector<RepeatGroup>& groups, const Scene& scene,
                                    const RepeatScatterOptions& options = {},
                                    const std::string& model_label = "calibrated model");
/// group,speed_mm_per_s,depth_mm,band_min_N,band_max_N,mean_N,model_N rows (groups of two or more).
std::string repeat_scatter_csv(const std::vector<RepeatGroup>& groups, const io::Provenance& provenance);

}  // namespace puncture::validation
