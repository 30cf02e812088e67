#include "puncture/validation/trajectory_objective.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <sstream>

namespace puncture::validation {

namespace {

std::string mm(double m) {
  std::ostringstream s;
  s << std::setprecision(4) << m * 1e3 << " mm";
  return s.str();
}

/// Piecewise-linear y(x) of the samples idx (x non-decreasing), for interpolation.
struct Branch {
  std::vector<double> x, y;
};

Branch branch(const InsertionCurve& c, const std::vector<std::size_t>& idx, const std::vector<double>& values,
              bool reverse) {
  Branch b;
  std::vector<std::size_t> order = idx;
  if (reverse) std::reverse(order.begin(), order.end());
  for (std::size_t i : order) {
    const double x = c.depth_m[i];
    if (!b.x.empty() && x <= b.x.back()) {
      b.y.back() = values[i];  // a repeated depth: the later value (after a drop)
      continue;
    }
    b.x.push_back(x);
    b.y.push_back(values[i]);
  }
  return b;
}

/// Reference samples of `idx` that are not part of a force drop at one depth.
std::vector<std::size_t> without_drops(const InsertionCurve& c, const std::vector<std::size_t>& idx) {
  std::vector<std::size_t> out;
  for (std::size_t p = 0; p < idx.size(); ++p) {
    const double d = c.depth_m[idx[p]];
    const bool drop = (p > 0 && c.depth_m[idx[p - 1]] == d) || (p + 1 < idx.size() && c.depth_m[idx[p + 1]] == d);
    if (!drop) out.push_back(idx[p]);
  }
  return out;
}

ObjectiveTerm make_term(const std::string& name, const std::string& layer) {
  ObjectiveTerm t;
  t.name = name;
  t.layer = layer;
  return t;
}

/// RMSE over reference samples; keeps each sample's error (NaN where the
/// model curve does not reach it) for the term's residuals.
struct Rmse {
  double sum_sq = 0.0;
  std::size_t n = 0;
  std::vector<double> errors;
  void add(double e) { sum_sq += e * e, ++n, errors.push_back(e); }
  void miss() { errors.push_back(std::numeric_limits<double>::quiet_NaN()); }
  double value() const { return n ? std::sqrt(sum_sq / static_cast<double>(n)) : 0.0; }
  /// sqrt(weight / n) x error / P per sample, 0 where missed.
  std::vector<double> residuals(double weight, double P) const {
    std::vector<double> r(errors.size(), 0.0);
    if (n == 0) return r;
    const double s = std::sqrt(weight / static_cast<double>(n)) / P;
    for (std::size_t i = 0; i < errors.size(); ++i)
      if (std::isfinite(errors[i])) r[i] = s * errors[i];
    return r;
  }
};

}  // namespace

const ObjectiveTerm* TrajectoryComparison::term(const std::string& name, const std::string& layer) const {
  for (const ObjectiveTerm& t : terms)
    if (t.name == name && t.layer == layer) return &t;
  return nullptr;
}

std::vector<double> TrajectoryComparison::residuals() const {
  std::vector<double> r;
  for (const ObjectiveTerm& t : terms) r.insert(r.end(), t.residuals.begin(), t.residuals.end());
  return r;
}

namespace {

/// One comparison of a model curve with a reference: the terms in order
/// (whole insertion, per layer, withdrawal, dwell), each added with its
/// residuals.
class TrajectoryComparer {
 public:
  TrajectoryComparer(const InsertionCurve& model, const InsertionCurve& reference, const ReferenceEvents& ev,
                     const std::vector<LayerGeometry>& layers, const ObjectiveWeights& w, const TermSelection& sel)
      : model_(model), reference_(reference), ev_(ev), layers_(layers), w_(w), sel_(sel),
        ref_in_(without_drops(reference, insertion_phase(reference))), mod_in_(insertion_phase(model)) {
    for (std::size_t i : insertion_phase(reference))
      out_.reference_peak_force_N = std::max(out_.reference_peak_force_N, std::abs(reference.force_N[i]));
    P_ = out_.reference_peak_force_N > 0.0 ? out_.reference_peak_force_N : 1.0;
    model_in_ = branch(model, mod_in_, model.force_N, false);
  }

  TrajectoryComparison run() {
    if (sel_.whole_curve_terms) whole_insertion_terms();
    const std::vector<LayerSegments> seg = segments();
    std::vector<std::size_t> chosen = sel_.layers;
    if (chosen.empty())
      for (std::size_t k = 0; k < layers_.size(); ++k) chosen.push_back(k);
    for (std::size_t k : chosen) layer_terms(k, seg[k]);
    if (sel_.withdrawal) withdrawal_term();
    if (sel_.dwell) dwell_term();
    bool any_reference_puncture = false;
    for (const PunctureEventMetrics& p : ev_.punctures) any_reference_puncture = any_reference_puncture || p.found;
    if (!any_reference_puncture)
      out_.warnings.push_back("no puncture found in the reference (" + ev_.note + "): puncture terms are n/a");
    return std::move(out_);
  }

 private:
  /// A single-value term has one residual, an RMSE term (force_term) one per
  /// reference sample it covers.
  void add_term(ObjectiveTerm t, bool single_value = true) {
    if (t.available && !std::isfinite(t.value)) t.available = false, t.note = "not finite";
    if (single_value) t.residuals = {t.available ? std::sqrt(t.weight) * t.value : 0.0};
    if (!t.available) std::fill(t.residuals.begin(), t.residuals.end(), 0.0);
    out_.objective += t.contribution();
    out_.terms.push_back(std::move(t));
  }
  void add_rmse_term(ObjectiveTerm t) { add_term(std::move(t), false); }
  void add_unavailable(const std::string& name, const std::string& layer, double weight, const std::string& note) {
    ObjectiveTerm t = make_term(name, layer);
    t.weight = weight;
    t.note = note;
    add_term(t);
  }

  /// RMSE of model - reference over the reference insertion samples with depth in [from, to).
  Rmse insertion_rmse(double from, double to, bool inclusive_end, const std::vector<double>& ref_values,
                      const Branch& model_branch) const {
    Rmse r;
    for (std::size_t i : ref_in_) {
      const double d = reference_.depth_m[i];
      if (d < from || d > sel_.max_depth_m || (inclusive_end ? d > to : d >= to)) continue;
      double f = 0.0;
      if (interpolate_linear(model_branch.x, model_branch.y, d, f)) r.add(f - ref_values[i]);
      else r.miss();
    }
    return r;
  }

  ObjectiveTerm force_term(const std::string& name, const std::string& layer, double weight, const Rmse& r,
                           const std::string& where) const {
    ObjectiveTerm t = make_term(name, layer);
    t.weight = weight;
    t.samples = r.n;
    t.available = r.n > 0;
    t.raw = r.value();
    t.value = t.raw / P_;
    t.note = r.n > 0 ? where : "no reference samples " + where;
    t.residuals = r.residuals(weight, P_);
    return t;
  }

  /// overall and the parts (tip, cutting, friction) over the insertion.
  void whole_insertion_terms() {
    const double inf = std::numeric_limits<double>::infinity();
    add_rmse_term(force_term("overall", "", w_.overall_rmse,
                             insertion_rmse(-inf, inf, true, reference_.force_N, model_in_), "over the insertion"));
    const char* part_names[] = {"tip_force", "cutting_force", "friction_force"};
    const std::vector<double>* ref_parts[] = {&reference_.tip_force_N, &reference_.cutting_force_N,
                                              &reference_.friction_force_N};
    const std::vector<double>* mod_parts[] = {&model_.tip_force_N, &model_.cutting_force_N, &model_.friction_force_N};
    for (int p = 0; p < 3; ++p) {
      if (!reference_.has_parts() || !model_.has_parts()) {
        add_unavailable(part_names[p], "", w_.parts,
                        reference_.has_parts() ? "the model curve has no part columns" : "the reference has no part columns");
        continue;
      }
      add_rmse_term(force_term(part_names[p], "", w_.parts,
                               insertion_rmse(-inf, inf, true, *ref_parts[p], branch(model_, mod_in_, *mod_parts[p], false)),
                               "over the insertion"));
    }
  }

  /// The reference's layer segments and the model's punctures. A reference
  /// without parts does not say where a cut ends: there, the cut through
  /// layer k (and layer k + 1's pressing) ends where the model's cut ends
  /// (cut_end_from_parts: where its tip meets layer k + 1, or at the puncture
  /// when it meets it at the break with no cutting), within the segment.
  std::vector<LayerSegments> segments() {
    std::vector<LayerSegments> seg = layer_segments(ev_, layers_);
    out_.model_punctures.resize(layers_.size());
    for (std::size_t k = 0; k < layers_.size(); ++k) out_.model_punctures[k] = puncture_event(model_, layers_[k].name);
    if (reference_.has_parts() || !model_.has_parts()) return seg;
    for (std::size_t k = 0; k < layers_.size(); ++k) {
      if (!seg[k].has_after || !out_.model_punctures[k].found) continue;
      double end = cut_end_from_parts(model_, mod_in_, out_.model_punctures[k].depth_m, 0.0);
      if (!std::isfinite(end)) continue;
      end = std::clamp(end, seg[k].after_from_m, seg[k].after_to_m);
      seg[k].after_to_m = end;
      seg[k].has_after = end > seg[k].after_from_m;
      if (k + 1 < seg.size() && seg[k + 1].has_pressing) seg[k + 1].pressing_from_m = end;
    }
    return seg;
  }

  /// pressing, puncture force, depth and missing puncture, after_puncture of layer k.
  void layer_terms(std::size_t k, const LayerSegments& s) {
    const std::string& name = layers_[k].name;
    if (s.has_pressing)
      add_rmse_term(force_term("pressing", name, w_.pressing,
                               insertion_rmse(s.pressing_from_m, s.pressing_to_m, !ev_.punctures[k].found,
                                              reference_.force_N, model_in_),
                               "over " + mm(s.pressing_from_m) + " - " + mm(s.pressing_to_m)));
    else
      add_unavailable("pressing", name, w_.pressing,
                      ev_.has_contact_onset ? "the reference does not reach this layer" : "the reference has no contact onset");
    puncture_terms(k);
    if (s.has_after)
      add_rmse_term(force_term("after_puncture", name, w_.after_puncture,
                               insertion_rmse(s.after_from_m, s.after_to_m, false, reference_.force_N, model_in_),
                               "over " + mm(s.after_from_m) + " - " + mm(s.after_to_m)));
    else
      add_unavailable("after_puncture", name, w_.after_puncture,
                      ev_.punctures[k].found ? "the reference ends at the puncture" : "the reference does not puncture this layer");
  }

  void puncture_terms(std::size_t k) {
    const std::string& name = layers_[k].name;
    const PunctureEventMetrics& rp = ev_.punctures[k];
    const PunctureEventMetrics& mp = out_.model_punctures[k];
    const double depth_scale =
        std::min(layers_[k].thickness_m, layers_[k].spacing_L_m > 0 ? layers_[k].spacing_L_m : layers_[k].thickness_m);
    ObjectiveTerm force = make_term("puncture_force", name), depth = make_term("puncture_depth", name),
                  missing = make_term("missing_puncture", name);
    force.weight = w_.puncture_force;
    depth.weight = w_.puncture_depth;
    missing.weight = w_.missing_puncture;
    if (rp.found && mp.found && rp.depth_m <= sel_.max_depth_m) {
      force.available = depth.available = true;
      force.raw = mp.force_N - rp.force_N;
      force.value = force.raw / (std::abs(rp.force_N) > 0.0 ? std::abs(rp.force_N) : P_);
      depth.raw = mp.depth_m - rp.depth_m;
      depth.value = depth.raw / depth_scale;
      force.samples = depth.samples = 1;
      std::ostringstream n;
      n << "model " << mm(mp.depth_m) << ", " << std::setprecision(4) << mp.force_N << " N; reference " << mm(rp.depth_m)
        << ", " << rp.force_N << " N";
      force.note = depth.note = n.str();
      if (std::abs(depth.raw) > depth_scale)
        out_.warnings.push_back("layer " + name + ": the model punctures at " + mm(mp.depth_m) + ", the reference at " +
                                mm(rp.depth_m) + ": more than L = " + mm(depth_scale) + " apart");
    } else {
      force.note = depth.note =
          !rp.found ? "the reference does not puncture this layer" : "the model does not puncture this layer";
    }
    if (rp.found && rp.depth_m > sel_.max_depth_m) {
      missing.note = "beyond the compared depth";
    } else {
      missing.available = true;
      missing.value = rp.found != mp.found ? 1.0 : 0.0;
      missing.note = rp.found != mp.found ? (rp.found ? "only the reference punctures" : "only the model punctures")
                                          : (rp.found ? "both puncture" : "neither punctures");
      if (rp.found != mp.found) out_.warnings.push_back("layer " + name + ": " + missing.note + " it");
    }
    add_term(force);
    add_term(depth);
    add_term(missing);
  }

  /// Depth-aligned over the reference's withdrawal.
  void withdrawal_term() {
    const std::vector<std::size_t> ref_out = without_drops(reference_, withdrawal_phase(reference_));
    const std::vector<std::size_t> mod_out = withdrawal_phase(model_);
    if (ref_out.empty()) return add_unavailable("withdrawal", "", w_.withdrawal, "the reference has no withdrawal");
    if (mod_out.empty()) return add_unavailable("withdrawal", "", w_.withdrawal, "the model run has no withdrawal");
    const Branch mb = branch(model_, mod_out, model_.force_N, true);
    Rmse r;
    for (std::size_t i : ref_out) {
      const double d = reference_.depth_m[i];
      if (d > sel_.withdrawal_max_depth_m) continue;
      double f = 0.0;
      if (interpolate_linear(mb.x, mb.y, d, f)) r.add(f - reference_.force_N[i]);
      else r.miss();
    }
    add_rmse_term(force_term("withdrawal", "", w_.withdrawal, r, "over the withdrawal"));
  }

  /// Time-aligned from the start of the dwell.
  void dwell_term() {
    const std::vector<std::size_t> ref_dwell = dwell_phase(reference_), mod_dwell = dwell_phase(model_);
    if (ref_dwell.empty()) return add_unavailable("dwell", "", w_.dwell, "the reference has no dwell");
    if (!reference_.has_time) return add_unavailable("dwell", "", w_.dwell, "the reference has no time column");
    if (mod_dwell.empty()) return add_unavailable("dwell", "", w_.dwell, "the model run has no dwell");
    std::vector<double> mt, mf;
    for (std::size_t i : mod_dwell) {
      const double tr = model_.time_s[i] - model_.time_s[mod_dwell.front()];
      if (!mt.empty() && tr <= mt.back()) continue;
      mt.push_back(tr);
      mf.push_back(model_.force_N[i]);
    }
    Rmse r;
    for (std::size_t i : ref_dwell) {
      const double tr = reference_.time_s[i] - reference_.time_s[ref_dwell.front()];
      double f = 0.0;
      if (mt.size() == 1 && tr == 0.0) f = mf.front(), r.add(f - reference_.force_N[i]);
      else if (interpolate_linear(mt, mf, tr, f)) r.add(f - reference_.force_N[i]);
      else r.miss();
    }
    add_rmse_term(force_term("dwell", "", w_.dwell, r, "over the dwell"));
  }

  const InsertionCurve& model_;
  const InsertionCurve& reference_;
  const ReferenceEvents& ev_;
  const std::vector<LayerGeometry>& layers_;
  const ObjectiveWeights& w_;
  const TermSelection& sel_;
  const std::vector<std::size_t> ref_in_, mod_in_;
  Branch model_in_;
  double P_ = 1.0;
  TrajectoryComparison out_;
};

}  // namespace

TrajectoryComparison compare_trajectory(const InsertionCurve& model, const InsertionCurve& reference,
                                        const ReferenceEvents& ev, const std::vector<LayerGeometry>& layers,
                                        const ObjectiveWeights& w, const TermSelection& sel) {
  return TrajectoryComparer(model, reference, ev, layers, w, sel).run();
}

}  // namespace puncture::validation
