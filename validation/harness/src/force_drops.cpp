// detect_force_drops and the contact onset of a depth-force curve
// (puncture_events.hpp: the rules; force_noise.hpp: the noise estimate).
// Depths in m, forces in N.
#include <algorithm>
#include <cmath>
#include <limits>

#include "puncture/validation/force_noise.hpp"
#include "puncture/validation/puncture_events.hpp"

namespace puncture::validation {

namespace {

/// The lowest insertion force over phase[from..to] (inclusive); +infinity when empty.
double lowest_force_N(const InsertionCurve& c, const std::vector<std::size_t>& phase, std::size_t from, std::size_t to) {
  double lowest = std::numeric_limits<double>::infinity();
  for (std::size_t q = from; q <= to; ++q) lowest = std::min(lowest, c.force_N[phase[q]]);
  return lowest;
}

/// Where the fall from the maximum phase[p] to its lowest sample phase[low]
/// starts: of the samples of [p, low) still above the fall's middle, the one
/// farthest above the chord from the maximum to the lowest sample (the knee
/// between a plateau, flat or sagging, and the fall; the maximum itself when
/// the force falls at once; samples after the fall, near the lowest one, do
/// not count).
std::size_t fall_start(const InsertionCurve& c, const std::vector<std::size_t>& phase, std::size_t p, std::size_t low) {
  const double d0 = c.depth_m[phase[p]], f0 = c.force_N[phase[p]];
  const double span = c.depth_m[phase[low]] - d0, fall = f0 - c.force_N[phase[low]];
  std::size_t start = p;
  double farthest = 0.0;
  for (std::size_t r = p + 1; r < low; ++r) {
    if (c.force_N[phase[r]] < f0 - 0.5 * fall) continue;  // past the fall's middle
    const double along = span > 0.0 ? (c.depth_m[phase[r]] - d0) / span : 0.0;
    const double above = c.force_N[phase[r]] - (f0 - fall * along);
    if (above > farthest) farthest = above, start = r;
  }
  return start;
}

/// One candidate drop at the maximum phase[p]: false when it is none.
struct Candidate {
  std::size_t lowest_at = 0;  ///< phase index of the lowest sample of the fall
  ForceDrop drop;
};
bool candidate_at(const InsertionCurve& c, const std::vector<std::size_t>& phase, std::size_t p, double sigma,
                  double peak, std::size_t level_from, const PunctureDetectionOptions& o, Candidate& out) {
  const double f = c.force_N[phase[p]];
  // A maximum, or any sample of a plateau that sags into the fall (none of
  // which need be a maximum on a noise-free curve).
  if (!(c.force_N[phase[p + 1]] < f)) return false;  // no fall right after it
  if (sigma > 0.0 && f < o.min_peak_sigmas * sigma) return false;  // the force itself is within the noise
  // The sample right after the maximum counts whatever the sampling; later
  // ones while the tip is within the window.
  double lowest = c.force_N[phase[p + 1]];
  std::size_t lowest_at = p + 1;
  for (std::size_t q = p + 2; q < phase.size(); ++q) {
    if (c.depth_m[phase[q]] > c.depth_m[phase[p + 1]] + o.window_m) break;
    if (c.force_N[phase[q]] > f) break;  // rose above the maximum again
    if (c.force_N[phase[q]] < lowest) lowest = c.force_N[phase[q]], lowest_at = q;
  }
  const double drop = f - lowest;
  if (!(drop >= o.min_drop_fraction * std::abs(f) && drop >= o.min_drop_of_peak * peak && drop > 0.0)) return false;
  if (!(drop >= o.min_drop_sigmas * sigma)) return false;
  // Risen into from below: a layer pressed up to its break, not a plateau
  // entered from above (the end of a cut onto an unloaded layer).
  const double rise = f - lowest_force_N(c, phase, level_from, p);
  if (!(rise >= o.min_rise_of_drop * drop && rise > o.noise_band_sigmas * sigma)) return false;
  const std::size_t start = fall_start(c, phase, p, lowest_at);
  out.lowest_at = lowest_at;
  out.drop = ForceDrop{phase[p], c.depth_m[phase[start + 1]], f, drop};
  out.drop.noise_sigmas = sigma > 0.0 ? drop / sigma : std::numeric_limits<double>::infinity();
  out.drop.marginal = sigma > 0.0 && drop < o.clear_drop_sigmas * sigma;
  return true;
}

}  // namespace

std::vector<ForceDrop> detect_force_drops(const InsertionCurve& curve, const PunctureDetectionOptions& o) {
  return detect_force_drops(curve, force_noise_sigma_N(curve, insertion_phase(curve)), o);
}

std::vector<ForceDrop> detect_force_drops(const InsertionCurve& curve, double sigma,
                                          const PunctureDetectionOptions& o) {
  const std::vector<std::size_t> phase = insertion_phase(curve);
  double peak = 0.0;
  for (std::size_t i : phase) peak = std::max(peak, std::abs(curve.force_N[i]));
  std::vector<ForceDrop> found;
  double previous_lowest_m = -std::numeric_limits<double>::infinity();
  // The rise to a maximum is measured from the lowest sample of the drop
  // before it; a maximum inside (or just after) the last drop's fall belongs
  // to that drop, and its rise is measured from where that drop's was.
  std::size_t group_from = 0, after_group = 0;
  for (std::size_t p = 0; p + 1 < phase.size(); ++p) {
    const bool in_group = !found.empty() && curve.depth_m[phase[p]] <= previous_lowest_m + o.window_m;
    Candidate k;
    if (!candidate_at(curve, phase, p, sigma, peak, std::min(p, in_group ? group_from : after_group), o, k)) continue;
    const ForceDrop& d = k.drop;
    const bool same_fall = curve.depth_m[phase[p]] <= previous_lowest_m;
    if (!found.empty() && (same_fall || d.depth_m - found.back().depth_m <= o.window_m)) {
      if (d.drop_N > found.back().drop_N) found.back() = d;  // one drop seen twice: keep the larger
      previous_lowest_m = std::max(previous_lowest_m, curve.depth_m[phase[k.lowest_at]]);
      after_group = std::max(after_group, k.lowest_at);
      continue;
    }
    found.push_back(d);
    previous_lowest_m = curve.depth_m[phase[k.lowest_at]];
    group_from = std::min(p, in_group ? group_from : after_group);
    after_group = k.lowest_at;
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
