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

TrajectoryComparison compare_trajectory(const InsertionCurve& model, const InsertionCurve& reference,
                                        const ReferenceEvents& ev, const std::vector<LayerGeometry>& layers,
                                        const ObjectiveWeights& w, const TermSelection& sel) {
  TrajectoryComparison out;
  const std::vector<std::size_t> ref_in = without_drops(reference, insertion_phase(reference));
  const std::vector<std::size_t> mod_in = insertion_phase(model);
  for (std::size_t i : insertion_phase(reference))
    out.reference_peak_force_N = std::max(out.reference_peak_force_N, std::abs(reference.force_N[i]));
  const double P = out.reference_peak_force_N > 0.0 ? out.reference_peak_force_N : 1.0;
  const Branch model_in = branch(model, mod_in, model.force_N, false);

  // A single-value term has one residual, an RMSE term (force_term) one per
  // reference sample it covers.
  auto add_term = [&](ObjectiveTerm t, bool single_value = true) {
    if (t.available && !std::isfinite(t.value)) t.available = false, t.note = "not finite";
    if (single_value) t.residuals = {t.available ? std::sqrt(t.weight) * t.value : 0.0};
    if (!t.available) std::fill(t.residuals.begin(), t.residuals.end(), 0.0);
    out.objective += t.contribution();
    out.terms.push_back(std::move(t));
  };
  auto add_rmse_term = [&](ObjectiveTerm t) { add_term(std::move(t), false); };
  // RMSE of model - reference over the reference insertion samples with depth in [from, to).
  auto insertion_rmse = [&](double from, double to, bool inclusive_end, const std::vector<double>& ref_values,
                            const Branch& model_branch) {
    Rmse r;
    for (std::size_t i : ref_in) {
      const double d = reference.depth_m[i];
      if (d < from || d > sel.max_depth_m || (inclusive_end ? d > to : d >= to)) continue;
      double f = 0.0;
      if (interpolate_linear(model_branch.x, model_branch.y, d, f)) r.add(f - ref_values[i]);
      else r.miss();
    }
    return r;
  };
  auto force_term = [&](const std::string& name, const std::string& layer, double weight, const Rmse& r,
                        const std::string& where) {
    ObjectiveTerm t = make_term(name, layer);
    t.weight = weight;
    t.samples = r.n;
    t.available = r.n > 0;
    t.raw = r.value();
    t.value = t.raw / P;
    t.note = r.n > 0 ? where : "no reference samples " + where;
    t.residuals = r.residuals(weight, P);
    return t;
  };

  // --- whole insertion ---
  if (sel.whole_curve_terms) {
    const double inf = std::numeric_limits<double>::infinity();
    add_rmse_term(force_term("overall", "", w.overall_rmse, insertion_rmse(-inf, inf, true, reference.force_N, model_in),
                        "over the insertion"));
    const char* part_names[] = {"tip_force", "cutting_force", "friction_force"};
    const std::vector<double>* ref_parts[] = {&reference.tip_force_N, &reference.cutting_force_N, &reference.friction_force_N};
    const std::vector<double>* mod_parts[] = {&model.tip_force_N, &model.cutting_force_N, &model.friction_force_N};
    for (int p = 0; p < 3; ++p) {
      if (!reference.has_parts() || !model.has_parts()) {
        ObjectiveTerm t = make_term(part_names[p], "");
        t.weight = w.parts;
        t.note = reference.has_parts() ? "the model curve has no part columns" : "the reference has no part columns";
        add_term(t);
        continue;
      }
      add_rmse_term(force_term(part_names[p], "", w.parts,
                          insertion_rmse(-inf, inf, true, *ref_parts[p], branch(model, mod_in, *mod_parts[p], false)),
                          "over the insertion"));
    }
  }

  // --- per layer ---
  std::vector<LayerSegments> seg = layer_segments(ev, layers);
  out.model_punctures.resize(layers.size());
  for (std::size_t k = 0; k < layers.size(); ++k) out.model_punctures[k] = puncture_event(model, layers[k].name);
  // A reference without parts does not say where a cut ends: there, the cut
  // through layer k (and layer k + 1's pressing) ends where the model's cut
  // ends (cut_end_from_parts: where its tip meets layer k + 1, or at the
  // puncture when it meets it at the break with no cutting), within the
  // segment.
  if (!reference.has_parts() && model.has_parts()) {
    for (std::size_t k = 0; k < layers.size(); ++k) {
      if (!seg[k].has_after || !out.model_punctures[k].found) continue;
      double end = cut_end_from_parts(model, mod_in, out.model_punctures[k].depth_m, 0.0);
      if (!std::isfinite(end)) continue;
      end = std::clamp(end, seg[k].after_from_m, seg[k].after_to_m);
      seg[k].after_to_m = end;
      seg[k].has_after = end > seg[k].after_from_m;
      if (k + 1 < seg.size() && seg[k + 1].has_pressing) seg[k + 1].pressing_from_m = end;
    }
  }
  std::vector<std::size_t> chosen = sel.layers;
  if (chosen.empty())
    for (std::size_t k = 0; k < layers.size(); ++k) chosen.push_back(k);
  for (std::size_t k : chosen) {
    const std::string& name = layers[k].name;
    const LayerSegments& s = seg[k];
    if (s.has_pressing) {
      add_rmse_term(force_term("pressing", name, w.pressing,
                          insertion_rmse(s.pressing_from_m, s.pressing_to_m, !ev.punctures[k].found, reference.force_N, model_in),
                          "over " + mm(s.pressing_from_m) + " - " + mm(s.pressing_to_m)));
    } else {
      ObjectiveTerm t = make_term("pressing", name);
      t.weight = w.pressing;
      t.note = ev.has_contact_onset ? "the reference does not reach this layer" : "the reference has no contact onset";
      add_term(t);
    }
    const PunctureEventMetrics& rp = ev.punctures[k];
    const PunctureEventMetrics& mp = out.model_punctures[k];
    const double depth_scale = std::min(layers[k].thickness_m, layers[k].spacing_L_m > 0 ? layers[k].spacing_L_m : layers[k].thickness_m);
    ObjectiveTerm force = make_term("puncture_force", name), depth = make_term("puncture_depth", name),
                  missing = make_term("missing_puncture", name);
    force.weight = w.puncture_force;
    depth.weight = w.puncture_depth;
    missing.weight = w.missing_puncture;
    if (rp.found && mp.found && rp.depth_m <= sel.max_depth_m) {
      force.available = depth.available = true;
      force.raw = mp.force_N - rp.force_N;
      force.value = force.raw / (std::abs(rp.force_N) > 0.0 ? std::abs(rp.force_N) : P);
      depth.raw = mp.depth_m - rp.depth_m;
      depth.value = depth.raw / depth_scale;
      force.samples = depth.samples = 1;
      std::ostringstream n;
      n << "model " << mm(mp.depth_m) << ", " << std::setprecision(4) << mp.force_N << " N; reference " << mm(rp.depth_m)
        << ", " << rp.force_N << " N";
      force.note = depth.note = n.str();
      if (std::abs(depth.raw) > depth_scale)
        out.warnings.push_back("layer " + name + ": the model punctures at " + mm(mp.depth_m) + ", the reference at " +
                               mm(rp.depth_m) + ": more than L = " + mm(depth_scale) + " apart");
    } else {
      const std::string why = !rp.found ? "the reference does not puncture this layer" : "the model does not puncture this layer";
      force.note = depth.note = why;
    }
    if (rp.found && rp.depth_m > sel.max_depth_m) {
      missing.note = "beyond the compared depth";
    } else {
      missing.available = true;
      missing.value = rp.found != mp.found ? 1.0 : 0.0;
      missing.note = rp.found != mp.found ? (rp.found ? "only the reference punctures" : "only the model punctures")
                                          : (rp.found ? "both puncture" : "neither punctures");
      if (rp.found != mp.found) out.warnings.push_back("layer " + name + ": " + missing.note + " it");
    }
    add_term(force);
    add_term(depth);
    add_term(missing);
    if (s.has_after) {
      add_rmse_term(force_term("after_puncture", name, w.after_puncture,
                          insertion_rmse(s.after_from_m, s.after_to_m, false, reference.force_N, model_in),
                          "over " + mm(s.after_from_m) + " - " + mm(s.after_to_m)));
    } else {
      ObjectiveTerm t = make_term("after_puncture", name);
      t.weight = w.after_puncture;
      t.note = rp.found ? "the reference ends at the puncture" : "the reference does not puncture this layer";
      add_term(t);
    }
  }

  // --- withdrawal (depth-aligned) ---
  if (sel.withdrawal) {
    ObjectiveTerm t = make_term("withdrawal", "");
    t.weight = w.withdrawal;
    const std::vector<std::size_t> ref_out = without_drops(reference, withdrawal_phase(reference));
    const std::vector<std::size_t> mod_out = withdrawal_phase(model);
    if (ref_out.empty()) {
      t.note = "the reference has no withdrawal";
      add_term(t);
    } else if (mod_out.empty()) {
      t.note = "the model run has no withdrawal";
      add_term(t);
    } else {
      const Branch mb = branch(model, mod_out, model.force_N, true);
      Rmse r;
      for (std::size_t i : ref_out) {
        const double d = reference.depth_m[i];
        if (d > sel.withdrawal_max_depth_m) continue;
        double f = 0.0;
        if (interpolate_linear(mb.x, mb.y, d, f)) r.add(f - reference.force_N[i]);
        else r.miss();
      }
      add_rmse_term(force_term("withdrawal", "", w.withdrawal, r, "over the withdrawal"));
    }
  }

  // --- dwell (time-aligned from its start) ---
  if (sel.dwell) {
    ObjectiveTerm t = make_term("dwell", "");
    t.weight = w.dwell;
    const std::vector<std::size_t> ref_dwell = dwell_phase(reference), mod_dwell = dwell_phase(model);
    if (ref_dwell.empty()) {
      t.note = "the reference has no dwell";
      add_term(t);
    } else if (!reference.has_time) {
      t.note = "the reference has no time column";
      add_term(t);
    } else if (mod_dwell.empty()) {
      t.note = "the model run has no dwell";
      add_term(t);
    } else {
      std::vector<double> mt, mf;
      for (std::size_t i : mod_dwell) {
        const double tr = model.time_s[i] - model.time_s[mod_dwell.front()];
        if (!mt.empty() && tr <= mt.back()) continue;
        mt.push_back(tr);
        mf.push_back(model.force_N[i]);
      }
      Rmse r;
      for (std::size_t i : ref_dwell) {
        const double tr = reference.time_s[i] - reference.time_s[ref_dwell.front()];
        double f = 0.0;
        if (mt.size() == 1 && tr == 0.0) f = mf.front(), r.add(f - reference.force_N[i]);
        else if (interpolate_linear(mt, mf, tr, f)) r.add(f - reference.force_N[i]);
        else r.miss();
      }
      add_rmse_term(force_term("dwell", "", w.dwell, r, "over the dwell"));
    }
  }

  bool any_reference_puncture = false;
  for (const PunctureEventMetrics& p : ev.punctures) any_reference_puncture = any_reference_puncture || p.found;
  if (!any_reference_puncture)
    out.warnings.push_back("no puncture found in the reference (" + ev.note + "): puncture terms are n/a");
  return out;
}

}  // namespace puncture::validation
