// The scaled start of a layer's calibration stage (scaled_start.hpp).
#include "scaled_start.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "model_runs.hpp"
#include "puncture/stiffening.hpp"
#include "puncture/validation/pressing_polynomial.hpp"

namespace puncture::validation::calibration_detail {

namespace {

// Scaled start

/// Pressing of layer k in a curve with known events: force at the contact
/// onset and at the puncture and the deflection in between.
bool pressing_rise(const InsertionCurve& c, const ReferenceEvents& ev, const std::vector<LayerGeometry>& layers,
                   std::size_t k, double& deflection_m, double& force_rise_N) {
  const std::vector<LayerSegments> seg = layer_segments(ev, layers);
  if (!seg[k].has_pressing || !ev.punctures[k].found) return false;
  double f0 = 0.0;
  std::vector<double> x, y;
  for (std::size_t i : insertion_phase(c)) {
    if (!x.empty() && c.depth_m[i] <= x.back()) continue;
    x.push_back(c.depth_m[i]);
    y.push_back(c.force_N[i]);
  }
  if (!interpolate_linear(x, y, seg[k].pressing_from_m, f0)) return false;
  deflection_m = ev.punctures[k].depth_m - seg[k].pressing_from_m;
  force_rise_N = ev.punctures[k].force_N - f0;
  return deflection_m > 0.0 && force_rise_N > 0.0;
}

/// What every step of the scaled start reads.
struct StartContext {
  std::size_t k;
  const ReferenceCurve& reference;
  const ReferenceEvents& ref_ev;
  const std::vector<LayerGeometry>& layers;
  const std::vector<Parameter>& parameters;
  bool tuned(ParamKind kind) const {
    for (const Parameter& p : parameters)
      if (p.kind == kind && p.layer == k) return true;
    return false;
  }
};

/// A curve's insertion (or, reversed, withdrawal) branch as x (depth) increasing, y = value(i).
template <class Value>
void depth_branch(const InsertionCurve& c, std::vector<std::size_t> idx, bool reverse, Value value,
                  std::vector<double>& x, std::vector<double>& y) {
  if (reverse) std::reverse(idx.begin(), idx.end());
  for (std::size_t i : idx) {
    if (!x.empty() && c.depth_m[i] <= x.back()) continue;
    x.push_back(c.depth_m[i]);
    y.push_back(value(i));
  }
}

/// Polynomial stiffening tuned: the reference's rise through the layer as a
/// non-negative cubic s z + a2 z^2 + a3 z^3 (pressing_polynomial.hpp) gives
/// a2 and a3, and its linear part s is the slope K is scaled to (the secant
/// slope would fold the stiffening into K). Returns s, or 0 without a fit.
double start_stiffening(const StartContext& c, Scene& s) {
  if (!c.tuned(ParamKind::StiffeningQuadratic) || !c.tuned(ParamKind::StiffeningCubic) || !c.ref_ev.punctures[c.k].found)
    return 0.0;
  const LayerSegments seg = layer_segments(c.ref_ev, c.layers)[c.k];
  if (!seg.has_pressing) return 0.0;
  std::vector<double> z, f;
  const InsertionCurve& ref = c.reference.curve;
  for (std::size_t i : insertion_phase(ref)) {
    const double d = ref.depth_m[i];
    if (d < seg.pressing_from_m || d > c.ref_ev.punctures[c.k].depth_m) continue;
    z.push_back(d - seg.pressing_from_m);
    f.push_back(ref.force_N[i]);
  }
  if (z.size() < 4) return 0.0;
  const double f0 = f.front();
  for (double& v : f) v -= f0;
  if (!(z.back() > 0.0 && f.back() > 0.0)) return 0.0;
  const PressingPolynomial fit = fit_pressing_polynomial(z, f);
  param_ref(s, c.k, ParamKind::StiffeningQuadratic) = fit.quadratic_N_per_m2;
  param_ref(s, c.k, ParamKind::StiffeningCubic) = fit.cubic_N_per_m3;
  // A floor of 5 % of the secant keeps K (a log-space parameter) finite when the rise is a pure power law.
  return std::max(fit.linear_N_per_m, 0.05 * f.back() / z.back());
}

/// K (and k_s) by the ratio of pressing slopes, the threshold or energy by
/// the breakthrough deflections; with may_stop, returns true instead when
/// both ratios are within 0.1 % (the fixed point: K and the threshold
/// interact through the ring profile).
bool scale_pressing(const StartContext& c, Scene& s, const InsertionCurve& model, const ReferenceEvents& mod_ev,
                    double linear_slope, bool may_stop) {
  double z_ref = 0.0, f_ref = 0.0, z_model = 0.0, f_model = 0.0;
  if (!pressing_rise(c.reference.curve, c.ref_ev, c.layers, c.k, z_ref, f_ref) ||
      !pressing_rise(model, mod_ev, c.layers, c.k, z_model, f_model))
    return false;
  double stiffness_ratio = (f_ref / z_ref) / (f_model / z_model);
  if (linear_slope > 0.0) {
    const double model_linear = (f_model - stiffening_force_N(s.layers[c.k].force_law.stiffening, z_model)) / z_model;
    if (model_linear > 0.0) stiffness_ratio = linear_slope / model_linear;
  }
  const double deflection_ratio = z_ref / z_model;
  if (may_stop && std::abs(stiffness_ratio - 1.0) < 1e-3 && std::abs(deflection_ratio - 1.0) < 1e-3) return true;
  if (c.tuned(ParamKind::VirtualStiffness)) param_ref(s, c.k, ParamKind::VirtualStiffness) *= stiffness_ratio;
  if (c.tuned(ParamKind::SurfaceStiffness)) param_ref(s, c.k, ParamKind::SurfaceStiffness) *= stiffness_ratio;
  if (c.tuned(ParamKind::DeformedThreshold)) param_ref(s, c.k, ParamKind::DeformedThreshold) *= deflection_ratio;
  if (c.tuned(ParamKind::CriticalEnergy))
    param_ref(s, c.k, ParamKind::CriticalEnergy) *= deflection_ratio * deflection_ratio * stiffness_ratio;
  return false;
}

/// A layer whose scene gives its fracture toughness G_c (fracture_energy
/// puncture criterion, as the FEM reference uses it) starts its critical force
/// from physics, not from the reference's puncture force: the force whose work
/// per unit advance opens a crack as wide as the needle, F_c = G_c 2 a (a the
/// needle radius; the cutting-force estimate of Azar and Hayward 2008 applied
/// to the first crack). True when it did.
bool start_critical_force_from_toughness(const StartContext& c, Scene& s) {
  if (!c.tuned(ParamKind::CriticalForce)) return false;
  const PunctureCriterion& p = s.layers[c.k].puncture;
  if (p.kind != PunctureCriterion::Kind::FractureEnergy || !(p.toughness_J_per_m2 > 0.0)) return false;
  param_ref(s, c.k, ParamKind::CriticalForce) = p.toughness_J_per_m2 * 2.0 * s.needle.radius_m;
  return true;
}

/// Otherwise (no G_c, e.g. a measured curve of an unknown tissue): the tip's
/// share of the reference's puncture force, minus the model's friction and
/// cutting there, taken before the model's own puncture of the layer when
/// that comes first (its own cut would count otherwise, and a too low
/// critical force would keep itself).
void start_critical_force_from_reference(const StartContext& c, Scene& s, const InsertionCurve& model,
                                         const ReferenceEvents& mod_ev) {
  if (!c.tuned(ParamKind::CriticalForce) || !c.ref_ev.punctures[c.k].found || !model.has_parts()) return;
  double at = c.ref_ev.punctures[c.k].depth_m;
  if (mod_ev.punctures[c.k].found) at = std::min(at, mod_ev.punctures[c.k].depth_m - 1e-5);
  std::vector<double> x, y;
  depth_branch(model, insertion_phase(model), false, [&](std::size_t i) { return model.force_N[i] - model.tip_force_N[i]; },
               x, y);
  double other = 0.0;
  interpolate_linear(x, y, at, other);
  const double want = c.ref_ev.punctures[c.k].force_N - other;
  if (want > 0.0) param_ref(s, c.k, ParamKind::CriticalForce) = want;
}

/// Cutting and friction by least squares of r = reference - model: on the
/// cut r = dC + dF h, on the withdrawal inside the layer r = -dF h (h: shaft
/// length in the layer).
void start_cut_and_friction(const StartContext& c, Scene& s, const InsertionCurve& model) {
  const bool cut = c.tuned(ParamKind::Cutting), fric = c.tuned(ParamKind::Friction);
  if (!cut && !fric) return;
  const LayerSegments seg = layer_segments(c.ref_ev, c.layers)[c.k];
  const InsertionCurve& ref = c.reference.curve;
  std::vector<double> mx, my, wx, wy;
  depth_branch(model, insertion_phase(model), false, [&](std::size_t i) { return model.force_N[i]; }, mx, my);
  depth_branch(model, withdrawal_phase(model), true, [&](std::size_t i) { return model.force_N[i]; }, wx, wy);
  double a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0;
  auto add_row = [&](double cc, double h, double r) { a11 += cc * cc, a12 += cc * h, a22 += h * h, b1 += cc * r, b2 += h * r; };
  const double top = c.layers[c.k].top_depth_m, t = c.layers[c.k].thickness_m;
  double f = 0.0;
  if (seg.has_after)
    for (std::size_t i : insertion_phase(ref)) {
      const double d = ref.depth_m[i];
      if (d > seg.after_from_m && d < seg.after_to_m && interpolate_linear(mx, my, d, f))
        add_row(1.0, shaft_length_in_layer_m(d, top, t), ref.force_N[i] - f);
    }
  const double withdrawal_limit = seg.has_after ? seg.after_to_m - 0.5e-3 : -1.0;
  for (std::size_t i : withdrawal_phase(ref)) {
    const double d = ref.depth_m[i];
    if (d > top && d <= std::min(top + t, withdrawal_limit) && interpolate_linear(wx, wy, d, f))
      add_row(0.0, -shaft_length_in_layer_m(d, top, t), ref.force_N[i] - f);
  }
  double dC = 0.0, dF = 0.0;
  const double det = a11 * a22 - a12 * a12;
  if (cut && fric && det > 1e-12 * (a11 * a22) && a11 > 0.0) {
    dC = (a22 * b1 - a12 * b2) / det;
    dF = (a11 * b2 - a12 * b1) / det;
  } else if (cut && a11 > 0.0) {
    dC = b1 / a11;
  } else if (fric && a22 > 0.0) {
    dF = b2 / a22;
  }
  if (cut) param_ref(s, c.k, ParamKind::Cutting) = std::max(0.0, param_value(s, c.k, ParamKind::Cutting) + dC);
  if (fric)
    for (const Parameter& p : c.parameters)
      if (p.kind == ParamKind::Friction && p.layer == c.k)
        set_param(s, p, std::max(0.0, param_value(s, c.k, ParamKind::Friction) + dF));
}

}  // namespace

Scene scaled_start(const Scene& candidate, std::size_t k, const ReferenceCurve& reference, const ReferenceEvents& ref_ev,
                   const std::vector<LayerGeometry>& layers, const CalibrationOptions& options, const SurfaceCache& cache,
                   const std::vector<Parameter>& parameters) {
  const StartContext c{k, reference, ref_ev, layers, parameters};
  Scene s = candidate;
  const double linear_slope = start_stiffening(c, s);
  const bool physical_critical_force = start_critical_force_from_toughness(c, s);
  for (int pass = 0; pass < 8; ++pass) {
    InsertionCurve model;
    try {
      model = simulate_insertion_curve(objective_scene(s, reference, options, false), &cache);
    } catch (const std::exception&) {
      return candidate;
    }
    const ReferenceEvents mod_ev = reference_events(model, layers);  // its own states
    if (scale_pressing(c, s, model, mod_ev, linear_slope, pass >= 2)) break;
    if (!physical_critical_force) start_critical_force_from_reference(c, s, model, mod_ev);
    start_cut_and_friction(c, s, model);
    clamp_into_bounds(s, parameters);
  }
  return s;
}

Scene rate_exponent_start(const Scene& scene, const std::vector<std::size_t>& layers,
                          const std::vector<bool>& level_tuned, const std::vector<ReferenceCurve>& references,
                          const std::vector<ReferenceEvents>& events, std::vector<std::string>& notes) {
  Scene s = scene;
  for (std::size_t k : layers) {
    if (!level_tuned[k] || s.layers[k].force_law.breakthrough.kind != BreakthroughCriterion::Kind::CriticalForce)
      continue;
    std::vector<double> x, y;  // ln v, ln F of every puncture of layer k
    for (std::size_t r = 0; r < references.size() && r < events.size(); ++r) {
      const auto& p = events[r].punctures;
      if (k >= p.size() || !p[k].found || !(p[k].force_N > 0.0)) continue;
      x.push_back(std::log(reference_speed(scene, references[r].curve)));
      y.push_back(std::log(p[k].force_N));
    }
    if (x.size() < 2) continue;
    double mx = 0.0, my = 0.0, sxx = 0.0, sxy = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) mx += x[i] / x.size(), my += y[i] / x.size();
    for (std::size_t i = 0; i < x.size(); ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
    if (!(sxx > 1e-6)) continue;  // one speed
    const double n = std::clamp(sxy / sxx, 0.0, 1.0);
    s.layers[k].force_law.breakthrough.rate_exponent = n;
    notes.push_back("layer " + s.layers[k].name + ": breakthrough_rate_exponent started at " + std::to_string(n) +
                    ", the slope of ln F against ln v of its " + std::to_string(x.size()) +
                    " punctures (then tuned with its critical force)");
  }
  return s;
}

std::string critical_force_start_note(const Scene& scene, const std::vector<std::size_t>& layers,
                                      const CalibrationOptions& options) {
  if (!options.scaled_start) return {};
  std::ostringstream note;
  for (std::size_t k : layers) {
    const std::vector<ParamKind> kinds = layer_kinds(scene, k, options.parameters, nullptr);
    if (std::find(kinds.begin(), kinds.end(), ParamKind::CriticalForce) == kinds.end()) continue;
    const Layer& l = scene.layers[k];
    note << (note.tellp() > 0 ? "; " : "") << l.name << ": ";
    if (l.puncture.kind == PunctureCriterion::Kind::FractureEnergy && l.puncture.toughness_J_per_m2 > 0.0)
      note << "G_c x 2a = " << l.puncture.toughness_J_per_m2 << " J/m^2 x " << 2e3 * scene.needle.radius_m
           << " mm = " << l.puncture.toughness_J_per_m2 * 2.0 * scene.needle.radius_m
           << " N (the layer's fracture toughness)";
    else
      note << "the reference's puncture force less the model's other terms there (no fracture toughness)";
  }
  return note.str();
}

}  // namespace puncture::validation::calibration_detail
