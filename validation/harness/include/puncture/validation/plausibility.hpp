// plausibility.hpp: checks a real-time run against what is physically
// plausible, so a mistyped parameter (K = 1e300) does not pass silently.
//
// In:  the scene and the scripted run's result.
// Out: human-readable warnings (empty if nothing is suspicious):
//   * the needle force exceeds scene_limits::kPlausibleForceN (50 N: needle
//     insertion into soft tissue needs a few newtons; tens of newtons mean a
//     stiffness off by orders of magnitude);
//   * a layer whose bottom lies above the target depth (the needle must pass
//     through it) was not punctured.
// `puncture run` prints them on stderr and stores them in summary.json.
#pragma once

#include <string>
#include <vector>

#include "puncture/model/realtime_model.hpp"
#include "puncture/scene.hpp"

namespace puncture::validation {

std::vector<std::string> plausibility_warnings(const Scene& scene, const ScriptedRunResult& run);

/// Which ticks realtime_curve.csv keeps: all when ticks <= max_rows, else
/// every stride-th tick plus every tick at which a layer's state changes and
/// the last tick. Returns the kept indices in order; stride is set to the
/// step used (1 without decimation).
std::vector<std::size_t> decimated_tick_indices(const ScriptedRunResult& run, std::size_t max_rows, std::size_t& stride);

}  // namespace puncture::validation
