// backtracking_line_search.hpp (internal): the line search of both FEM solvers' Newton steps.
//
// backtracking_line_search(free_N, accept_any, floor_N, max_halvings, try_step):
//   tries alpha = 1, 1/2, 1/4, ... (at most max_halvings halvings) along the
//   Newton direction. try_step(alpha, halvings) makes the state u + alpha du the
//   trial state and returns its free residual norm (N), or nullopt if that state
//   is inadmissible (an inverted or non-finite element). The first trial whose
//   residual falls below (1 - 1e-4 alpha) free_N (sufficient decrease of the
//   residual norm) or below floor_N, or any admissible trial when accept_any (a
//   prescribed displacement is still being reached), is accepted and stays the
//   trial state.
// Out: LineSearchResult: accepted (then alpha and halvings are that trial's);
//   otherwise alpha is the admissible trial with the smallest residual (the
//   caller makes it the trial state again) or -1 if no trial was admissible;
//   free_N is the returned trial's residual.
#pragma once

#include <cmath>
#include <limits>
#include <optional>

namespace puncture::fem {

struct LineSearchResult {
  double alpha = -1.0;
  int halvings = 0;
  bool accepted = false;
  double free_N = std::numeric_limits<double>::infinity();  ///< the returned trial's free residual
};

template <class TryStep>
LineSearchResult backtracking_line_search(double free_N, bool accept_any, double floor_N, int max_halvings,
                                          TryStep&& try_step) {
  LineSearchResult best;
  double best_free = std::numeric_limits<double>::infinity();
  double alpha = 1.0;
  for (int h = 0; h <= max_halvings; ++h, alpha *= 0.5) {
    const std::optional<double> trial_free = try_step(alpha, h);
    if (!trial_free || !std::isfinite(*trial_free)) continue;
    if (accept_any || *trial_free < (1.0 - 1e-4 * alpha) * free_N || *trial_free <= floor_N)
      return {alpha, h, true, *trial_free};
    if (*trial_free < best_free) {
      best_free = *trial_free;
      best = {alpha, h, false, best_free};
    }
  }
  return best;
}

}  // namespace puncture::fem
