#include "puncture/validation/reference_checks.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "puncture/validation/number_format.hpp"

namespace puncture::validation {

namespace {
std::string mm(double m) { return significant_digits(m * 1e3, 4) + " mm"; }
}  // namespace

std::vector<std::string> detection_doubts(const ReferenceEvents& ev, const std::vector<LayerGeometry>& layers) {
  std::vector<std::string> doubts;
  std::size_t clear = 0;
  for (const ForceDrop& d : ev.drops) {
    if (!d.marginal) {
      ++clear;
      continue;
    }
    doubts.push_back("the drop at " + mm(d.depth_m) + " (" + significant_digits(d.drop_N, 3) + " N) is only " +
                     significant_digits(d.noise_sigmas, 3) + " x the noise (" + significant_digits(ev.noise_N, 3) +
                     " N)");
  }
  if (clear > layers.size())
    doubts.push_back(std::to_string(clear) + " clear force drops for " + std::to_string(layers.size()) + " layers");
  std::size_t passed = 0;
  for (const LayerGeometry& l : layers)
    if (l.thickness_m > 0.0 && ev.deepest_m > l.top_depth_m + l.thickness_m) ++passed;
  if (ev.drops.size() < passed)
    doubts.push_back(std::to_string(ev.drops.size()) + " force drop(s), but the curve (to " + mm(ev.deepest_m) +
                     ") passes the undeformed bottom of " + std::to_string(passed) + " layer(s)");
  return doubts;
}

std::size_t samples_after_contact(const InsertionCurve& c, const ReferenceEvents& ev) {
  if (!ev.has_contact_onset) return 0;
  std::size_t n = 0;
  for (std::size_t i : insertion_phase(c))
    if (c.depth_m[i] > ev.contact_onset_m) ++n;
  return n;
}

void check_reference_fittable(const InsertionCurve& c, const ReferenceEvents& ev, bool depths_given,
                              const PunctureDetectionOptions& o) {
  double peak = 0.0;
  for (std::size_t i : insertion_phase(c)) peak = std::max(peak, std::abs(c.force_N[i]));
  std::ostringstream why;
  if (!(peak > 0.0) || peak < o.min_peak_sigmas * ev.noise_N) {
    why << "no force above the noise (largest insertion force " << peak << " N, noise " << ev.noise_N << " N)";
  } else if (samples_after_contact(c, ev) == 0) {
    why << "no samples after contact ("
        << (ev.has_contact_onset ? "the contact onset at " + mm(ev.contact_onset_m) + " is the deepest insertion sample"
                                 : std::string("the force never stays above the contact threshold"))
        << ")";
  } else if (!depths_given && ev.source == PunctureSource::ForceDrops && !ev.doubts.empty()) {
    why << "puncture detection is unsure: ";
    for (std::size_t k = 0; k < ev.doubts.size(); ++k) why << (k ? "; " : "") << ev.doubts[k];
    why << ". Give the layers' puncture depths (puncture calibrate --puncture-depths D1,D2,... in mm)";
  } else {
    return;
  }
  throw ReferenceError(c.source + ": cannot calibrate against this reference: " + why.str());
}

std::vector<LayerIdentifiability> layer_identifiability(const InsertionCurve& c, const ReferenceEvents& ev,
                                                        const std::vector<LayerGeometry>& layers) {
  std::vector<LayerIdentifiability> out(layers.size());
  const std::vector<LayerSegments> seg = layer_segments(ev, layers);
  const std::vector<std::size_t> phase = insertion_phase(c);
  for (std::size_t k = 0; k < layers.size(); ++k) {
    out[k].punctured = k < ev.punctures.size() && ev.punctures[k].found;
    for (std::size_t i : phase) {
      const double d = c.depth_m[i];
      if (seg[k].has_pressing && d >= seg[k].pressing_from_m && d < seg[k].pressing_to_m) ++out[k].pressing_samples;
      if (seg[k].has_after && d >= seg[k].after_from_m && d < seg[k].after_to_m) ++out[k].cut_samples;
    }
  }
  return out;
}

void check_enough_samples(const InsertionCurve& c, const ReferenceEvents& ev, std::size_t tuned, std::size_t requested) {
  const std::size_t n = samples_after_contact(c, ev);
  if ((tuned > 0 || requested == 0) && n >= tuned) return;
  throw ReferenceError(c.source + ": cannot calibrate against this reference: " +
                       (tuned == 0 ? std::string("it identifies no parameter of the calibrated layers (no pressing, "
                                                 "puncture or cut of them with enough samples)")
                                   : "fewer samples after contact (" + std::to_string(n) + ") than tuned parameters (" +
                                         std::to_string(tuned) + ")"));
}

}  // namespace puncture::validation
