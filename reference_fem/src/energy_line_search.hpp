// energy_line_search.hpp (internal): the 3D solver's fallback line search on
// the potential's slope along the Newton direction (Matthies & Strang 1979).
//
// energy_line_search(slope0, max_trials, slope_at):
//   slope0: g(0) = du . R(u), the potential's slope along the Newton direction
//   du at the iterate (N m; < 0 for a descent direction, else nullopt).
//   slope_at(alpha) makes u + alpha du the trial state and returns its slope
//   g(alpha) = du . R(u + alpha du), or nullopt if that state is inadmissible
//   (an inverted or non-finite element). At most max_trials calls.
// Out: a step length alpha in (0, 1]: the first admissible of 1, 1/2, 1/4, ...
//   if the potential still falls there (g <= 0) or its slope is within half of
//   |slope0|; otherwise the root of g between 0 and that end by regula falsi
//   (Illinois), accepted once |g(alpha)| <= |slope0| / 2, or the longest step
//   found on the descending side (g < 0) when the trials run out; nullopt if no
//   trial was admissible or none descended.
#pragma once

#include <cmath>
#include <optional>

namespace puncture::fem {

template <class SlopeAt>
std::optional<double> energy_line_search(double slope0, int max_trials, SlopeAt&& slope_at) {
  if (!(slope0 < 0.0)) return std::nullopt;
  const double accept = 0.5 * -slope0;
  int trials = 0;
  double a_hi = 1.0;
  std::optional<double> g_end;
  for (; trials < max_trials; ++trials) {  // an admissible far end
    g_end = slope_at(a_hi);
    if (g_end && std::isfinite(*g_end)) break;
    g_end.reset();
    a_hi *= 0.5;
  }
  if (!g_end) return std::nullopt;
  ++trials;
  if (*g_end <= 0.0 || std::abs(*g_end) <= accept) return a_hi;
  double a_lo = 0.0, g_lo = slope0, g_hi = *g_end;
  int last_side = 0;  // Illinois: halve the end that stayed twice
  for (; trials < max_trials; ++trials) {
    const double a = a_hi - g_hi * (a_hi - a_lo) / (g_hi - g_lo);
    std::optional<double> g = slope_at(a);
    if (g && !std::isfinite(*g)) g.reset();
    if (g && std::abs(*g) <= accept) return a;
    if (!g || *g > 0.0) {
      a_hi = a;
      if (g) g_hi = *g;
      if (last_side == 1) g_lo *= 0.5;
      last_side = 1;
    } else {
      a_lo = a;
      g_lo = *g;
      if (last_side == -1) g_hi *= 0.5;
      last_side = -1;
    }
  }
  if (a_lo > 0.0) return a_lo;
  return std::nullopt;
}

}  // namespace puncture::fem
