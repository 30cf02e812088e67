#include "puncture/validation/calibration.hpp"

#include <gsl/gsl_rng.h>
#include <gsl/gsl_siman.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <nlohmann/json.hpp>
#include <nlopt.hpp>
#include <stdexcept>

#include "puncture/io/output_session.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/scene_io.hpp"


namespace puncture::validation {

namespace {
constexpr double kMm = 1e-3;
constexpr int kMaxParameters = 32;
}  // namespace

CalibrationMethod parse_calibration_method(const std::string& name) {
  if (name == "bobyqa") return CalibrationMethod::Bobyqa;
  if (name == "nelder_mead") return CalibrationMethod::NelderMead;
  if (name == "simulated_annealing") return CalibrationMethod::SimulatedAnnealing;
  throw std::invalid_argument("unknown calibration method '" + name +
                              "' (expected bobyqa, nelder_mead or simulated_annealing)");
}

const char* to_string(CalibrationMethod method) {
  switch (method) {
    case CalibrationMethod::Bobyqa: return "bobyqa";
    case CalibrationMethod::NelderMead: return "nelder_mead";
    case CalibrationMethod::SimulatedAnnealing: return "simulated_annealing";
  }
  return "unknown";
}

std::vector<LayerParameters> layer_parameters(const Scene& scene) {
  std::vector<LayerParameters> out;
  for (const Layer& l : scene.layers)
    out.push_back({l.name, l.force_mesh.virtual_stiffness_N_per_m, l.damping_N_s_per_m2, l.force_mesh.rings_w,
                   l.force_mesh.spacing_L_m, l.force_mesh.surface_stiffness_N_per_m, l.force_mesh.deformed_threshold_m});
  return out;
}

bool reference_is_quasi_static(const ReferenceCurve& reference) {
  if (reference_is_rate_dependent(reference.curve)) return false;
  if (reference.kind == "fem") return true;
  const auto it = reference.curve.metadata.find("quasi_static");
  return it != reference.curve.metadata.end() && (it->second == "true" || it->second == "yes" || it->second == "1");
}

bool reference_is_rate_dependent(const InsertionCurve& curve) {
  const auto it = curve.metadata.find("rate_dependent");
  if (it == curve.metadata.end()) return false;
  std::string v = it->second;
  std::transform(v.begin(), v.end(), v.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return v == "true" || v == "yes" || v == "1";
}

// ---------------------------------------------------------------------------
// Surface cache

SurfaceCache::SurfaceCache(const Scene& scene) : diameter_m_(scene.sample.diameter_m), degree_(scene.realtime.sh_degree) {
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    thickness_m_.push_back(scene.layers[k].thickness_m);
    const LayerDisc disc = layer_disc(scene, k);
    surfaces_.push_back(LayerSurface::fit(disc.top_z_m, disc.bottom_z_m, disc.radius_m, degree_));
    const LayerSurface& s = surfaces_.back();
    fits_.push_back({scene.layers[k].name, s.degree(), s.fit_report(), s.top_face_max_error_m(),
                     s.top_face_rms_error_m(), s.whole_surface_rms_error_m()});
  }
}

bool SurfaceCache::matches(const Scene& scene) const {
  if (scene.layers.size() != thickness_m_.size() || scene.sample.diameter_m != diameter_m_ ||
      scene.realtime.sh_degree != degree_)
    return false;
  for (std::size_t k = 0; k < thickness_m_.size(); ++k)
    if (scene.layers[k].thickness_m != thickness_m_[k]) return false;
  return true;
}

RealtimeModel SurfaceCache::build(const Scene& scene) const {
  if (!matches(scene))
    throw std::invalid_argument("SurfaceCache::build: the scene's geometry or SH degree differs from the cached surfaces");
  RealtimeModel model;
  std::vector<std::unique_ptr<ContactSurface>> owned;
  for (const LayerSurface& s : surfaces_) {
    auto copy = std::make_unique<LayerSurface>(s);
    model.surfaces.push_back(copy.get());
    owned.push_back(std::move(copy));
  }
  model.fits = fits_;
  model.simulator = std::make_unique<PunctureSimulator>(scene, std::move(owned));
  return model;
}

InsertionCurve simulate_insertion_curve(const Scene& scene, const SurfaceCache* cache) {
  RealtimeModel model = cache ? cache->build(scene) : build_realtime_model(scene);
  const ScriptedRunResult run = run_scripted_insertion(model, scene);
  return curve_from_run(scene, run, "realtime model (" + scene.name + ")");
}

// ---------------------------------------------------------------------------
// Stage objective

namespace {

enum class ParamKind { VirtualStiffness, DeformedThreshold, SurfaceStiffness, Spacing, Damping };

const char* param_name(ParamKind k) {
  switch (k) {
    case ParamKind::VirtualStiffness: return "K";
    case ParamKind::DeformedThreshold: return "deformed_threshold";
    case ParamKind::SurfaceStiffness: return "surface_stiffness";
    case ParamKind::Spacing: return "L";
    case ParamKind::Damping: return "d";
  }
  return "?";
}

double& param_ref(Scene& s, std::size_t layer, ParamKind k) {
  Layer& l = s.layers[layer];
  switch (k) {
    case ParamKind::VirtualStiffness: return l.force_mesh.virtual_stiffness_N_per_m;
    case ParamKind::DeformedThreshold: return l.force_mesh.deformed_threshold_m;
    case ParamKind::SurfaceStiffness: return l.force_mesh.surface_stiffness_N_per_m;
    case ParamKind::Spacing: return l.force_mesh.spacing_L_m;
    case ParamKind::Damping: return l.damping_N_s_per_m2;
  }
  throw std::logic_error("param_ref");
}

struct Parameter {
  std::size_t layer;
  ParamKind kind;
  double lower_log, upper_log;
};

/// Reference speed: metadata "speed_mm_per_s" if present, else the scene's.
double reference_speed(const Scene& scene, const InsertionCurve& ref) {
  double v = 0.0;
  if (ref.metadata_number("speed_mm_per_s", v)) {
    if (!(v > 0.0)) throw std::invalid_argument(ref.source + ": metadata speed_mm_per_s must be > 0");
    return v * kMm;
  }
  return scene.insertion.speed_m_per_s;
}

/// The cheap model run for one reference (see the header comment).
Scene objective_scene(const Scene& current, const ReferenceCurve& reference, const CalibrationOptions& o,
                      double max_depth_m) {
  const InsertionCurve& ref = reference.curve;
  Scene s = current;
  // A quasi-static, frictionless reference (the FEM) has nothing the damping
  // force d h v could be compared with: the model runs without it (d itself
  // stays in the tuned scene).
  if (reference_is_quasi_static(reference)) s.effects.damping = false;
  s.realtime.integrator = o.integrator;
  s.effects.surface_output = false;
  s.insertion.speed_m_per_s = reference_speed(current, ref);
  s.insertion.dwell_s = 0.0;
  if (std::isfinite(max_depth_m)) s.insertion.target_depth_m = std::min(s.insertion.target_depth_m, max_depth_m);
  s.insertion.withdrawal_speed_m_per_s = std::max(0.2, 20.0 * s.insertion.speed_m_per_s);
  if (o.objective_depth_step_m > 0.0)
    s.realtime.haptic_rate_Hz = std::max(s.realtime.haptic_rate_Hz, s.insertion.speed_m_per_s / o.objective_depth_step_m);
  return s;
}

}  // namespace

Scene calibration_run_scene(const Scene& scene, const ReferenceCurve& reference, const CalibrationOptions& options) {
  return objective_scene(scene, reference, options, std::numeric_limits<double>::infinity());
}

namespace {

struct StageContext {
  const std::vector<ReferenceCurve>* references = nullptr;
  const CalibrationOptions* options = nullptr;
  const SurfaceCache* cache = nullptr;
  const CalibrationProgressCallback* progress = nullptr;
  Scene scene;                          ///< current values (the stage's parameters are overwritten per evaluation)
  std::vector<Parameter> parameters;
  std::vector<std::size_t> layers;      ///< layers whose per-layer terms enter the objective
  std::vector<double> max_depth_m;      ///< per reference
  std::string name;
  int* total_evaluations = nullptr;
  int evaluations = 0;
  double best = std::numeric_limits<double>::infinity();
  std::vector<double> best_x;

  Scene scene_at(const double* x) const {
    Scene s = scene;
    for (std::size_t p = 0; p < parameters.size(); ++p)
      param_ref(s, parameters[p].layer, parameters[p].kind) = std::exp(x[p]);
    return s;
  }

  double objective_of(const Scene& s) const {
    const CalibrationWeights& w = options->weights;
    double total = 0.0;
    for (std::size_t r = 0; r < references->size(); ++r) {
      const InsertionCurve& ref = (*references)[r].curve;
      // The model runs the whole insertion (so its breakthrough of the stage's
      // layer is found wherever it happens); the force is compared down to
      // max_depth_m only.
      const InsertionCurve model = simulate_insertion_curve(
          objective_scene(s, (*references)[r], *options, std::numeric_limits<double>::infinity()), cache);
      const CurveComparison c = compare_curves(model, ref, max_depth_m[r]);
      if (c.n_compared == 0) return kFailedObjective;
      const double peak = c.reference_peak_force_N > 0.0 ? c.reference_peak_force_N : 1.0;
      total += w.overall_rmse * c.force_rmse_relative * c.force_rmse_relative;
      for (std::size_t k : layers) {
        const LayerMetrics* lm = c.layer(s.layers[k].name);
        if (!lm) continue;
        total += w.layer_rmse * lm->force_rmse_relative * lm->force_rmse_relative;
        if (lm->reference_puncture.found && lm->model_puncture.found) {
          // Depth scale: the layer's ring spacing L (the accuracy asked of a
          // puncture depth), or its thickness if thinner.
          const double depth_scale = std::min(s.layers[k].thickness_m, s.layers[k].force_mesh.spacing_L_m);
          const double dz = lm->puncture_depth_error_m / depth_scale;
          const double f_ref = lm->reference_puncture.force_N > 0.0 ? lm->reference_puncture.force_N : peak;
          const double df = lm->puncture_force_error_N / f_ref;
          total += w.puncture_depth * dz * dz + w.puncture_force * df * df;
        } else if (lm->reference_puncture.found != lm->model_puncture.found) {
          total += w.missing_puncture;
        }
      }
    }
    return std::isfinite(total) ? total : kFailedObjective;
  }

  double evaluate(const double* x) {
    double f = kFailedObjective;
    try {
      f = objective_of(scene_at(x));
    } catch (const std::exception&) {
      f = kFailedObjective;  // e.g. a candidate the simulator rejects: counted, never accepted
    }
    ++evaluations;
    if (total_evaluations) ++*total_evaluations;
    if (f < best) {
      best = f;
      best_x.assign(x, x + parameters.size());
    }
    if (progress && *progress)
      (*progress)(CalibrationProgress{total_evaluations ? *total_evaluations : evaluations, best, f, name});
    return f;
  }
};

double nlopt_objective(unsigned n, const double* x, double* grad, void* data) {
  (void)n;
  (void)grad;  // derivative-free algorithms only
  return static_cast<StageContext*>(data)->evaluate(x);
}

const char* nlopt_result_name(nlopt::result r) {
  switch (r) {
    case nlopt::SUCCESS: return "success";
    case nlopt::STOPVAL_REACHED: return "stopval_reached";
    case nlopt::FTOL_REACHED: return "ftol_reached";
    case nlopt::XTOL_REACHED: return "xtol_reached";
    case nlopt::MAXEVAL_REACHED: return "maxeval_reached";
    case nlopt::MAXTIME_REACHED: return "maxtime_reached";
    default: return "failure";
  }
}

/// One local derivative-free minimisation in log space; returns NLopt's code name.
std::string run_nlopt_once(StageContext& ctx, nlopt::algorithm algorithm, std::vector<double> x, int max_evaluations) {
  const unsigned n = static_cast<unsigned>(ctx.parameters.size());
  // NLopt's BOBYQA needs at least two variables; one variable goes to Nelder-Mead.
  if (n < 2 && algorithm == nlopt::LN_BOBYQA) algorithm = nlopt::LN_NELDERMEAD;
  nlopt::opt opt(algorithm, n);
  std::vector<double> lo(n), hi(n), step(n);
  for (unsigned p = 0; p < n; ++p) {
    lo[p] = ctx.parameters[p].lower_log, hi[p] = ctx.parameters[p].upper_log;
    x[p] = std::clamp(x[p], lo[p], hi[p]);
    step[p] = std::min(0.2, 0.25 * (hi[p] - lo[p]));
  }
  opt.set_lower_bounds(lo);
  opt.set_upper_bounds(hi);
  opt.set_initial_step(step);
  opt.set_min_objective(nlopt_objective, &ctx);
  opt.set_maxeval(max_evaluations);
  opt.set_xtol_abs(ctx.options->log_x_tolerance);
  opt.set_ftol_abs(1e-14);
  double f = 0.0;
  try {
    return nlopt_result_name(opt.optimize(x, f));
  } catch (const nlopt::roundoff_limited&) {
    return "roundoff_limited";
  } catch (const std::runtime_error& e) {
    return std::string("failure: ") + e.what();
  }
}

/// Local minimisation with restarts: the objective has narrow curved valleys
/// (K against the threshold) and small steps where a breakthrough moves by
/// one tick, on which BOBYQA's trust region can collapse early. While a run
/// improves the best objective by more than 1 % and evaluations remain, a new
/// run starts from the best point with fresh initial steps.
std::string run_nlopt(StageContext& ctx, nlopt::algorithm algorithm, const std::vector<double>& x0) {
  const int budget = ctx.options->max_evaluations_per_stage;
  const int start_evaluations = ctx.evaluations;
  std::string record;
  std::vector<double> x = x0;
  for (int run = 0; run < 20; ++run) {
    const int left = budget - (ctx.evaluations - start_evaluations);
    if (left < 2 * static_cast<int>(ctx.parameters.size()) + 2) break;
    const double before = ctx.best;
    record = run_nlopt_once(ctx, algorithm, x, left);
    if (!ctx.best_x.empty()) x = ctx.best_x;
    if (!(ctx.best < before - 0.01 * std::abs(before))) break;
    if (run > 0) record += " (restart " + std::to_string(run) + ")";
  }
  return record;
}

// --- simulated annealing (GSL gsl_siman, fixed-size state) ---
struct AnnealState {
  int n;
  double x[kMaxParameters];
};
thread_local StageContext* g_anneal_ctx = nullptr;
thread_local double g_anneal_scale = 1.0;

double anneal_energy(void* xp) {
  const auto* s = static_cast<const AnnealState*>(xp);
  return g_anneal_ctx->evaluate(s->x) / g_anneal_scale;
}
void anneal_step(const gsl_rng* r, void* xp, double step_size) {
  auto* s = static_cast<AnnealState*>(xp);
  for (int p = 0; p < s->n; ++p) {
    const Parameter& par = g_anneal_ctx->parameters[static_cast<std::size_t>(p)];
    const double u = 2.0 * gsl_rng_uniform(r) - 1.0;
    s->x[p] = std::clamp(s->x[p] + u * step_size, par.lower_log, par.upper_log);
  }
}
double anneal_distance(void* a, void* b) {
  const auto* s = static_cast<const AnnealState*>(a);
  const auto* t = static_cast<const AnnealState*>(b);
  double d = 0.0;
  for (int p = 0; p < s->n; ++p) d += (s->x[p] - t->x[p]) * (s->x[p] - t->x[p]);
  return std::sqrt(d);
}

std::string run_annealing(StageContext& ctx, const std::vector<double>& x0) {
  const AnnealingSettings& a = ctx.options->annealing;
  AnnealState state{static_cast<int>(x0.size()), {}};
  std::copy(x0.begin(), x0.end(), state.x);
  const double f0 = ctx.evaluate(state.x);
  g_anneal_ctx = &ctx;
  g_anneal_scale = (f0 > 0.0 && f0 < kFailedObjective) ? f0 : 1.0;
  gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(rng, a.seed);
  gsl_siman_params_t params{0, a.iters_fixed_T, a.step_size, 1.0, a.t_initial, a.mu_t, a.t_min};
  gsl_siman_solve(rng, &state, anneal_energy, anneal_step, anneal_distance, nullptr, nullptr, nullptr, nullptr,
                  sizeof(AnnealState), params);
  gsl_rng_free(rng);
  g_anneal_ctx = nullptr;
  std::string record = "annealing";
  if (a.polish_locally) record += " + nelder_mead: " + run_nlopt(ctx, nlopt::LN_NELDERMEAD, ctx.best_x);
  return record;
}

std::string run_stage(StageContext& ctx, const std::vector<double>& x0) {
  switch (ctx.options->method) {
    case CalibrationMethod::Bobyqa: return run_nlopt(ctx, nlopt::LN_BOBYQA, x0);
    case CalibrationMethod::NelderMead: return run_nlopt(ctx, nlopt::LN_NELDERMEAD, x0);
    case CalibrationMethod::SimulatedAnnealing: return run_annealing(ctx, x0);
  }
  throw std::logic_error("run_stage: unknown method");
}

std::vector<double> log_values(const Scene& s, const std::vector<Parameter>& params) {
  std::vector<double> x;
  for (const Parameter& p : params) x.push_back(std::log(param_ref(const_cast<Scene&>(s), p.layer, p.kind)));
  return x;
}

Parameter make_parameter(const Scene& start, std::size_t layer, ParamKind kind, double bound_factor) {
  const double p0 = param_ref(const_cast<Scene&>(start), layer, kind);
  if (!(p0 > 0.0) || !std::isfinite(p0))
    throw std::invalid_argument(std::string("calibrate: layer '") + start.layers[layer].name + "': parameter " +
                                param_name(kind) + " must be > 0 to be tuned in log space");
  return {layer, kind, std::log(p0) - std::log(bound_factor), std::log(p0) + std::log(bound_factor)};
}

/// Pressing phase of a layer in a curve: from the first Pressed sample to the
/// puncture. Returns false if the curve does not press and puncture it.
bool pressing_phase(const InsertionCurve& c, const std::string& layer, double& deflection_m, double& force_rise_N) {
  const int li = c.layer_index(layer);
  const PunctureEventMetrics e = puncture_event(c, layer);
  if (li < 0 || !e.found) return false;
  const auto& states = c.layer_states[static_cast<std::size_t>(li)];
  for (std::size_t i = 0; i < c.size(); ++i)
    if (states[i] == LayerState::Pressed) {
      deflection_m = e.depth_m - c.depth_m[i];
      force_rise_N = e.force_N - c.force_N[i];
      return deflection_m > 0.0 && force_rise_N > 0.0;
    }
  return false;
}

/// Scaled start of a layer's stage (two passes): the layer's stiffnesses (K,
/// and k_s when it is tuned: their ratio, hence the ring profile, is kept) are
/// scaled by the ratio of the reference's pressing slope to the model's, and
/// the deformation threshold by the ratio of the deflections at breakthrough
/// (z0 = threshold / u_w is linear in the threshold). This brings a start
/// that is orders of magnitude off (Table 2 stiffnesses against the FEM) into
/// the basin the local optimiser can handle. Values stay inside the bounds.
Scene scaled_start(const Scene& candidate, std::size_t k, const ReferenceCurve& reference,
                   const CalibrationOptions& options, const SurfaceCache& cache,
                   const std::vector<Parameter>& parameters) {
  const std::string& name = candidate.layers[k].name;
  double z_ref = 0.0, f_ref = 0.0;
  if (!pressing_phase(reference.curve, name, z_ref, f_ref)) return candidate;
  Scene s = candidate;
  auto clamp_to_bounds = [&](ParamKind kind) {
    for (const Parameter& p : parameters)
      if (p.kind == kind) {
        double& v = param_ref(s, k, kind);
        v = std::exp(std::clamp(std::log(v), p.lower_log, p.upper_log));
      }
  };
  for (int pass = 0; pass < 2; ++pass) {
    InsertionCurve model;
    try {
      model = simulate_insertion_curve(objective_scene(s, reference, options, std::numeric_limits<double>::infinity()), &cache);
    } catch (const std::exception&) {
      return candidate;
    }
    double z_model = 0.0, f_model = 0.0;
    if (!pressing_phase(model, name, z_model, f_model)) break;
    const double stiffness_ratio = (f_ref / z_ref) / (f_model / z_model);
    const TunedParameterSet& t = options.parameters;
    if (t.virtual_stiffness) param_ref(s, k, ParamKind::VirtualStiffness) *= stiffness_ratio;
    if (t.surface_stiffness) param_ref(s, k, ParamKind::SurfaceStiffness) *= stiffness_ratio;
    if (t.deformed_threshold) param_ref(s, k, ParamKind::DeformedThreshold) *= z_ref / z_model;
    for (ParamKind kind : {ParamKind::VirtualStiffness, ParamKind::SurfaceStiffness, ParamKind::DeformedThreshold})
      clamp_to_bounds(kind);
  }
  return s;
}

}  // namespace

// ---------------------------------------------------------------------------

CalibrationResult calibrate(const Scene& scene, const std::vector<ReferenceCurve>& references,
                            const CalibrationOptions& options, const CalibrationProgressCallback& progress) {
  if (references.empty()) throw std::invalid_argument("calibrate: no reference curve");
  if (scene.layers.empty()) throw std::invalid_argument("calibrate: the scene has no layers");
  if (!(options.bound_factor > 1.0)) throw std::invalid_argument("calibrate: bound_factor must be > 1");
  if (options.max_evaluations_per_stage < 1) throw std::invalid_argument("calibrate: max_evaluations_per_stage must be >= 1");
  if (options.rings_search_radius < 0) throw std::invalid_argument("calibrate: rings_search_radius must be >= 0");
  parse_mesh_integrator(options.integrator);
  for (const ReferenceCurve& r : references) insertion_phase(r.curve);  // throws with the file name if unusable

  std::vector<std::size_t> layers;
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const bool wanted = options.layers.empty() ||
                        std::find(options.layers.begin(), options.layers.end(), scene.layers[k].name) != options.layers.end();
    if (wanted) layers.push_back(k);
  }
  for (const std::string& name : options.layers) {
    bool found = false;
    for (const Layer& l : scene.layers) found = found || l.name == name;
    if (!found) throw std::invalid_argument("calibrate: the scene has no layer '" + name + "'");
  }

  CalibrationResult result;
  for (std::size_t k : layers) result.calibrated_layers.push_back(scene.layers[k].name);
  result.initial = layer_parameters(scene);

  bool rate_info = false;
  for (const ReferenceCurve& r : references) rate_info = rate_info || reference_is_rate_dependent(r.curve);
  switch (options.parameters.damping) {
    case DampingPolicy::Fixed:
      result.damping_tuned = false;
      result.damping_note = "d kept fixed (DampingPolicy::Fixed)";
      break;
    case DampingPolicy::Tune:
      result.damping_tuned = true;
      result.damping_note = "d tuned on request (DampingPolicy::Tune)";
      break;
    case DampingPolicy::Auto:
      result.damping_tuned = rate_info;
      result.damping_note = rate_info ? "d tuned: a reference is marked rate_dependent"
                                      : "d kept fixed: no reference carries rate information (rate_dependent metadata); "
                                        "a quasi-static reference cannot identify d";
      break;
  }

  const SurfaceCache cache(scene);
  int total_evaluations = 0;
  Scene current = scene;

  auto make_context = [&](const std::string& name) {
    StageContext ctx;
    ctx.references = &references;
    ctx.options = &options;
    ctx.cache = &cache;
    ctx.progress = &progress;
    ctx.total_evaluations = &total_evaluations;
    ctx.name = name;
    return ctx;
  };

  // --- per-layer stages, top to bottom ---
  for (std::size_t k : layers) {
    const std::string& lname = scene.layers[k].name;
    std::vector<double> max_depth;
    for (const ReferenceCurve& r : references) {
      const PunctureEventMetrics e = puncture_event(r.curve, lname);
      max_depth.push_back(e.found ? e.depth_m + options.depth_margin_m : std::numeric_limits<double>::infinity());
    }
    std::vector<ParamKind> kinds;
    const TunedParameterSet& t = options.parameters;
    if (t.virtual_stiffness) kinds.push_back(ParamKind::VirtualStiffness);
    if (t.deformed_threshold) kinds.push_back(ParamKind::DeformedThreshold);
    if (t.surface_stiffness) kinds.push_back(ParamKind::SurfaceStiffness);
    if (t.spacing) kinds.push_back(ParamKind::Spacing);
    std::vector<int> ring_candidates{current.layers[k].force_mesh.rings_w};
    if (t.rings)
      for (int dw = 1; dw <= options.rings_search_radius; ++dw)
        for (int w : {ring_candidates.front() - dw, ring_candidates.front() + dw})
          if (w >= 2) ring_candidates.push_back(w);

    double stage_best = std::numeric_limits<double>::infinity();
    Scene stage_best_scene = current;
    bool have_start = false;
    for (int w : ring_candidates) {
      Scene candidate = current;
      candidate.layers[k].force_mesh.rings_w = w;
      try {
        validate_scene(candidate, "calibration candidate");
      } catch (const SceneError&) {
        continue;  // e.g. the force mesh would leave the sample
      }
      StageContext ctx = make_context(lname + " (w = " + std::to_string(w) + ")");
      ctx.scene = candidate;
      ctx.layers = {k};
      ctx.max_depth_m = max_depth;
      for (ParamKind kind : kinds) ctx.parameters.push_back(make_parameter(scene, k, kind, options.bound_factor));
      if (ctx.parameters.size() > static_cast<std::size_t>(kMaxParameters))
        throw std::invalid_argument("calibrate: too many parameters in one stage");
      CalibrationStageRecord rec;
      rec.stage = ctx.name;
      // The objective at the scene's own values: the "before" of the first
      // candidate, and the stage's start unless the start is scaled.
      double at_scene_values = kFailedObjective;
      if (!have_start || !options.scaled_start)
        at_scene_values = ctx.evaluate(log_values(candidate, ctx.parameters).data());
      if (!have_start) {
        result.objective_before += at_scene_values;
        have_start = true;
      }
      if (options.scaled_start) {
        ctx.scene = scaled_start(candidate, k, references.front(), options, cache, ctx.parameters);
        candidate = ctx.scene;
      }
      const std::vector<double> x0 = log_values(candidate, ctx.parameters);
      rec.objective_start = options.scaled_start ? ctx.evaluate(x0.data()) : at_scene_values;
      rec.nlopt_result = ctx.parameters.empty() ? "nothing to tune" : run_stage(ctx, x0);
      rec.objective_best = ctx.best;
      rec.evaluations = ctx.evaluations;
      result.stages.push_back(rec);
      if (ctx.best < stage_best) {
        stage_best = ctx.best;
        stage_best_scene = ctx.scene_at(ctx.best_x.data());
      }
    }
    current = stage_best_scene;
    result.objective_after += std::isfinite(stage_best) ? stage_best : 0.0;
  }

  // --- damping stage: d of every calibrated layer on the whole insertion ---
  if (result.damping_tuned) {
    StageContext ctx = make_context("damping");
    ctx.scene = current;
    ctx.layers = layers;
    ctx.max_depth_m.assign(references.size(), std::numeric_limits<double>::infinity());
    for (std::size_t k : layers) ctx.parameters.push_back(make_parameter(scene, k, ParamKind::Damping, options.bound_factor));
    const std::vector<double> x0 = log_values(current, ctx.parameters);
    CalibrationStageRecord rec;
    rec.stage = ctx.name;
    rec.objective_start = ctx.evaluate(x0.data());
    rec.nlopt_result = run_stage(ctx, x0);
    rec.objective_best = ctx.best;
    rec.evaluations = ctx.evaluations;
    result.stages.push_back(rec);
    current = ctx.scene_at(ctx.best_x.data());
    result.objective_after += ctx.best;
  }

  result.tuned_scene = current;
  result.tuned = layer_parameters(current);
  result.evaluations = total_evaluations;
  const double inf = std::numeric_limits<double>::infinity();
  for (const ReferenceCurve& r : references) {
    result.model_before.push_back(simulate_insertion_curve(objective_scene(scene, r, options, inf), &cache));
    result.model_after.push_back(simulate_insertion_curve(objective_scene(current, r, options, inf), &cache));
    result.before.push_back(compare_curves(result.model_before.back(), r.curve));
    result.after.push_back(compare_curves(result.model_after.back(), r.curve));
  }
  return result;
}

CalibrationResult calibrate(const Scene& scene, const InsertionCurve& reference, const CalibrationOptions& options,
                            const CalibrationProgressCallback& progress) {
  std::string kind = "curve";  // unknown origin: compared as it is (damping included)
  const auto it = reference.metadata.find("kind");
  if (it != reference.metadata.end()) kind = it->second;
  return calibrate(scene, std::vector<ReferenceCurve>{{reference, kind}}, options, progress);
}

// ---------------------------------------------------------------------------
// Preset

namespace {

nlohmann::json comparison_json(const CurveComparison& c) {
  nlohmann::json j;
  j["n_compared"] = c.n_compared;
  j["compared_depth_range_mm"] = {c.compared_from_depth_m / kMm, c.compared_to_depth_m / kMm};
  j["reference_peak_force_N"] = c.reference_peak_force_N;
  j["force_rmse_N"] = c.force_rmse_N;
  j["force_rmse_relative"] = c.force_rmse_relative;
  nlohmann::json layers = nlohmann::json::array();
  for (const LayerMetrics& l : c.layers) {
    nlohmann::json lj{{"layer", l.layer},
                      {"pressed_samples", l.n_samples},
                      {"force_rmse_N", l.force_rmse_N},
                      {"force_rmse_relative", l.force_rmse_relative},
                      {"reference_punctured", l.reference_puncture.found},
                      {"model_punctured", l.model_puncture.found}};
    if (l.has_pressed_interval) lj["pressed_interval_mm"] = {l.pressed_from_depth_m / kMm, l.pressed_to_depth_m / kMm};
    if (l.reference_puncture.found)
      lj["reference_puncture"] = {{"depth_mm", l.reference_puncture.depth_m / kMm}, {"force_N", l.reference_puncture.force_N}};
    if (l.model_puncture.found)
      lj["model_puncture"] = {{"depth_mm", l.model_puncture.depth_m / kMm}, {"force_N", l.model_puncture.force_N}};
    if (l.reference_puncture.found && l.model_puncture.found) {
      lj["puncture_depth_error_mm"] = l.puncture_depth_error_m / kMm;
      lj["puncture_force_error_N"] = l.puncture_force_error_N;
    }
    layers.push_back(lj);
  }
  j["layers"] = layers;
  return j;
}

nlohmann::json parameters_json(const std::vector<LayerParameters>& ps) {
  nlohmann::json a = nlohmann::json::array();
  for (const LayerParameters& p : ps)
    a.push_back({{"layer", p.layer},
                 {"K_N_per_mm", p.virtual_stiffness_N_per_m * kMm},
                 {"damping_d_N_s_per_m2", p.damping_N_s_per_m2},
                 {"w", p.rings_w},
                 {"L_mm", p.spacing_L_m / kMm},
                 {"surface_stiffness_N_per_mm", p.surface_stiffness_N_per_m * kMm},
                 {"deformed_threshold_mm", p.deformed_threshold_m / kMm}});
  return a;
}

}  // namespace

std::string tuned_preset_provenance_json(const std::string& name, const CalibrationResult& result,
                                         const std::vector<ReferenceCurve>& references,
                                         const CalibrationOptions& options) {
  nlohmann::json j;
  j["preset"] = name;
  j["scene_file"] = name + ".json";
  nlohmann::json refs = nlohmann::json::array();
  for (std::size_t r = 0; r < references.size(); ++r) {
    const InsertionCurve& c = references[r].curve;
    const Scene s = objective_scene(result.tuned_scene, references[r], options, std::numeric_limits<double>::infinity());
    nlohmann::json rj{{"kind", references[r].kind},
                      {"source", c.source},
                      {"hash", c.content_hash.empty() ? nlohmann::json(nullptr) : nlohmann::json("fnv1a64:" + c.content_hash)},
                      {"samples", c.size()},
                      {"metadata", c.metadata},
                      {"rate_dependent", reference_is_rate_dependent(c)},
                      {"trajectory",
                       {{"start_height_mm", s.insertion.start_height_m / kMm},
                        {"speed_mm_per_s", s.insertion.speed_m_per_s / kMm},
                        {"target_depth_mm", s.insertion.target_depth_m / kMm},
                        {"compared", "insertion phase (velocity > 0)"}}}};
    if (r < result.before.size()) rj["metrics_before"] = comparison_json(result.before[r]);
    if (r < result.after.size()) rj["metrics_after"] = comparison_json(result.after[r]);
    refs.push_back(rj);
  }
  j["references"] = refs;
  j["calibrated_layers"] = result.calibrated_layers;
  j["parameters_before"] = parameters_json(result.initial);
  j["parameters_after"] = parameters_json(result.tuned);
  j["objective_before"] = result.objective_before;
  j["objective_after"] = result.objective_after;
  j["damping"] = {{"tuned", result.damping_tuned}, {"note", result.damping_note}};
  const TunedParameterSet& t = options.parameters;
  const CalibrationWeights& w = options.weights;
  nlohmann::json opt{{"method", to_string(options.method)},
                     {"sequential", "layers top to bottom, then d of all layers if tuned"},
                     {"tuned",
                      {{"K", t.virtual_stiffness},
                       {"deformed_threshold", t.deformed_threshold},
                       {"surface_stiffness", t.surface_stiffness},
                       {"L", t.spacing},
                       {"w", t.rings}}},
                     {"bound_factor", options.bound_factor},
                     {"rings_search_radius", options.rings_search_radius},
                     {"max_evaluations_per_stage", options.max_evaluations_per_stage},
                     {"log_x_tolerance", options.log_x_tolerance},
                     {"integrator", options.integrator},
                     {"objective_depth_step_mm", options.objective_depth_step_m / kMm},
                     {"depth_margin_mm", options.depth_margin_m / kMm},
                     {"weights",
                      {{"overall_rmse", w.overall_rmse},
                       {"layer_rmse", w.layer_rmse},
                       {"puncture_depth", w.puncture_depth},
                       {"puncture_force", w.puncture_force},
                       {"missing_puncture", w.missing_puncture}}},
                     {"evaluations", result.evaluations}};
  if (options.method == CalibrationMethod::SimulatedAnnealing) {
    const AnnealingSettings& a = options.annealing;
    opt["annealing"] = {{"iters_fixed_T", a.iters_fixed_T}, {"step_size", a.step_size}, {"t_initial", a.t_initial},
                        {"mu_t", a.mu_t},                   {"t_min", a.t_min},         {"seed", a.seed},
                        {"polish_locally", a.polish_locally}};
  }
  nlohmann::json stages = nlohmann::json::array();
  for (const CalibrationStageRecord& s : result.stages)
    stages.push_back({{"stage", s.stage},
                      {"evaluations", s.evaluations},
                      {"objective_start", s.objective_start},
                      {"objective_best", s.objective_best},
                      {"optimiser_result", s.nlopt_result}});
  opt["stages"] = stages;
  j["optimiser"] = opt;
  j["date_utc"] = io::utc_timestamp();
  j["project_version"] = io::program_version();
  j["git_revision"] = io::git_revision();
  j["machine"] = io::machine_summary();
  return j.dump(2) + "\n";
}

void write_tuned_preset(io::OutputSession& session, const std::string& name, const CalibrationResult& result,
                        const std::vector<ReferenceCurve>& references, const CalibrationOptions& options) {
  if (name.empty() || name.find('/') != std::string::npos)
    throw std::invalid_argument("write_tuned_preset: preset name must be a plain file stem (got '" + name + "')");
  Scene preset = result.tuned_scene;
  preset.name = name;
  preset.description = (preset.description.empty() ? std::string() : preset.description + " ") +
                       "Force-mesh parameters calibrated (see " + name + ".provenance.json).";
  const std::string text = scene_to_json_text(preset);
  parse_scene(text, name + ".json");  // the preset must load: fail before writing anything
  session.write_text(name + ".json", text);
  session.write_text(name + ".provenance.json", tuned_preset_provenance_json(name, result, references, options));
}

}  // namespace puncture::validation
