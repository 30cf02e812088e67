// detect_force_drops and the contact onset of a depth-force curve
// (puncture_events.hpp: the rules; force_noise.hpp: the noise estimate).
#include <algorithm>
#include <cmath>
#include <limits>

#include "puncture/validation/force_noise.hpp"
#include "puncture/validation/puncture_events.hpp"

namespace puncture::validation {

namespace {

struct SlopeFit {
  double slope = std::numeric_limits<double>::quiet_NaN();  ///< N/m; NaN if fewer than three distinct depths
  double standard_error_per_N = 0.0;  ///< 1 / sqrt(Sxx): the slope's standard error per N of force noise
};

/// Least-squares slope of force against depth over the insertion samples
/// from phase[from] going in `direction` (-1 back, +1 forward) over `window`
/// of depth (at least two samples besides the first).
SlopeFit slope(const InsertionCurve& c, const std::vector<std::size_t>& phase, std::size_t from, int direction,
               double window) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  const double d0 = c.depth_m[phase[from]];
  for (long q = static_cast<long>(from); q >= 0 && q < static_cast<long>(phase.size()); q += direction) {
    const double x = c.depth_m[phase[static_cast<std::size_t>(q)]] - d0;
    if (std::abs(x) > window && n >= 3) break;
    const double y = c.force_N[phase[static_cast<std::size_t>(q)]];
    sx += x, sy += y, sxx += x * x, sxy += x * y, ++n;
  }
  SlopeFit fit;
  const double den = n * sxx - sx * sx;
  if (n < 3 || !(den > 0.0)) return fit;
  fit.slope = (n * sxy - sx * sy) / den;
  fit.standard_error_per_N = std::sqrt(n / den);  // 1 / sqrt(Sxx), Sxx = den / n
  return fit;
}

/// The slope before the maximum at phase[p]: over slope_window_m before it,
/// or, when the force stayed within `band` of F_p over a plateau that the
/// curve rose into from below (at most max_plateau_m long), the steeper of
/// that and the rise before the plateau.
SlopeFit slope_before(const InsertionCurve& c, const std::vector<std::size_t>& phase, std::size_t p, double band,
                      const PunctureDetectionOptions& o) {
  const SlopeFit at_max = slope(c, phase, p, -1, o.slope_window_m);
  const double fp = c.force_N[phase[p]];
  std::size_t s = p;
  while (s > 0 && std::abs(c.force_N[phase[s - 1]] - fp) <= band &&
         c.depth_m[phase[s - 1]] >= c.depth_m[phase[p]] - o.max_plateau_m)
    --s;
  if (s == p || s == 0 || !(c.force_N[phase[s - 1]] < fp - band)) return at_max;  // no plateau risen into
  const SlopeFit rise = slope(c, phase, s, -1, o.slope_window_m);
  return std::isfinite(rise.slope) && (!std::isfinite(at_max.slope) || rise.slope > at_max.slope) ? rise : at_max;
}

}  // namespace

std::vector<ForceDrop> detect_force_drops(const InsertionCurve& curve, const PunctureDetectionOptions& o) {
  return detect_force_drops(curve, force_noise_sigma_N(curve, insertion_phase(curve)), o);
}

std::vector<ForceDrop> detect_force_drops(const InsertionCurve& curve, double sigma,
                                          const PunctureDetectionOptions& o) {
  const std::vector<std::size_t> phase = insertion_phase(curve);
  const double band = o.noise_band_sigmas * sigma;
  double peak = 0.0;
  for (std::size_t i : phase) peak = std::max(peak, std::abs(curve.force_N[i]));
  std::vector<ForceDrop> found;
  double previous_lowest_m = -std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p + 1 < phase.size(); ++p) {
    const double f = curve.force_N[phase[p]];
    if (p > 0 && curve.force_N[phase[p - 1]] > f) continue;  // not a maximum
    if (!(curve.force_N[phase[p + 1]] < f)) continue;          // no fall right after it
    if (sigma > 0.0 && f < o.min_peak_sigmas * sigma) continue;  // the force itself is within the noise
    // The sample right after the maximum counts whatever the sampling; later
    // ones while the tip is within the window.
    double lowest = curve.force_N[phase[p + 1]];
    std::size_t lowest_at = p + 1;
    for (std::size_t q = p + 2; q < phase.size(); ++q) {
      if (curve.depth_m[phase[q]] > curve.depth_m[phase[p + 1]] + o.window_m) break;
      if (curve.force_N[phase[q]] > f) break;  // rose above the maximum again
      if (curve.force_N[phase[q]] < lowest) lowest = curve.force_N[phase[q]], lowest_at = q;
    }
    const double drop = f - lowest;
    if (!(drop >= o.min_drop_fraction * std::abs(f) && drop >= o.min_drop_of_peak * peak && drop > 0.0)) continue;
    if (!(drop >= o.min_drop_sigmas * sigma)) continue;
    // A stiff rise before it (or before the plateau it follows), a softer
    // course after it, beyond the slopes' noise (see the header).
    const SlopeFit before = slope_before(curve, phase, p, std::max(band, o.plateau_fraction * drop), o);
    const SlopeFit after = slope(curve, phase, lowest_at, +1, o.slope_window_m);
    const double margin = o.slope_margin_sigmas * sigma * std::hypot(before.standard_error_per_N, after.standard_error_per_N);
    if (std::isfinite(before.slope) && std::isfinite(after.slope) && !(before.slope + margin > after.slope)) continue;
    // Where the fall starts: the last sample still within the noise band of F_p.
    std::size_t start = p;
    for (std::size_t r = p; r < lowest_at; ++r)
      if (curve.force_N[phase[r]] >= f - band) start = r;
    ForceDrop d{phase[p], curve.depth_m[phase[start + 1]], f, drop};
    d.noise_sigmas = sigma > 0.0 ? drop / sigma : std::numeric_limits<double>::infinity();
    d.marginal = sigma > 0.0 && drop < o.clear_drop_sigmas * sigma;
    const bool same_fall = curve.depth_m[phase[p]] <= previous_lowest_m;
    if (!found.empty() && (same_fall || d.depth_m - found.back().depth_m <= o.window_m)) {
      if (d.drop_N > found.back().drop_N) found.back() = d;  // one drop seen twice: keep the larger
      previous_lowest_m = std::max(previous_lowest_m, curve.depth_m[phase[lowest_at]]);
      continue;
    }
    found.push_back(d);
    previous_lowest_m = curve.depth_m[phase[lowest_at]];
  }
  return found;
}

bool contact_onset_from_force(const InsertionCurve& c, const std::vector<std::size_t>& phase, double sigma_N,
                              const PunctureDetectionOptions& o, double& onset_m) {
  double peak = 0.0;
  for (std::size_t i : phase) peak = std::max(peak, std::abs(c.force_N[i]));
  const double threshold = std::max(o.onset_fraction * peak, o.noise_band_sigmas * sigma_N);
  for (std::size_t p = 0; p < phase.size(); ++p) {
    if (!(std::abs(c.force_N[phase[p]]) > threshold)) continue;
    bool holds = true;  // stays above the threshold over the next onset_hold_m (noise spikes do not)
    for (std::size_t q = p + 1; q < phase.size() && holds; ++q) {
      if (c.depth_m[phase[q]] > c.depth_m[phase[p]] + o.onset_hold_m && q > p + 1) break;
      holds = std::abs(c.force_N[phase[q]]) > threshold;
    }
    if (!holds) continue;
    onset_m = c.depth_m[phase[p]];
    return true;
  }
  return false;
}

}  // namespace puncture::validation
