// sweep.hpp: what accuracy costs in time (`puncture sweep`): every
// real-time fidelity knob varied one at a time around a scene's values,
// each variant's error against a reference curve (the finest FEM) and its
// cost, as table rows, CSV and markdown.
//
// Per variant: force RMSE over the insertion phase (N, and relative to the
// reference peak) and the puncture-depth error (RMS over the layers both
// models puncture; layers punctured by one model only count in
// missed_punctures); cost = mean and 99th percentile of the haptic-tick wall
// time over the ticks with contact (real-time; tick_cost in realtime_model.hpp:
// where the work is, not the median over all ticks, which is a tick without
// contact) or FEM wall time per load step. The real-time force compared is the whole
// force, the damping force d h v included (as validate and calibrate).
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "puncture/io/provenance.hpp"
#include "puncture/scene.hpp"
#include "puncture/validation/metrics.hpp"

namespace puncture::validation {

struct SweepRow {
  std::string model;    ///< "realtime" or "fem"
  std::string knob;     ///< e.g. "sh_degree"
  std::string value;    ///< the knob's value as text
  bool baseline = false;
  std::string status = "ok";
  double force_rmse_N = std::numeric_limits<double>::quiet_NaN();
  double force_rmse_relative = std::numeric_limits<double>::quiet_NaN();
  double puncture_depth_error_mm = std::numeric_limits<double>::quiet_NaN();
  int punctures_compared = 0;
  int missed_punctures = 0;
  double time_per_step_s = std::numeric_limits<double>::quiet_NaN();  ///< real-time: mean tick over the ticks with contact
  double time_p99_s = std::numeric_limits<double>::quiet_NaN();       ///< real-time: 99th percentile over the ticks with contact
  std::string time_kind;
  double n_dofs = std::numeric_limits<double>::quiet_NaN();
};

/// Errors of `model` against `reference` into row.
void fill_sweep_errors(SweepRow& row, const InsertionCurve& model, const InsertionCurve& reference);

/// One real-time variant: validates the scene (an invalid variant gets status
/// "invalid: <scene error>"), runs the scripted insertion, compares.
SweepRow sweep_realtime_variant(const Scene& scene, const std::string& knob, const std::string& value, bool baseline,
                                const InsertionCurve& reference);

/// Every real-time knob around the scene's values: SH degree l, rings w (added
/// to every layer), spacing L (factor on every layer), integrator, haptic
/// rate. on_variant(knob, value) is called before each variant runs.
std::vector<SweepRow> sweep_realtime_knobs(const Scene& scene, const InsertionCurve& reference,
                                           const std::function<void(const std::string& knob, const std::string& value)>&
                                               on_variant = {});

/// accuracy_cost.csv with the provenance header.
std::string sweep_table_csv(const std::vector<SweepRow>& rows, const io::Provenance& provenance);
/// accuracy_cost.md.
std::string sweep_table_markdown(const Scene& scene, const std::vector<SweepRow>& rows, const std::string& finest,
                                 const io::Provenance& provenance, const std::vector<std::string>& plots);

}  // namespace puncture::validation
