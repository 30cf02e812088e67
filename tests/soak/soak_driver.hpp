// soak_driver.hpp: a long run of the haptic tick over random needle
// trajectories, checking what must hold at every tick.
//
// Episodes: each builds a fresh real-time model (scenes/default.json with
// EVERY effect the scene schema knows turned on: scene_io's known_effects(),
// so an effect added to the schema is soaked without touching this file;
// effect-specific scene changes go in SoakOptions::scene_edits, one line
// each; with layer_interaction on, layers below the first that use the ring
// rule get a critical_force breakthrough at the force the ring rule broke
// them with in a scripted insertion of the scene without layer_interaction,
// because scene_io refuses the ring rule there), the integrator cycling through quasi_static, explicit, implicit,
// and drives it with a random trajectory: segments to random depths between
// the start height and near the sample base (so some pass every layer and
// most reverse), each at a random speed (log-uniform in [min, max]), with
// random dwells in between, a random lateral offset of the needle's entry
// point (x, y in [-max_offset, max_offset]) and a random inclination of the
// needle (angle to the surface normal in [0, max_angle], any azimuth: the
// tip moves on the inclined line through the entry point, as a device may
// hold it). Ticks are 1 / haptic_rate_Hz apart.
//
// Checks per tick (violations are counted, the first few described):
//   * every force (total, per layer surface and damping) is finite; tick()
//     itself throws on a non-finite force, which counts as a failure too;
//   * bounded energy (passivity): the elastic energy of the intact force
//     meshes never exceeds the work the needle did on them,
//     W = sum over ticks and pressed layers of the trapezoid
//     0.5 (F_prev + F) (delta - delta_prev) with F the layer's surface force
//     and delta its contact deflection, plus a tolerance of
//     energy_rel_tolerance * W + 1e-9 J;
//   * no heap allocation inside tick() (allocation_counter.hpp).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace puncture::soak {

struct SoakOptions {
  long long ticks = 1000000;          ///< total haptic ticks over all episodes
  std::uint64_t seed = 1;
  long long min_episode_ticks = 5000;
  long long max_episode_ticks = 60000;
  double min_speed_mm_per_s = 0.5;
  double max_speed_mm_per_s = 200.0;
  double max_lateral_offset_mm = 1.0;
  double max_angle_deg = 30.0;        ///< inclination of the needle to the surface normal (uniform in [0, max])
  double dwell_probability = 0.3;     ///< after each segment
  double max_dwell_s = 1.0;
  double energy_rel_tolerance = 0.02;
  std::string scene_path;             ///< empty: scenes/default.json of the source tree
  /// Extra edits of the scene JSON (text -> text) applied before parsing.
  std::vector<std::function<void(std::string& scene_json)>> scene_edits;
};

struct SoakReport {
  long long ticks = 0;
  long long episodes = 0;
  std::vector<std::string> effects;      ///< effects that were on
  long long ticks_per_integrator[3] = {0, 0, 0};  ///< quasi_static, explicit, implicit
  long long punctures = 0;
  long long episodes_all_punctured = 0;
  long long reversals = 0;               ///< insertion <-> withdrawal changes of direction
  long long dwell_ticks = 0;
  double max_speed_mm_per_s = 0.0;
  double max_angle_deg = 0.0;            ///< largest inclination an episode used
  double max_abs_force_N = 0.0;
  double max_energy_J = 0.0;
  double max_energy_to_work = 0.0;       ///< max over ticks of E / (W + 1e-9 J)
  long long non_finite = 0;              ///< ticks with a non-finite force (incl. tick() throwing)
  long long energy_violations = 0;
  long long allocations = 0;             ///< heap allocations inside tick()
  bool allocation_count_from_sanitizer = false;
  double wall_time_s = 0.0;
  double median_tick_us = 0.0;           ///< over a sample of ticks
  double p99_tick_us = 0.0;
  std::vector<std::string> failures;     ///< first few violations, described

  bool passed() const { return non_finite == 0 && energy_violations == 0 && allocations == 0; }
};

/// Runs the soak; progress(fraction) about every 5 %.
SoakReport run_soak(const SoakOptions& options, const std::function<void(double)>& progress = {});

}  // namespace puncture::soak
