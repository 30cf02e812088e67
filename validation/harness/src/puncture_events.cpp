#include "puncture/validation/puncture_events.hpp"

#include "puncture/validation/force_noise.hpp"
#include "puncture/validation/reference_checks.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace puncture::validation {

const char* to_string(PunctureSource source) {
  switch (source) {
    case PunctureSource::GivenDepths: return "given depths";
    case PunctureSource::StateColumns: return "state columns";
    case PunctureSource::ForceDrops: return "force drops";
  }
  return "unknown";
}

std::vector<LayerGeometry> layer_geometry(const Scene& scene) {
  std::vector<LayerGeometry> out;
  for (std::size_t k = 0; k < scene.layers.size(); ++k)
    out.push_back({scene.layers[k].name, scene.layer_top_depth_m(k), scene.layers[k].thickness_m,
                   scene.layers[k].force_mesh.spacing_L_m});
  return out;
}

double cut_end_from_parts(const InsertionCurve& curve, const std::vector<std::size_t>& samples,
                          double puncture_depth_m, double zero_N) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (!curve.has_parts()) return nan;
  bool after = false, first = true, concurrent = false;
  for (std::size_t i : samples) {
    if (curve.depth_m[i] < puncture_depth_m) continue;
    const bool tip_free = curve.tip_force_N[i] <= zero_N;
    const bool cutting = curve.cutting_force_N[i] > zero_N;
    if (!after) {  // skip the samples up to the drop itself
      after = tip_free;
      continue;
    }
    if (first) {
      first = false;
      if (!tip_free) {
        if (!cutting) return puncture_depth_m;  // the next layer met at the break, no cut
        concurrent = true;                      // cut while the next layer is pressed
      }
      continue;
    }
    if (concurrent ? !cutting : !tip_free) return curve.depth_m[i];
  }
  return nan;
}

ReferenceEvents reference_events(const InsertionCurve& reference, const std::vector<LayerGeometry>& layers,
                                 const std::vector<double>& given, const PunctureDetectionOptions& o) {
  ReferenceEvents ev;
  ev.punctures.resize(layers.size());
  const std::vector<std::size_t> phase = insertion_phase(reference);
  double peak = 0.0;
  ev.deepest_m = reference.depth_m[phase.front()];
  for (std::size_t i : phase) {
    peak = std::max(peak, std::abs(reference.force_N[i]));
    ev.deepest_m = std::max(ev.deepest_m, reference.depth_m[i]);
  }
  ev.noise_N = force_noise_sigma_N(reference, phase);
  std::ostringstream note;
  if (!given.empty()) {
    ev.source = PunctureSource::GivenDepths;
    if (given.size() > layers.size())
      throw std::invalid_argument("puncture depths: " + std::to_string(given.size()) + " given for " +
                                  std::to_string(layers.size()) + " layers");
    for (std::size_t k = 0; k < given.size(); ++k) {
      const double d = given[k];
      if (!std::isfinite(d) || d <= reference.depth_m[phase.front()] || d > ev.deepest_m)
        throw std::invalid_argument("puncture depth " + std::to_string(d * 1e3) + " mm of layer '" + layers[k].name +
                                    "' lies outside the reference's insertion");
      if (k > 0 && !(d > given[k - 1]))
        throw std::invalid_argument("puncture depths must increase from the top layer down");
      PunctureEventMetrics& e = ev.punctures[k];
      e.found = true;
      e.depth_m = d;
      e.force_N = -std::numeric_limits<double>::infinity();
      for (std::size_t i : phase)
        if (reference.depth_m[i] <= d && reference.depth_m[i] >= d - o.window_m) e.force_N = std::max(e.force_N, reference.force_N[i]);
      if (!std::isfinite(e.force_N)) e.force_N = 0.0;
    }
    note << given.size() << " puncture depth(s) given";
  } else if (reference.has_layer_states()) {
    ev.source = PunctureSource::StateColumns;
    for (std::size_t k = 0; k < layers.size(); ++k) ev.punctures[k] = puncture_event(reference, layers[k].name);
    note << "punctures from the <layer>_state columns";
  } else {
    ev.source = PunctureSource::ForceDrops;
    ev.drops = detect_force_drops(reference, ev.noise_N, o);
    std::vector<ForceDrop> kept = ev.drops;
    if (kept.size() > layers.size()) {
      std::sort(kept.begin(), kept.end(), [](const ForceDrop& a, const ForceDrop& b) { return a.drop_N > b.drop_N; });
      kept.resize(layers.size());
      std::sort(kept.begin(), kept.end(), [](const ForceDrop& a, const ForceDrop& b) { return a.depth_m < b.depth_m; });
    }
    for (std::size_t k = 0; k < kept.size(); ++k) ev.punctures[k] = {true, kept[k].depth_m, kept[k].peak_force_N};
    note << ev.drops.size() << " force drop(s) found (>= " << 100.0 * o.min_drop_fraction << " % of the force, >= "
         << 100.0 * o.min_drop_of_peak << " % of the peak and >= " << o.min_drop_sigmas << " x the noise "
         << ev.noise_N << " N within " << o.window_m * 1e3 << " mm)";
    if (ev.drops.size() > kept.size()) note << "; the " << kept.size() << " largest kept";
    note << "; no state columns";
  }
  ev.note = note.str();
  if (ev.source == PunctureSource::ForceDrops) ev.doubts = detection_doubts(ev, layers);

  // Where each cut ends (cut_end_from_parts).
  ev.cut_end_m.assign(layers.size(), std::numeric_limits<double>::quiet_NaN());
  if (reference.has_parts())
    for (std::size_t k = 0; k < layers.size(); ++k)
      if (ev.punctures[k].found)
        ev.cut_end_m[k] = cut_end_from_parts(reference, phase, ev.punctures[k].depth_m, 1e-12 * std::max(1.0, peak));

  // Contact onset: the top layer first pressed, else the force first above a fraction of the peak.
  const int top = !layers.empty() ? reference.layer_index(layers.front().name) : -1;
  if (top >= 0) {
    for (std::size_t i : phase)
      if (reference.layer_states[static_cast<std::size_t>(top)][i] != LayerState::Untouched) {
        ev.has_contact_onset = true;
        ev.contact_onset_m = reference.depth_m[i];
        break;
      }
  } else if (std::isfinite(reference.known_contact_depth_m)) {
    ev.has_contact_onset = true;  // a raw recording's contact fit (recording.hpp)
    ev.contact_onset_m = reference.known_contact_depth_m;
  } else {
    ev.has_contact_onset = contact_onset_from_force(reference, phase, ev.noise_N, o, ev.contact_onset_m);
  }
  return ev;
}

std::vector<LayerSegments> layer_segments(const ReferenceEvents& ev, const std::vector<LayerGeometry>& layers) {
  std::vector<LayerSegments> out(layers.size());
  if (!ev.has_contact_onset) return out;
  double start = ev.contact_onset_m;
  for (std::size_t k = 0; k < layers.size(); ++k) {
    LayerSegments& s = out[k];
    const PunctureEventMetrics& p = ev.punctures[k];
    if (start >= ev.deepest_m) break;  // the reference does not reach this layer
    s.has_pressing = true;
    s.pressing_from_m = start;
    s.pressing_to_m = p.found ? p.depth_m : ev.deepest_m;
    if (!p.found) break;
    const double bottom = layers[k].top_depth_m + layers[k].thickness_m;
    double end = p.depth_m < bottom ? bottom : p.depth_m + layers[k].thickness_m;
    if (k < ev.cut_end_m.size() && std::isfinite(ev.cut_end_m[k])) end = std::min(end, ev.cut_end_m[k]);
    if (k + 1 < layers.size() && ev.punctures[k + 1].found) end = std::min(end, ev.punctures[k + 1].depth_m);
    end = std::min(end, ev.deepest_m);
    s.has_after = end > p.depth_m;
    s.after_from_m = p.depth_m;
    s.after_to_m = std::max(end, p.depth_m);
    start = s.after_to_m;
  }
  return out;
}

}  // namespace puncture::validation
