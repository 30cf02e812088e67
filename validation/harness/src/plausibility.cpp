// plausibility.cpp: see plausibility.hpp.
#include "puncture/validation/plausibility.hpp"

#include <cmath>
#include <sstream>

#include "puncture/scene_limits.hpp"

namespace puncture::validation {

std::vector<std::string> plausibility_warnings(const Scene& scene, const ScriptedRunResult& run) {
  std::vector<std::string> warnings;
  double peak = 0.0, peak_time = 0.0;
  for (const TickResult& t : run.ticks)
    if (std::abs(t.total_force_N) > std::abs(peak)) peak = t.total_force_N, peak_time = t.time_s;
  if (std::abs(peak) > scene_limits::kPlausibleForceN) {
    std::ostringstream w;
    w << "peak needle force " << peak << " N at t = " << peak_time << " s exceeds " << scene_limits::kPlausibleForceN
      << " N: not plausible for a needle in soft tissue (check the stiffness K, k_s and the damping d of the scene)";
    warnings.push_back(w.str());
  }
  const double target = scene.insertion.target_depth_m;
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const double bottom = scene.layer_top_depth_m(k) + scene.layers[k].thickness_m;
    if (!(bottom < target)) continue;
    bool punctured = false;
    for (const PunctureEvent& e : run.events) punctured = punctured || e.layer == static_cast<int>(k);
    if (!punctured) {
      std::ostringstream w;
      w << "layer '" << scene.layers[k].name << "' was not punctured although the target depth ("
        << target * 1e3 << " mm) lies below its bottom (" << bottom * 1e3
        << " mm): its breakthrough threshold or stiffness may be off";
      warnings.push_back(w.str());
    }
  }
  return warnings;
}

std::vector<std::size_t> decimated_tick_indices(const ScriptedRunResult& run, std::size_t max_rows, std::size_t& stride) {
  const std::size_t n = run.ticks.size();
  stride = 1;
  if (max_rows > 0 && n > max_rows) stride = (n + max_rows - 1) / max_rows;
  std::vector<std::size_t> kept;
  kept.reserve(n / stride + 2 * run.events.size() + 2);
  for (std::size_t i = 0; i < n; ++i) {
    bool keep = stride == 1 || i % stride == 0 || i + 1 == n;
    if (!keep && i > 0)
      for (std::size_t k = 0; k < run.ticks[i].layers.size() && !keep; ++k)
        keep = run.ticks[i].layers[k].state != run.ticks[i - 1].layers[k].state;
    if (keep) kept.push_back(i);
  }
  return kept;
}

}  // namespace puncture::validation
