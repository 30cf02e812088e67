// curve_comparison.cpp: compare_curves (metrics.hpp): the model's force at
// the reference's insertion samples, per layer over its pressed interval, its
// puncture against the reference's.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "puncture/validation/metrics.hpp"
#include "puncture/validation/puncture_events.hpp"

namespace puncture::validation {

const LayerMetrics* CurveComparison::layer(const std::string& name) const {
  for (const auto& l : layers)
    if (l.layer == name) return &l;
  return nullptr;
}

namespace {

/// The model's force at the reference's insertion samples down to max_depth_m
/// (linear in depth), skipping the samples of a force drop at one instant.
struct ComparedSamples {
  std::vector<std::size_t> index;  ///< reference sample indices
  std::vector<double> error_N;     ///< model - reference there
};

ComparedSamples compare_at_reference_samples(const InsertionCurve& model, const InsertionCurve& reference,
                                             const std::vector<std::size_t>& ref_phase, double max_depth_m) {
  const std::vector<std::size_t> mod_phase = insertion_phase(model);
  std::vector<double> mx, my;
  mx.reserve(mod_phase.size()), my.reserve(mod_phase.size());
  for (std::size_t i : mod_phase) mx.push_back(model.depth_m[i]), my.push_back(model.force_N[i]);
  ComparedSamples out;
  for (std::size_t p = 0; p < ref_phase.size(); ++p) {
    const std::size_t i = ref_phase[p];
    if (reference.depth_m[i] > max_depth_m) continue;
    // A depth recorded twice is a force drop at one instant: the force there
    // is not one value, so those samples are not compared.
    const bool drop = (p > 0 && reference.depth_m[ref_phase[p - 1]] == reference.depth_m[i]) ||
                      (p + 1 < ref_phase.size() && reference.depth_m[ref_phase[p + 1]] == reference.depth_m[i]);
    if (drop) continue;
    double f = 0.0;
    if (!interpolate_linear(mx, my, reference.depth_m[i], f)) continue;
    out.index.push_back(i);
    out.error_N.push_back(f - reference.force_N[i]);
  }
  return out;
}

/// A reference without state columns: its own punctures and segments from its
/// force drops, in the model's layer order (never the model's states, which
/// would let a model that breaks early judge itself on a tiny interval).
struct DropEvents {
  std::vector<LayerGeometry> geometry;
  ReferenceEvents events;
  std::vector<LayerSegments> segments;
};

DropEvents drop_events_of(const InsertionCurve& model, const InsertionCurve& reference,
                          const std::vector<LayerGeometry>* geometry) {
  DropEvents d;
  if (reference.has_layer_states()) return d;
  if (geometry) {
    d.geometry = *geometry;
  } else {
    for (const auto& n : model.layer_names) d.geometry.push_back({n, 0.0, 0.0, 0.0});
  }
  d.events = reference_events(reference, d.geometry);
  d.segments = layer_segments(d.events, d.geometry);
  return d;
}

/// The depth interval over which the reference presses `lm.layer`: from its
/// Pressed states, else from its force drops.
void set_pressed_interval(const InsertionCurve& reference, const std::vector<std::size_t>& ref_phase,
                          const DropEvents& drops, LayerMetrics& lm) {
  if (reference.has_layer_states()) {
    const int li = reference.layer_index(lm.layer);
    if (li < 0) return;
    const auto& states = reference.layer_states[static_cast<std::size_t>(li)];
    for (std::size_t i : ref_phase) {
      if (states[i] != LayerState::Pressed) continue;
      const double d = reference.depth_m[i];
      if (!lm.has_pressed_interval) lm.pressed_from_depth_m = lm.pressed_to_depth_m = d;
      lm.has_pressed_interval = true;
      lm.pressed_from_depth_m = std::min(lm.pressed_from_depth_m, d);
      lm.pressed_to_depth_m = std::max(lm.pressed_to_depth_m, d);
    }
    return;
  }
  for (std::size_t k = 0; k < drops.geometry.size(); ++k) {
    if (drops.geometry[k].name != lm.layer || !drops.segments[k].has_pressing) continue;
    lm.has_pressed_interval = true;
    lm.pressed_from_depth_m = drops.segments[k].pressing_from_m;
    // The puncture sample itself is after the drop: up to the sample before it.
    lm.pressed_to_depth_m = drops.segments[k].pressing_to_m;
  }
}

/// One layer: the force RMSE over its pressed interval and its punctures in both curves.
LayerMetrics layer_metrics(const std::string& name, const InsertionCurve& model, const InsertionCurve& reference,
                           const std::vector<std::size_t>& ref_phase, const ComparedSamples& compared,
                           const DropEvents& drops, double peak_N) {
  LayerMetrics lm;
  lm.layer = name;
  set_pressed_interval(reference, ref_phase, drops, lm);
  if (lm.has_pressed_interval) {
    double s = 0.0;
    for (std::size_t c = 0; c < compared.index.size(); ++c) {
      const double d = reference.depth_m[compared.index[c]];
      if (d < lm.pressed_from_depth_m || d > lm.pressed_to_depth_m) continue;
      ++lm.n_samples;
      s += compared.error_N[c] * compared.error_N[c];
    }
    if (lm.n_samples > 0) lm.force_rmse_N = std::sqrt(s / static_cast<double>(lm.n_samples));
    lm.force_rmse_relative = peak_N > 0.0 ? lm.force_rmse_N / peak_N : 0.0;
  }
  lm.reference_puncture = puncture_event(reference, name);
  if (!reference.has_layer_states())
    for (std::size_t k = 0; k < drops.geometry.size(); ++k)
      if (drops.geometry[k].name == name) lm.reference_puncture = drops.events.punctures[k];
  lm.model_puncture = puncture_event(model, name);
  if (lm.reference_puncture.found && lm.model_puncture.found) {
    lm.puncture_depth_error_m = lm.model_puncture.depth_m - lm.reference_puncture.depth_m;
    lm.puncture_force_error_N = lm.model_puncture.force_N - lm.reference_puncture.force_N;
  }
  return lm;
}

}  // namespace

CurveComparison compare_curves(const InsertionCurve& model, const InsertionCurve& reference, double max_depth_m,
                               const std::vector<LayerGeometry>* geometry) {
  const std::vector<std::size_t> ref_phase = insertion_phase(reference);
  CurveComparison out;
  for (std::size_t i : ref_phase) out.reference_peak_force_N = std::max(out.reference_peak_force_N, std::abs(reference.force_N[i]));
  const ComparedSamples compared = compare_at_reference_samples(model, reference, ref_phase, max_depth_m);
  out.n_compared = compared.index.size();
  if (!compared.index.empty()) {
    double sq = 0.0;
    for (double e : compared.error_N) sq += e * e;
    out.force_rmse_N = std::sqrt(sq / static_cast<double>(compared.index.size()));
    out.compared_from_depth_m = reference.depth_m[compared.index.front()];
    out.compared_to_depth_m = reference.depth_m[compared.index.back()];
  }
  const double peak = out.reference_peak_force_N;
  out.force_rmse_relative = peak > 0.0 ? out.force_rmse_N / peak : 0.0;
  std::vector<std::string> names = reference.layer_names;
  for (const auto& n : model.layer_names)
    if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
  const DropEvents drops = drop_events_of(model, reference, geometry);
  for (const std::string& name : names)
    out.layers.push_back(layer_metrics(name, model, reference, ref_phase, compared, drops, peak));
  return out;
}

}  // namespace puncture::validation
