// calibrate(): the sequence of stages (calibration.hpp). Reads top-down as
// the algorithm: check the references and find their punctures, decide what
// they identify, tune each layer top to bottom (again for layers in series),
// then d, then everything jointly; evaluate before and after; report the
// parameters and what the Jacobian at the optimum says about them.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "calibration_parameters.hpp"
#include "identifiability_report.hpp"
#include "model_runs.hpp"
#include "optimisers.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/calibration.hpp"
#include "puncture/validation/reference_checks.hpp"
#include "scaled_start.hpp"
#include "stage_objective.hpp"

namespace puncture::validation {

using namespace calibration_detail;

namespace {

/// The state of one calibrate() call shared by its stages.
struct Calibration {
  const Scene& scene;
  const std::vector<ReferenceCurve>& references;
  const CalibrationOptions& options;
  const CalibrationProgressCallback& progress;
  std::vector<std::size_t> layers;  ///< calibrated, top to bottom
  std::vector<LayerGeometry> geometry;
  std::vector<LayerIdentifiability> identifiable;  ///< per layer, merged over the references
  SurfaceCache cache;
  int total_evaluations = 0;
  CalibrationStop stop;  ///< the progress callback threw (calibration.hpp)
  std::vector<Parameter> parameters;  ///< every tuned parameter; bounds fixed once, from the scene's values
  std::vector<bool> moved_inside;

  Calibration(const Scene& s, const std::vector<ReferenceCurve>& r, const CalibrationOptions& o,
              const CalibrationProgressCallback& p)
      : scene(s), references(r), options(o), progress(p), geometry(layer_geometry(s)), cache(s) {}

  StageInputs inputs(const CalibrationResult& result) {
    return StageInputs{&references, &result.reference_events, &geometry, &options, &cache, &progress,
                       &total_evaluations, &stop};
  }
  Parameter parameter(std::size_t k, ParamKind kind) {
    for (const Parameter& p : parameters)
      if (p.layer == k && p.kind == kind) return p;
    bool moved = false;
    parameters.push_back(make_parameter(scene, k, kind, options.bound_factor, moved));
    moved_inside.push_back(moved);
    return parameters.back();
  }
  bool calibrated(std::size_t k) const { return std::find(layers.begin(), layers.end(), k) != layers.end(); }
};

void check_options(const Scene& scene, const std::vector<ReferenceCurve>& references, const CalibrationOptions& o) {
  if (references.empty()) throw std::invalid_argument("calibrate: no reference curve");
  if (scene.layers.empty()) throw std::invalid_argument("calibrate: the scene has no layers");
  if (!(o.bound_factor > 1.0)) throw std::invalid_argument("calibrate: bound_factor must be > 1");
  if (o.max_evaluations_per_stage < 1) throw std::invalid_argument("calibrate: max_evaluations_per_stage must be >= 1");
  if (o.rings_search_radius < 0) throw std::invalid_argument("calibrate: rings_search_radius must be >= 0");
  if (o.threads < 0) throw std::invalid_argument("calibrate: threads must be >= 0");
  if (!(o.lm_difference_step > 0.0)) throw std::invalid_argument("calibrate: lm_difference_step must be > 0");
  parse_mesh_integrator(o.integrator);
  for (const ReferenceCurve& r : references) insertion_phase(r.curve);  // throws with the file name if unusable
}

/// The references' punctures, checked (reference_checks.hpp), and what they identify per layer (any reference counts).
void find_reference_events(Calibration& c, CalibrationResult& result) {
  const CalibrationOptions& o = c.options;
  for (std::size_t r = 0; r < c.references.size(); ++r) {
    const InsertionCurve& curve = c.references[r].curve;
    result.reference_events.push_back(
        reference_events(curve, c.geometry, r == 0 ? o.puncture_depths_m : std::vector<double>{}, o.detection));
    result.warnings.push_back(curve.source + ": " + result.reference_events.back().note);
    check_reference_fittable(curve, result.reference_events.back(), r == 0 && !o.puncture_depths_m.empty(), o.detection);
  }
  c.identifiable.assign(c.geometry.size(), {});
  for (std::size_t r = 0; r < c.references.size(); ++r) {
    const auto more = layer_identifiability(c.references[r].curve, result.reference_events[r], c.geometry);
    for (std::size_t k = 0; k < c.identifiable.size(); ++k) {
      c.identifiable[k].pressing_samples = std::max(c.identifiable[k].pressing_samples, more[k].pressing_samples);
      c.identifiable[k].cut_samples = std::max(c.identifiable[k].cut_samples, more[k].cut_samples);
      c.identifiable[k].punctured = c.identifiable[k].punctured || more[k].punctured;
    }
  }
}

/// True when layer k (k >= 1) is met at the tip when the layer above breaks in
/// the first reference (its puncture deeper than k's rest top, without layer
/// interaction): the crack above stays open while k is pressed
/// (shaft_forces.hpp), so the cutting force of layer k - 1 is felt over k's
/// pressing, however short its own cut.
bool met_at_tip(const Calibration& c, const CalibrationResult& result, std::size_t k) {
  if (k == 0 || k >= c.geometry.size() || c.scene.effects.layer_interaction) return false;
  const auto& above = result.reference_events.front().punctures[k - 1];
  return above.found && above.depth_m > c.geometry[k].top_depth_m;
}

/// Layer k's stage also tunes the cutting force of the layer above when k is
/// met at the tip (see above) and punctured in the reference: k's puncture
/// force is then that cutting force + k's critical force + the shaft forces,
/// at a depth k's critical force sets, so k's puncture depth and force
/// identify both, however few samples the cut above has.
bool tunes_cutting_above(const Calibration& c, const CalibrationResult& result, std::size_t k) {
  return c.options.cutting_from_next_puncture && c.options.parameters.cutting && c.scene.effects.cutting && k > 0 &&
         c.calibrated(k - 1) &&
         met_at_tip(c, result, k) && c.identifiable[k].punctured;
}

/// Layer k's stage also tunes the rupture release of the layer above
/// (cutting.hpp) when its own cut is too short to identify it: the release
/// goes on while k is pressed and cut (k's stage compares the layers above
/// down to the end of k's cut), whatever the layers below do.
bool tunes_release_above(const Calibration& c, std::size_t k) {
  if (k == 0 || k >= c.scene.layers.size() || !c.options.parameters.cutting || !c.scene.effects.cutting) return false;
  return c.calibrated(k - 1) && c.calibrated(k) && c.scene.layers[k - 1].force_law.rupture_release_m > 0.0 &&
         c.identifiable[k - 1].punctured && (c.identifiable[k].pressing() || c.identifiable[k].punctured) &&
         !unidentified_reason(c.identifiable[k - 1], ParamKind::RuptureRelease).empty();
}

/// Layer k's parameter `kind` is tuned in layer k + 1's stage (see above).
bool tuned_in_stage_below(const Calibration& c, const CalibrationResult& result, std::size_t k, ParamKind kind) {
  if (kind == ParamKind::Cutting) return tunes_cutting_above(c, result, k + 1);
  if (kind == ParamKind::RuptureRelease) return tunes_release_above(c, k + 1);
  return false;
}

/// Why the references cannot identify a parameter; "" when they can (a
/// cutting force or rupture release also when the layer below identifies it,
/// tuned_in_stage_below), or when the user asked to tune it anyway
/// (keep_unidentifiable_at_start off).
std::string withheld_reason(const Calibration& c, const CalibrationResult& result, std::size_t k, ParamKind kind) {
  if (!c.options.keep_unidentifiable_at_start) return {};
  if (tuned_in_stage_below(c, result, k, kind)) return {};
  return unidentified_reason(c.identifiable[k], kind);
}

/// Warns for each requested parameter the references cannot identify (it
/// keeps its start value, or is tuned on request); returns the number that
/// will be tuned and requested.
std::pair<std::size_t, std::size_t> withhold_unidentified(const Calibration& c, CalibrationResult& result) {
  std::size_t tuned = 0, requested = 0;
  for (std::size_t k : c.layers) {
    for (ParamKind kind : layer_kinds(c.scene, k, c.options.parameters)) {
      ++requested;
      const std::string why = unidentified_reason(c.identifiable[k], kind);
      if (!why.empty() && tuned_in_stage_below(c, result, k, kind)) {
        const std::string& below = c.scene.layers[k + 1].name;
        result.warnings.push_back(
            "layer " + c.scene.layers[k].name + ": " + info(kind).name + " identified in layer " + below +
            "'s stage (" + why + ", but " +
            (kind == ParamKind::Cutting
                 ? below + " is met at the tip when " + c.scene.layers[k].name +
                       " breaks, so this crack is cut while it is pressed: its puncture force and depth identify "
                       "this cutting force)"
                 : "the release goes on while " + below + " is pressed and cut, which " + below +
                       "'s stage compares)"));
        ++tuned;
        continue;
      }
      if (!why.empty())
        result.warnings.push_back(
            "layer " + c.scene.layers[k].name + ": " + info(kind).name +
            (c.options.keep_unidentifiable_at_start
                 ? " kept at its start value (" + std::to_string(param_value(c.scene, k, kind) * info(kind).to_unit) +
                       " " + info(kind).unit + "): " + why
                 : " tuned on request although " + why));
      if (withheld_reason(c, result, k, kind).empty()) ++tuned;
    }
  }
  return {tuned, requested};
}

/// The distinct insertion speeds (m/s) of the references marked rate_dependent.
std::vector<double> rate_dependent_speeds(const Calibration& c) {
  std::vector<double> speeds;
  for (const ReferenceCurve& r : c.references) {
    if (!reference_is_rate_dependent(r.curve)) continue;
    const double v = reference_speed(c.scene, r.curve);
    bool known = false;
    for (double s : speeds) known = known || std::abs(s - v) <= 1e-6 * std::max(s, v);
    if (!known) speeds.push_back(v);
  }
  std::sort(speeds.begin(), speeds.end());
  return speeds;
}

/// Auto: d h v is told apart from the rate-independent shaft friction (and
/// from everything else a reference's force has in proportion to the shaft
/// length) only by how the force changes with the speed, so d is tuned when
/// rate-dependent references span two or more speeds; so is the rate
/// exponent n of every breakthrough threshold (run_rate_stage).
void decide_damping(const Calibration& c, CalibrationResult& result) {
  const std::vector<double> speeds = rate_dependent_speeds(c);
  std::ostringstream listed_text;
  listed_text.precision(4);
  for (std::size_t i = 0; i < speeds.size(); ++i) listed_text << (i ? ", " : "") << speeds[i] * 1e3;
  const std::string listed = listed_text.str();
  switch (c.options.parameters.damping) {
    case DampingPolicy::Fixed:
      result.damping_tuned = false;
      result.damping_note = "d kept fixed (DampingPolicy::Fixed)";
      break;
    case DampingPolicy::Tune:
      result.damping_tuned = true;
      result.damping_note = "d tuned on request (DampingPolicy::Tune)";
      break;
    case DampingPolicy::Auto:
      result.damping_tuned = speeds.size() >= 2;
      if (speeds.size() >= 2)
        result.damping_note = "d (and the breakthrough rate exponents n, cutting viscous fractions b and release "
                              "rate exponents m) tuned: rate-dependent references at " + listed + " mm/s";
      else if (speeds.size() == 1)
        result.damping_note = "d kept fixed: rate-dependent references at one speed only (" + listed +
                              " mm/s); at one speed d h v cannot be told apart from the shaft friction, so d "
                              "needs references at two or more speeds";
      else
        result.damping_note = "d kept fixed: no reference carries rate information (rate_dependent metadata); "
                              "a quasi-static reference cannot identify d";
      break;
  }
  if (result.damping_tuned && !c.scene.effects.damping) {
    result.damping_tuned = false;
    result.damping_note = "d kept fixed: the scene's damping effect is off";
  }
}

/// The terms of layer k's stage per reference: its own and those of the
/// calibrated layers above it (in series, layer k's stiffness changes their
/// pressing too), down to the end of its cut, and the withdrawal inside the
/// layers down to this one, clear of the model's turning point.
std::vector<TermSelection> layer_stage_selection(const Calibration& c, const CalibrationResult& result, std::size_t k) {
  std::vector<TermSelection> selection;
  for (const ReferenceEvents& ev : result.reference_events) {
    const LayerSegments seg = layer_segments(ev, c.geometry)[k];
    TermSelection sel;
    for (std::size_t j : c.layers)
      if (j <= k) sel.layers.push_back(j);
    sel.whole_curve_terms = false;
    sel.dwell = false;
    double end = std::numeric_limits<double>::infinity();
    if (seg.has_after) end = seg.after_to_m;
    else if (ev.punctures[k].found) end = ev.punctures[k].depth_m + c.options.depth_margin_m;
    else if (seg.has_pressing) end = seg.pressing_to_m;
    sel.max_depth_m = end;
    sel.withdrawal_max_depth_m = std::min(end - 0.5e-3, c.geometry[k].top_depth_m + c.geometry[k].thickness_m);
    selection.push_back(sel);
  }
  return selection;
}

/// Where a stage's model runs turn: past the deepest compared depth by the margin (whole trajectory without one).
double stage_turn_depth(const std::vector<TermSelection>& selection, const CalibrationOptions& o) {
  if (!(o.stage_turn_margin_m > 0.0)) return std::numeric_limits<double>::infinity();
  double deepest = 0.0;
  for (const TermSelection& s : selection) deepest = std::max(deepest, s.max_depth_m);
  return deepest + o.stage_turn_margin_m;
}

/// Derivative-free methods: the pressing and breakthrough parameters first
/// (cutting and friction where the start put them), then cutting and
/// friction, then all together: each step low-dimensional, where Nelder-Mead
/// converges (cutting and friction are small forces next to the puncture
/// peak, nearly flat directions of the whole problem). Levenberg-Marquardt
/// takes them all at once.
std::string optimise_stage(StageObjective& stage, const std::vector<double>& x0) {
  if (stage.parameters.empty()) return "nothing to tune";
  std::vector<Parameter> shape, level;
  for (const Parameter& p : stage.parameters) {
    const bool cut_level = p.kind == ParamKind::Cutting || p.kind == ParamKind::Friction ||
                           p.kind == ParamKind::RuptureRelease;
    (cut_level ? level : shape).push_back(p);
  }
  std::string record;
  if (stage.inputs().options->method != CalibrationMethod::LevenbergMarquardt && !shape.empty() && !level.empty()) {
    for (const std::vector<Parameter>* subset : {&shape, &level}) {
      StageObjective sub(stage.inputs(), stage.name());
      sub.scene = stage.best_x().empty() ? stage.scene : stage.scene_at(stage.best_x().data());
      sub.selection = stage.selection;
      sub.turn_depth_m = stage.turn_depth_m;
      sub.parameters = *subset;
      record += (record.empty() ? "" : "; ") + run_stage(sub, x_values(sub.scene, sub.parameters));
      stage.add_evaluations(sub.evaluations());
      if (!sub.best_x().empty()) stage.offer(x_values(sub.scene_at(sub.best_x().data()), stage.parameters), sub.best());
    }
    record += "; all: ";
  }
  return record + run_stage(stage, stage.best_x().empty() ? x0 : stage.best_x());
}

/// One ring count w of layer k's stage; returns the stage's best scene and objective.
std::pair<Scene, double> run_ring_candidate(Calibration& c, CalibrationResult& result, std::size_t k, Scene candidate,
                                            const std::string& name, bool first_pass) {
  StageObjective stage(c.inputs(result), name);
  stage.scene = candidate;
  stage.selection = layer_stage_selection(c, result, k);
  stage.turn_depth_m = stage_turn_depth(stage.selection, c.options);
  for (ParamKind kind : layer_kinds(candidate, k, c.options.parameters,
                                    c.options.keep_unidentifiable_at_start ? &c.identifiable[k] : nullptr))
    stage.parameters.push_back(c.parameter(k, kind));
  for (ParamKind kind : {ParamKind::Cutting, ParamKind::RuptureRelease}) {
    if (k == 0 || !tuned_in_stage_below(c, result, k - 1, kind)) continue;
    const Parameter above = c.parameter(k - 1, kind);
    if (std::none_of(stage.parameters.begin(), stage.parameters.end(),
                     [&](const Parameter& p) { return p.layer == above.layer && p.kind == above.kind; }))
      stage.parameters.push_back(above);
  }
  if (stage.parameters.size() > static_cast<std::size_t>(kMaxParameters))
    throw std::invalid_argument("calibrate: too many parameters in one stage");
  CalibrationStageRecord rec;
  rec.stage = name;
  clamp_into_bounds(candidate, stage.parameters);
  if (c.options.scaled_start && first_pass)
    candidate = scaled_start(candidate, k, c.references.front(), result.reference_events.front(), c.geometry, c.options,
                             c.cache, stage.parameters);
  stage.scene = candidate;
  const std::vector<double> x0 = x_values(candidate, stage.parameters);
  rec.objective_start = stage.evaluate(x0.data());
  rec.nlopt_result = optimise_stage(stage, x0);
  rec.objective_best = stage.best();
  rec.evaluations = stage.evaluations();
  result.stages.push_back(rec);
  return {stage.best_x().empty() ? candidate : stage.scene_at(stage.best_x().data()), stage.best()};
}

/// Layer k's stage at its ring count (and the neighbouring ones when w is tuned, first pass).
Scene run_layer_stage(Calibration& c, CalibrationResult& result, const Scene& current, std::size_t k, int pass,
                      int passes) {
  std::vector<int> rings{current.layers[k].force_mesh.rings_w};
  if (c.options.parameters.rings && pass == 0)
    for (int dw = 1; dw <= c.options.rings_search_radius; ++dw)
      for (int w : {rings.front() - dw, rings.front() + dw})
        if (w >= 2) rings.push_back(w);
  std::pair<Scene, double> best{current, std::numeric_limits<double>::infinity()};
  std::string rejected;
  for (int w : rings) {
    Scene candidate = current;
    candidate.layers[k].force_mesh.rings_w = w;
    try {
      validate_scene(candidate, "calibration candidate");
    } catch (const SceneError& e) {
      rejected = e.what();
      continue;  // e.g. the force mesh would leave the sample
    }
    const std::string name = current.layers[k].name + " (w = " + std::to_string(w) + ")" +
                             (passes > 1 ? ", pass " + std::to_string(pass + 1) : std::string());
    auto tried = run_ring_candidate(c, result, k, candidate, name, pass == 0);
    if (tried.second < best.second) best = std::move(tried);
  }
  if (!std::isfinite(best.second) && !rejected.empty())  // not one ring count was a valid scene: say why
    throw std::invalid_argument("calibrate: layer " + current.layers[k].name + ": no valid scene to tune (" +
                                rejected + ")");
  return best.first;
}

/// A stage over `parameters` on the whole objective (every term, dwell included, whole trajectory).
StageObjective whole_objective_stage(Calibration& c, CalibrationResult& result, const std::string& name,
                                     const Scene& current, std::vector<Parameter> parameters) {
  StageObjective stage(c.inputs(result), name);
  stage.scene = current;
  stage.selection.assign(c.references.size(), TermSelection{});
  stage.with_dwell = true;
  stage.parameters = std::move(parameters);
  return stage;
}

/// True when layer k's cutting force gets a rate law in the rate stage: the
/// scene cuts and the references cut through the layer (cutting.hpp). Like d
/// and n it is decided by the references' speeds, also when C itself is kept.
bool tunes_cutting_rate(const Calibration& c, std::size_t k) {
  return c.scene.effects.cutting && c.identifiable[k].cut();
}

/// True when layer k's rupture release length gets a rate law in the rate
/// stage: the scene uses a release (a length > 0) and the references cut
/// through the layer.
bool tunes_release_rate(const Calibration& c, std::size_t k) {
  return tunes_cutting_rate(c, k) && c.scene.layers[k].force_law.rupture_release_m > 0.0;
}

/// The rate stage: d of every calibrated layer, the rate exponent n of every
/// breakthrough threshold that has one (breakthrough_rate.hpp) with the
/// threshold's level at v_ref when the layer stage tuned it (fitted there to
/// every speed at the start n, a compromise n alone cannot undo), the viscous
/// fraction b of every cutting force the references cut and the rate exponent
/// m of every rupture release length in use (cutting.hpp), on the
/// whole trajectory of references at two or more speeds; every other
/// parameter as the layer stages left it. A cutting force or release length
/// without a rate law yet gets the scene's insertion speed (the calibration
/// trajectory's, where the layer stages fitted it) as its reference speed v_ref.
Scene run_rate_stage(Calibration& c, CalibrationResult& result, const Scene& current_in) {
  Scene current = current_in;
  std::vector<Parameter> ds;
  for (std::size_t k : c.layers) {
    ds.push_back(c.parameter(k, ParamKind::Damping));
    if (has_breakthrough_rate(c.scene, k)) {
      ds.push_back(c.parameter(k, ParamKind::BreakthroughRate));
      // With n its level F_c,ref (or G,ref): the layer stage fitted it to every speed at the start n.
      for (const Parameter& p : std::vector<Parameter>(c.parameters))
        if (p.layer == k && (p.kind == ParamKind::CriticalForce || p.kind == ParamKind::CriticalEnergy)) ds.push_back(p);
    }
    if (tunes_cutting_rate(c, k)) {
      ds.push_back(c.parameter(k, ParamKind::CuttingRate));
      CuttingRate& rate = current.layers[k].force_law.cutting_rate;
      if (rate.viscous_fraction == 0.0) rate.reference_speed_m_per_s = c.scene.insertion.speed_m_per_s;
    }
    if (tunes_release_rate(c, k)) {
      ds.push_back(c.parameter(k, ParamKind::ReleaseRate));
      ReleaseRate& rate = current.layers[k].force_law.rupture_release_rate;
      if (rate.exponent == 0.0) rate.reference_speed_m_per_s = c.scene.insertion.speed_m_per_s;
    }
  }
  StageObjective stage = whole_objective_stage(c, result, "rate (d, n, b, m)", current, ds);
  const std::vector<double> x0 = x_values(current, stage.parameters);
  CalibrationStageRecord rec;
  rec.stage = stage.name();
  rec.objective_start = stage.evaluate(x0.data());
  rec.nlopt_result = run_stage(stage, x0);
  rec.objective_best = stage.best();
  rec.evaluations = stage.evaluations();
  result.stages.push_back(rec);
  return stage.scene_at(stage.best_x().data());
}

/// The tuned parameters of the calibrated layers (d included when tuned).
std::vector<Parameter> calibrated_parameters(const Calibration& c) {
  std::vector<Parameter> ps;
  for (const Parameter& p : c.parameters)
    if (c.calibrated(p.layer)) ps.push_back(p);
  return ps;
}

/// Every tuned parameter of every calibrated layer on the whole objective.
Scene run_joint_stage(Calibration& c, CalibrationResult& result, const Scene& current) {
  StageObjective stage = whole_objective_stage(c, result, "joint", current, calibrated_parameters(c));
  const std::vector<double> x0 = x_values(current, stage.parameters);
  CalibrationStageRecord rec;
  rec.stage = stage.name();
  rec.objective_start = stage.evaluate(x0.data());
  const bool worth_it = c.options.joint_polish && stage.parameters.size() > 1 &&
                        stage.parameters.size() <= static_cast<std::size_t>(kMaxParameters) &&
                        (c.layers.size() > 1 || result.damping_tuned);
  rec.nlopt_result = worth_it ? run_stage(stage, x0) : "not run (one layer, or joint_polish off)";
  rec.objective_best = stage.best();
  rec.evaluations = stage.evaluations();
  result.stages.push_back(rec);
  result.objective_after = stage.best();
  return worth_it && stage.best() < rec.objective_start ? stage.scene_at(stage.best_x().data()) : current;
}

/// The whole objective before and after, the model curves and comparisons per reference.
void evaluate_before_and_after(Calibration& c, CalibrationResult& result) {
  StageObjective whole = whole_objective_stage(c, result, "before", c.scene, {});
  try {
    result.objective_before = whole.value_of(c.scene);
  } catch (const std::exception&) {
    result.objective_before = kFailedObjective;
  }
  for (std::size_t r = 0; r < c.references.size(); ++r) {
    const ReferenceCurve& ref = c.references[r];
    result.model_before.push_back(simulate_insertion_curve(objective_scene(c.scene, ref, c.options, true), &c.cache));
    result.model_after.push_back(
        simulate_insertion_curve(objective_scene(result.tuned_scene, ref, c.options, true), &c.cache));
    result.before.push_back(compare_curves(result.model_before.back(), ref.curve));
    result.after.push_back(compare_curves(result.model_after.back(), ref.curve));
    result.trajectory_before.push_back(compare_trajectory(result.model_before.back(), ref.curve,
                                                          result.reference_events[r], c.geometry, c.options.weights));
    result.trajectory_after.push_back(compare_trajectory(result.model_after.back(), ref.curve,
                                                         result.reference_events[r], c.geometry, c.options.weights));
    for (const std::string& w : result.trajectory_after.back().warnings) result.warnings.push_back(ref.curve.source + ": " + w);
  }
}

void record_parameters(const Calibration& c, CalibrationResult& result) {
  for (std::size_t i = 0; i < c.parameters.size(); ++i) {
    if (!c.calibrated(c.parameters[i].layer) && c.parameters[i].kind != ParamKind::Damping &&
        c.parameters[i].kind != ParamKind::BreakthroughRate && c.parameters[i].kind != ParamKind::CuttingRate &&
        c.parameters[i].kind != ParamKind::ReleaseRate)
      continue;
    const TunedParameterRecord rec = parameter_record(c.scene, result.tuned_scene, c.parameters[i], c.moved_inside[i]);
    if (rec.start_moved_inside)
      result.warnings.push_back("layer " + rec.layer + ": " + rec.name + " started outside its physical bounds (" +
                                std::to_string(rec.start) + " " + rec.unit + "), moved inside");
    if (!rec.at_bound.empty())
      result.warnings.push_back("layer " + rec.layer + ": " + rec.name + " ended at its " + rec.at_bound + " bound (" +
                                std::to_string(rec.tuned) + " " + rec.unit + ")");
    result.parameters.push_back(rec);
  }
}

/// Tuned parameters the objective does not change with at the optimum go
/// back to their start values (calibration.hpp), unless the whole objective
/// then rises.
void restore_unidentified(Calibration& c, CalibrationResult& result) {
  if (!c.options.keep_unidentifiable_at_start) return;
  // The report lists the tuned parameters first, in this order.
  const std::vector<Parameter> tuned = calibrated_parameters(c);
  std::vector<ParameterIdentifiability>& report = result.identifiability.parameters;
  Scene restored = result.tuned_scene;
  std::vector<std::size_t> changed;
  for (std::size_t j = 0; j < tuned.size() && j < report.size(); ++j)
    if (report[j].insensitive) {
      set_param(restored, tuned[j], param_value(c.scene, tuned[j].layer, tuned[j].kind));
      changed.push_back(j);
    }
  if (changed.empty()) return;
  StageObjective whole = whole_objective_stage(c, result, "restore", restored, {});
  if (!(whole.value_of(restored) <= result.objective_after * (1.0 + 1e-9))) return;
  result.tuned_scene = restored;
  for (std::size_t j : changed) {
    report[j].value = param_value(restored, tuned[j].layer, tuned[j].kind) * info(tuned[j].kind).to_unit;
    report[j].reason += "; back at its start value";
  }
}

/// The identifiability report at the tuned values (identifiability_report.hpp).
void report_identifiability(Calibration& c, CalibrationResult& result) {
  StageObjective whole = whole_objective_stage(c, result, "identifiability", result.tuned_scene, calibrated_parameters(c));
  std::vector<WithheldParameter> withheld;
  for (std::size_t k : c.layers)
    for (ParamKind kind : layer_kinds(c.scene, k, c.options.parameters)) {
      const std::string why = withheld_reason(c, result, k, kind);
      if (!why.empty()) withheld.push_back({k, kind, why});
    }
  if (!result.damping_tuned && c.scene.effects.damping)
    for (std::size_t k : c.layers) {
      withheld.push_back({k, ParamKind::Damping, result.damping_note});
      if (has_breakthrough_rate(c.scene, k))
        withheld.push_back({k, ParamKind::BreakthroughRate, "tuned with d only; " + result.damping_note});
      if (tunes_cutting_rate(c, k))
        withheld.push_back({k, ParamKind::CuttingRate, "tuned with d only; " + result.damping_note});
      if (tunes_release_rate(c, k))
        withheld.push_back({k, ParamKind::ReleaseRate, "tuned with d only; " + result.damping_note});
    }
  result.identifiability = identifiability_report(whole, withheld, c.options);
}

}  // namespace

CalibrationResult calibrate(const Scene& scene, const std::vector<ReferenceCurve>& references,
                            const CalibrationOptions& options, const CalibrationProgressCallback& progress) {
  check_options(scene, references, options);
  Calibration c(scene, references, options, progress);
  c.layers = selected_layers(scene, options);
  CalibrationResult result;
  for (std::size_t k : c.layers) result.calibrated_layers.push_back(scene.layers[k].name);
  result.initial = layer_parameters(scene);
  find_reference_events(c, result);
  const auto [n_tuned, n_requested] = withhold_unidentified(c, result);
  decide_damping(c, result);
  check_enough_samples(references.front().curve, result.reference_events.front(),
                       n_tuned + (result.damping_tuned ? c.layers.size() : 0), n_requested);

  result.critical_force_note = critical_force_start_note(scene, c.layers, options);
  std::vector<bool> level_tuned(scene.layers.size(), false);
  for (std::size_t k : c.layers)
    level_tuned[k] = options.parameters.deformed_threshold && withheld_reason(c, result, k, ParamKind::CriticalForce).empty();
  Scene current = result.damping_tuned ? rate_exponent_start(scene, c.layers, level_tuned, references,
                                                             result.reference_events, result.warnings)
                                       : scene;
  const int passes = options.passes > 0 ? options.passes
                                        : (scene.effects.layer_interaction && c.layers.size() > 1 ? 2 : 1);
  for (int pass = 0; pass < passes; ++pass)
    for (std::size_t k : c.layers) {
      current = run_layer_stage(c, result, current, k, pass, passes);
      c.stop.rethrow_if_requested();
    }
  if (result.damping_tuned) current = run_rate_stage(c, result, current);
  c.stop.rethrow_if_requested();
  current = run_joint_stage(c, result, current);
  c.stop.rethrow_if_requested();

  result.tuned_scene = current;
  report_identifiability(c, result);
  restore_unidentified(c, result);
  result.tuned = layer_parameters(result.tuned_scene);
  evaluate_before_and_after(c, result);
  record_parameters(c, result);
  result.evaluations = c.total_evaluations;
  return result;
}

CalibrationResult calibrate(const Scene& scene, const InsertionCurve& reference, const CalibrationOptions& options,
                            const CalibrationProgressCallback& progress) {
  std::string kind = "curve";  // unknown origin: compared as it is (damping included)
  const auto it = reference.metadata.find("kind");
  if (it != reference.metadata.end()) kind = it->second;
  return calibrate(scene, std::vector<ReferenceCurve>{{reference, kind}}, options, progress);
}

}  // namespace puncture::validation
