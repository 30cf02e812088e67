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
#include "puncture/stiffening.hpp"
#include "puncture/validation/pressing_polynomial.hpp"
#include "puncture/validation/reference_checks.hpp"

namespace puncture::validation {

namespace {
constexpr double kMm = 1e-3;
constexpr int kMaxParameters = 32;
}  // namespace

std::vector<LayerParameters> layer_parameters(const Scene& scene) {
  std::vector<LayerParameters> out;
  for (const Layer& l : scene.layers) {
    LayerParameters p;
    p.layer = l.name;
    p.virtual_stiffness_N_per_m = l.force_mesh.virtual_stiffness_N_per_m;
    p.damping_N_s_per_m2 = l.damping_N_s_per_m2;
    p.rings_w = l.force_mesh.rings_w;
    p.spacing_L_m = l.force_mesh.spacing_L_m;
    p.surface_stiffness_N_per_m = l.force_mesh.surface_stiffness_N_per_m;
    p.deformed_threshold_m = l.force_mesh.deformed_threshold_m;
    const BreakthroughCriterion& b = l.force_law.breakthrough;
    p.breakthrough = b.kind == BreakthroughCriterion::Kind::Rings           ? "rings"
                     : b.kind == BreakthroughCriterion::Kind::CriticalForce ? "critical_force"
                                                                            : "critical_energy";
    p.critical_force_N = b.critical_force_N;
    p.critical_energy_J = b.critical_energy_J;
    p.cutting_force_N = l.force_law.cutting_force_N;
    p.friction_dynamic_N_per_m = l.force_law.friction.dynamic_N_per_m;
    p.friction_static_N_per_m = l.force_law.friction.static_N_per_m;
    p.stiffening_quadratic_N_per_m2 = l.force_law.stiffening.quadratic_N_per_m2;
    p.stiffening_cubic_N_per_m3 = l.force_law.stiffening.cubic_N_per_m3;
    p.stiffening_exponential_N_per_m = l.force_law.stiffening.exponential_stiffness_N_per_m;
    out.push_back(p);
  }
  return out;
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
// Parameters: what is tuned, in which space, within which bounds

namespace {

enum class ParamKind {
  VirtualStiffness,
  DeformedThreshold,
  CriticalForce,
  CriticalEnergy,
  SurfaceStiffness,
  Spacing,
  Damping,
  Cutting,
  Friction,
  StiffeningQuadratic,
  StiffeningCubic,
  StiffeningExponential,
  Presliding
};

struct ParamInfo {
  const char* name;
  const char* unit;     ///< unit of the reported values
  double to_unit;       ///< SI value x to_unit = reported value
  bool log_space;       ///< scale parameter (> 0), optimised in log space
  double typical;       ///< SI; linear-space parameters are optimised as value / max(|p0|, typical)
};

ParamInfo info(ParamKind k) {
  switch (k) {
    case ParamKind::VirtualStiffness: return {"K", "N/mm", kMm, true, 0.0};
    case ParamKind::DeformedThreshold: return {"deformed_threshold", "mm", 1.0 / kMm, true, 0.0};
    case ParamKind::CriticalForce: return {"critical_force", "N", 1.0, true, 0.0};
    case ParamKind::CriticalEnergy: return {"critical_energy", "mJ", 1e3, true, 0.0};
    case ParamKind::SurfaceStiffness: return {"surface_stiffness", "N/mm", kMm, true, 0.0};
    case ParamKind::Spacing: return {"L", "mm", 1.0 / kMm, true, 0.0};
    case ParamKind::Damping: return {"d", "N s/m^2", 1.0, true, 0.0};
    case ParamKind::Cutting: return {"cutting_force", "N", 1.0, false, 0.1};
    case ParamKind::Friction: return {"friction_dynamic", "N/mm", kMm, false, 1.0};
    case ParamKind::StiffeningQuadratic: return {"stiffening_quadratic", "N/mm^2", kMm * kMm, false, 1e4};
    case ParamKind::StiffeningCubic: return {"stiffening_cubic", "N/mm^3", kMm * kMm * kMm, false, 1e6};
    case ParamKind::StiffeningExponential: return {"stiffening_exponential", "N/mm", kMm, false, 10.0};
    case ParamKind::Presliding: return {"friction_presliding", "mm", 1.0 / kMm, false, 1e-3};
  }
  throw std::logic_error("info");
}

double& param_ref(Scene& s, std::size_t layer, ParamKind k) {
  Layer& l = s.layers[layer];
  switch (k) {
    case ParamKind::VirtualStiffness: return l.force_mesh.virtual_stiffness_N_per_m;
    case ParamKind::DeformedThreshold: return l.force_mesh.deformed_threshold_m;
    case ParamKind::CriticalForce: return l.force_law.breakthrough.critical_force_N;
    case ParamKind::CriticalEnergy: return l.force_law.breakthrough.critical_energy_J;
    case ParamKind::SurfaceStiffness: return l.force_mesh.surface_stiffness_N_per_m;
    case ParamKind::Spacing: return l.force_mesh.spacing_L_m;
    case ParamKind::Damping: return l.damping_N_s_per_m2;
    case ParamKind::Cutting: return l.force_law.cutting_force_N;
    case ParamKind::Friction: return l.force_law.friction.dynamic_N_per_m;
    case ParamKind::StiffeningQuadratic: return l.force_law.stiffening.quadratic_N_per_m2;
    case ParamKind::StiffeningCubic: return l.force_law.stiffening.cubic_N_per_m3;
    case ParamKind::StiffeningExponential: return l.force_law.stiffening.exponential_stiffness_N_per_m;
    case ParamKind::Presliding: return l.force_law.friction.presliding_m;
  }
  throw std::logic_error("param_ref");
}
double param_value(const Scene& s, std::size_t layer, ParamKind k) { return param_ref(const_cast<Scene&>(s), layer, k); }

/// Physical range of a parameter (SI); see calibration.hpp.
void physical_range(const Scene& s, std::size_t layer, ParamKind k, double& lo, double& hi) {
  const Layer& l = s.layers[layer];
  switch (k) {
    case ParamKind::VirtualStiffness: lo = 1e-2, hi = 1e6; return;                 // 1e-5 .. 1000 N/mm
    case ParamKind::DeformedThreshold: lo = 1e-6, hi = l.thickness_m; return;      // 1 um .. the layer thickness
    case ParamKind::CriticalForce: lo = 1e-4, hi = 50.0; return;                   // measured punctures: 0.5 mN .. 19 N
    case ParamKind::CriticalEnergy: lo = 1e-9, hi = 1.0; return;                   // G_c w t: 1 J/m^2 x 1 mm^2 .. 1e5 J/m^2 x 1 cm^2
    case ParamKind::SurfaceStiffness: lo = 1e-3, hi = 1e6; return;
    case ParamKind::Spacing: {
      lo = 1e-5;
      hi = l.force_mesh.rings_w > 1 ? 0.5 * s.sample.diameter_m / (l.force_mesh.rings_w - 1) : 0.5 * s.sample.diameter_m;
      return;
    }
    case ParamKind::Damping: lo = 1e-3, hi = 1e6; return;
    case ParamKind::Cutting: lo = 0.0, hi = 20.0; return;                          // G_c w: up to 1.6e4 J/m^2 x 1.27 mm
    case ParamKind::Friction: lo = 0.0, hi = 1e3; return;                          // 0 .. 1 N per mm of shaft
    case ParamKind::StiffeningQuadratic: lo = 0.0, hi = 1e9; return;               // 0 .. 1000 N/mm^2
    case ParamKind::StiffeningCubic: lo = 0.0, hi = 1e12; return;                  // 0 .. 1000 N/mm^3
    case ParamKind::StiffeningExponential: lo = 0.0, hi = 1e6; return;
    case ParamKind::Presliding: lo = 0.0, hi = 0.05; return;                       // 0 .. 50 mm of shaft travel
  }
}

struct Parameter {
  std::size_t layer;
  ParamKind kind;
  bool log_space;
  double scale = 1.0;             ///< linear space: x = value / scale
  double lower = 0.0, upper = 0.0;        ///< bounds in x
  double value_lo = 0.0, value_hi = 0.0;  ///< bounds in SI
  double friction_ratio = 1.0;    ///< static / dynamic friction kept while tuning the dynamic one
  double x_of(double v) const { return log_space ? std::log(v) : v / scale; }
  double value_of(double x) const { return log_space ? std::exp(x) : x * scale; }
};

void set_param(Scene& s, const Parameter& p, double value) {
  param_ref(s, p.layer, p.kind) = value;
  if (p.kind == ParamKind::Friction) s.layers[p.layer].force_law.friction.static_N_per_m = value * p.friction_ratio;
}

/// Bounds of a parameter from its start value (the scene's); the start is
/// moved inside when it lies outside (moved = true).
Parameter make_parameter(const Scene& start, std::size_t layer, ParamKind kind, double bound_factor, bool& moved) {
  const ParamInfo in = info(kind);
  double p0 = param_value(start, layer, kind);
  double lo = 0.0, hi = 0.0;
  physical_range(start, layer, kind, lo, hi);
  Parameter p{layer, kind, in.log_space};
  if (in.log_space) {
    if (!(p0 > 0.0) || !std::isfinite(p0))
      throw std::invalid_argument(std::string("calibrate: layer '") + start.layers[layer].name + "': parameter " +
                                  in.name + " must be > 0 to be tuned");
    const double q0 = std::clamp(p0, lo, hi);
    lo = std::max(lo, q0 / bound_factor);
    hi = std::min(hi, q0 * bound_factor);
  } else {
    if (!std::isfinite(p0)) throw std::invalid_argument("calibrate: non-finite start value");
    p.scale = std::max(std::abs(p0), in.typical);
  }
  moved = p0 < lo || p0 > hi;
  p.value_lo = lo;
  p.value_hi = hi;
  p.lower = p.log_space ? std::log(lo) : lo / p.scale;
  p.upper = p.log_space ? std::log(hi) : hi / p.scale;
  if (kind == ParamKind::Friction) {
    const ShaftFrictionLaw& f = start.layers[layer].force_law.friction;
    p.friction_ratio = f.dynamic_N_per_m > 0.0 ? f.static_N_per_m / f.dynamic_N_per_m : 1.0;
  }
  return p;
}

/// The stage parameters of layer k the options and the scene's effects call for.
/// Why the references do not identify a parameter (reference_checks.hpp); "" when they do.
std::string unidentified_reason(const LayerIdentifiability& id, ParamKind kind) {
  const std::string fewer = "the reference has fewer than " + std::to_string(kMinIdentifyingSamples);
  switch (kind) {
    case ParamKind::CriticalForce: case ParamKind::CriticalEnergy:  // the puncture's depth and force set them
      return id.punctured ? "" : "the reference has no puncture of this layer";
    case ParamKind::DeformedThreshold:  // a ring deflection: read off the pressing curve
      return !id.punctured ? "the reference has no puncture of this layer"
             : id.pressing() ? "" : fewer + " pressing samples of this layer before its puncture";
    case ParamKind::Cutting: case ParamKind::Friction: case ParamKind::Presliding:
      return id.cut() ? "" : fewer + " samples of the cut through this layer";
    case ParamKind::Damping: return "";
    default: return id.pressing() ? "" : fewer + " pressing samples of this layer";
  }
}

/// With `id`: only the parameters the references identify.
std::vector<ParamKind> layer_kinds(const Scene& scene, std::size_t k, const TunedParameterSet& t,
                                   const LayerIdentifiability* id = nullptr) {
  std::vector<ParamKind> kinds;
  const Layer& l = scene.layers[k];
  if (t.virtual_stiffness && scene.effects.surface_force) kinds.push_back(ParamKind::VirtualStiffness);
  if (t.deformed_threshold && scene.effects.surface_force) {
    switch (l.force_law.breakthrough.kind) {
      case BreakthroughCriterion::Kind::Rings: kinds.push_back(ParamKind::DeformedThreshold); break;
      case BreakthroughCriterion::Kind::CriticalForce: kinds.push_back(ParamKind::CriticalForce); break;
      case BreakthroughCriterion::Kind::CriticalEnergy: kinds.push_back(ParamKind::CriticalEnergy); break;
    }
  }
  if (t.surface_stiffness && scene.effects.surface_force) kinds.push_back(ParamKind::SurfaceStiffness);
  if (t.spacing && scene.effects.surface_force) kinds.push_back(ParamKind::Spacing);
  if (t.stiffening && scene.effects.stiffening && scene.effects.surface_force) {
    if (l.force_law.stiffening.kind == StiffeningLaw::Kind::Polynomial) {
      // a2 and a3: a measured pre-puncture rise is often closer to z^3 than z^2
      // (the default FEM's skin: F(8 mm) / F(4 mm) = 9.3).
      kinds.push_back(ParamKind::StiffeningQuadratic);
      kinds.push_back(ParamKind::StiffeningCubic);
    } else {
      kinds.push_back(ParamKind::StiffeningExponential);
    }
  }
  if (t.cutting && scene.effects.cutting) kinds.push_back(ParamKind::Cutting);
  if (t.friction && scene.effects.friction) {
    kinds.push_back(ParamKind::Friction);
    // Presliding is tuned when the scene uses it (a start > 0): the
    // withdrawal's reversal over the shaft travel identifies it.
    if (l.force_law.friction.presliding_m > 0.0) kinds.push_back(ParamKind::Presliding);
  }
  if (id) kinds.erase(std::remove_if(kinds.begin(), kinds.end(), [&](ParamKind kind) {
    return !unidentified_reason(*id, kind).empty(); }), kinds.end());
  return kinds;
}

// ---------------------------------------------------------------------------
// The reference's trajectory and the model runs

/// Reference speed: metadata "speed_mm_per_s" if present, else the scene's.
double reference_speed(const Scene& scene, const InsertionCurve& ref) {
  double v = 0.0;
  if (ref.metadata_number("speed_mm_per_s", v)) {
    if (!(v > 0.0)) throw std::invalid_argument(ref.source + ": metadata speed_mm_per_s must be > 0");
    return v * kMm;
  }
  return scene.insertion.speed_m_per_s;
}

struct ReferenceTrajectory {
  double deepest_m = 0.0;
  double dwell_s = 0.0;            ///< 0 without dwell rows or time
  bool has_withdrawal = false;
  double withdrawal_speed_m_per_s = 0.0;
};

ReferenceTrajectory reference_trajectory(const Scene& scene, const InsertionCurve& ref) {
  ReferenceTrajectory t;
  for (std::size_t i : insertion_phase(ref)) t.deepest_m = std::max(t.deepest_m, ref.depth_m[i]);
  const std::vector<std::size_t> dwell = dwell_phase(ref);
  if (ref.has_time && dwell.size() >= 2) t.dwell_s = ref.time_s[dwell.back()] - ref.time_s[dwell.front()];
  const std::vector<std::size_t> out = withdrawal_phase(ref);
  t.has_withdrawal = out.size() >= 2;
  if (t.has_withdrawal) {
    double v = 0.0;
    if (ref.metadata_number("withdrawal_speed_mm_per_s", v) && v > 0.0) {
      t.withdrawal_speed_m_per_s = v * kMm;
    } else if (ref.has_velocity) {
      std::vector<double> speeds;
      for (std::size_t i : out)
        if (ref.velocity_m_per_s[i] < 0.0) speeds.push_back(-ref.velocity_m_per_s[i]);
      if (!speeds.empty()) {
        std::nth_element(speeds.begin(), speeds.begin() + static_cast<long>(speeds.size() / 2), speeds.end());
        t.withdrawal_speed_m_per_s = speeds[speeds.size() / 2];
      }
    }
    if (!(t.withdrawal_speed_m_per_s > 0.0)) t.withdrawal_speed_m_per_s = scene.insertion.withdrawal_speed_m_per_s;
  }
  return t;
}

/// The model run compared with one reference (see the header comment).
Scene objective_scene(const Scene& current, const ReferenceCurve& reference, const CalibrationOptions& o,
                      bool with_dwell) {
  const InsertionCurve& ref = reference.curve;
  const ReferenceTrajectory rt = reference_trajectory(current, ref);
  Scene s = current;
  // The model runs with every effect of the scene, the damping force d h v
  // included: what `puncture run` and the real-time app render is compared.
  // Against a quasi-static reference (the FEM) d is not identifiable apart
  // from the friction (both grow with the shaft length): d stays fixed and
  // the tuned friction carries the rest.
  s.realtime.integrator = o.integrator;
  s.effects.surface_output = false;
  s.insertion.speed_m_per_s = reference_speed(current, ref);
  s.insertion.target_depth_m = std::min(rt.deepest_m, 0.999 * s.total_thickness_m());
  if (!(s.insertion.target_depth_m > -s.insertion.start_height_m))
    throw std::invalid_argument(ref.source + ": the reference's deepest sample lies above the scene's start height");
  s.insertion.dwell_s = with_dwell ? rt.dwell_s : 0.0;
  s.insertion.withdrawal_speed_m_per_s = rt.has_withdrawal ? rt.withdrawal_speed_m_per_s
                                                           : std::max(0.2, 20.0 * s.insertion.speed_m_per_s);
  if (o.objective_depth_step_m > 0.0)
    s.realtime.haptic_rate_Hz = std::max(s.realtime.haptic_rate_Hz, s.insertion.speed_m_per_s / o.objective_depth_step_m);
  return s;
}

}  // namespace

Scene calibration_run_scene(const Scene& scene, const ReferenceCurve& reference, const CalibrationOptions& options) {
  return objective_scene(scene, reference, options, true);
}

// ---------------------------------------------------------------------------
// Stage objective

namespace {

struct StageContext {
  const std::vector<ReferenceCurve>* references = nullptr;
  const std::vector<ReferenceEvents>* events = nullptr;
  const std::vector<LayerGeometry>* geometry = nullptr;
  const CalibrationOptions* options = nullptr;
  const SurfaceCache* cache = nullptr;
  const CalibrationProgressCallback* progress = nullptr;
  Scene scene;                          ///< current values (the stage's parameters are overwritten per evaluation)
  std::vector<Parameter> parameters;
  std::vector<TermSelection> selection;  ///< per reference
  bool with_dwell = false;
  std::string name;
  int* total_evaluations = nullptr;
  int evaluations = 0;
  double best = std::numeric_limits<double>::infinity();
  std::vector<double> best_x;

  Scene scene_at(const double* x) const {
    Scene s = scene;
    for (std::size_t p = 0; p < parameters.size(); ++p) set_param(s, parameters[p], parameters[p].value_of(x[p]));
    return s;
  }

  double objective_of(const Scene& s) const {
    double total = 0.0;
    for (std::size_t r = 0; r < references->size(); ++r) {
      const InsertionCurve model =
          simulate_insertion_curve(objective_scene(s, (*references)[r], *options, with_dwell), cache);
      total += compare_trajectory(model, (*references)[r].curve, (*events)[r], *geometry, options->weights, selection[r])
                   .objective;
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

/// One local derivative-free minimisation; returns NLopt's code name.
std::string run_nlopt_once(StageContext& ctx, nlopt::algorithm algorithm, std::vector<double> x, int max_evaluations) {
  const unsigned n = static_cast<unsigned>(ctx.parameters.size());
  // NLopt's BOBYQA needs at least two variables; one variable goes to Nelder-Mead.
  if (n < 2 && algorithm == nlopt::LN_BOBYQA) algorithm = nlopt::LN_NELDERMEAD;
  nlopt::opt opt(algorithm, n);
  std::vector<double> lo(n), hi(n), step(n);
  for (unsigned p = 0; p < n; ++p) {
    lo[p] = ctx.parameters[p].lower, hi[p] = ctx.parameters[p].upper;
    x[p] = std::clamp(x[p], lo[p], hi[p]);
    step[p] = std::min(0.2, 0.25 * (hi[p] - lo[p]));
    if (!(step[p] > 0.0)) step[p] = 1e-6;
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
/// (K against the breakthrough parameter) and small steps where a
/// breakthrough moves by one tick, on which BOBYQA's trust region can
/// collapse early. While a run improves the best objective by more than 1 %
/// and evaluations remain, a new run starts from the best point with fresh
/// initial steps.
std::string run_nlopt(StageContext& ctx, nlopt::algorithm algorithm, const std::vector<double>& x0) {
  const int budget = std::max(ctx.options->max_evaluations_per_stage,
                              ctx.options->evaluations_per_parameter * static_cast<int>(ctx.parameters.size()));
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
    s->x[p] = std::clamp(s->x[p] + u * step_size, par.lower, par.upper);
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

std::vector<double> x_values(const Scene& s, const std::vector<Parameter>& params) {
  std::vector<double> x;
  for (const Parameter& p : params) x.push_back(std::clamp(p.x_of(param_value(s, p.layer, p.kind)), p.lower, p.upper));
  return x;
}

void clamp_into_bounds(Scene& s, const std::vector<Parameter>& params) {
  for (const Parameter& p : params)
    set_param(s, p, std::clamp(param_value(s, p.layer, p.kind), p.value_lo, p.value_hi));
}

// ---------------------------------------------------------------------------
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

/// Scaled start of a layer's stage (up to eight passes), against the first
/// reference: K (and k_s when tuned, keeping K / k_s and so the ring
/// profile) scaled by the ratio of the reference's pressing slope to the
/// model's; the breakthrough parameter scaled to the reference's puncture
/// (threshold by the ratio of the breakthrough deflections, critical force
/// set to the reference's puncture force minus the model's friction and
/// cutting there, critical energy by the squared deflection ratio); then
/// cutting and friction from a least-squares fit of the force difference on
/// the layer's cut (level and slope with the shaft length) and, with a
/// withdrawal, of the withdrawal force inside the layer (friction only).
/// Values stay inside the bounds.
Scene scaled_start(const Scene& candidate, std::size_t k, const ReferenceCurve& reference, const ReferenceEvents& ref_ev,
                   const std::vector<LayerGeometry>& layers, const CalibrationOptions& options, const SurfaceCache& cache,
                   const std::vector<Parameter>& parameters) {
  auto tuned = [&](ParamKind kind) {
    for (const Parameter& p : parameters)
      if (p.kind == kind && p.layer == k) return true;
    return false;
  };
  Scene s = candidate;
  // Polynomial stiffening tuned: the reference's rise through the layer as a
  // non-negative cubic s z + a2 z^2 + a3 z^3 (pressing_polynomial.hpp) gives
  // a2 and a3, and its linear part s is the slope K is scaled to (the
  // secant slope would fold the stiffening into K).
  bool have_fit = false;
  double linear_slope = 0.0;
  if (tuned(ParamKind::StiffeningQuadratic) && tuned(ParamKind::StiffeningCubic) && ref_ev.punctures[k].found) {
    const std::vector<LayerSegments> seg = layer_segments(ref_ev, layers);
    if (seg[k].has_pressing) {
      std::vector<double> z, f;
      double f0 = 0.0;
      bool have_f0 = false;
      for (std::size_t i : insertion_phase(reference.curve)) {
        const double d = reference.curve.depth_m[i];
        if (d < seg[k].pressing_from_m || d > ref_ev.punctures[k].depth_m) continue;
        if (!have_f0) f0 = reference.curve.force_N[i], have_f0 = true;
        z.push_back(d - seg[k].pressing_from_m);
        f.push_back(reference.curve.force_N[i] - f0);
      }
      if (z.size() >= 4 && z.back() > 0.0 && f.back() > 0.0) {
        const PressingPolynomial fit = fit_pressing_polynomial(z, f);
        param_ref(s, k, ParamKind::StiffeningQuadratic) = fit.quadratic_N_per_m2;
        param_ref(s, k, ParamKind::StiffeningCubic) = fit.cubic_N_per_m3;
        // A floor of 5 % of the secant keeps K (a log-space parameter) finite
        // when the rise is a pure power law.
        linear_slope = std::max(fit.linear_N_per_m, 0.05 * f.back() / z.back());
        have_fit = true;
      }
    }
  }
  for (int pass = 0; pass < 8; ++pass) {
    InsertionCurve model;
    try {
      model = simulate_insertion_curve(objective_scene(s, reference, options, false), &cache);
    } catch (const std::exception&) {
      return candidate;
    }
    const ReferenceEvents mod_ev = reference_events(model, layers);  // its own states
    double z_ref = 0.0, f_ref = 0.0, z_model = 0.0, f_model = 0.0;
    const bool ref_rise = pressing_rise(reference.curve, ref_ev, layers, k, z_ref, f_ref);
    const bool model_rise = pressing_rise(model, mod_ev, layers, k, z_model, f_model);
    if (ref_rise && model_rise) {
      double stiffness_ratio = (f_ref / z_ref) / (f_model / z_model);
      if (have_fit) {
        const double model_linear =
            (f_model - stiffening_force_N(s.layers[k].force_law.stiffening, z_model)) / z_model;
        if (model_linear > 0.0) stiffness_ratio = linear_slope / model_linear;
      }
      // Converged: slope and breakthrough deflection within 0.1 % (the
      // fixed point of these updates; K and the threshold interact through
      // the ring profile, hence several passes).
      if (pass >= 2 && std::abs(stiffness_ratio - 1.0) < 1e-3 && std::abs(z_ref / z_model - 1.0) < 1e-3) break;
      if (tuned(ParamKind::VirtualStiffness)) param_ref(s, k, ParamKind::VirtualStiffness) *= stiffness_ratio;
      if (tuned(ParamKind::SurfaceStiffness)) param_ref(s, k, ParamKind::SurfaceStiffness) *= stiffness_ratio;
      if (tuned(ParamKind::DeformedThreshold)) param_ref(s, k, ParamKind::DeformedThreshold) *= z_ref / z_model;
      if (tuned(ParamKind::CriticalEnergy)) param_ref(s, k, ParamKind::CriticalEnergy) *= (z_ref / z_model) * (z_ref / z_model) * stiffness_ratio;
    }
    if (tuned(ParamKind::CriticalForce) && ref_ev.punctures[k].found && model.has_parts()) {
      // The tip's share of the reference's puncture force: minus the model's friction and cutting there.
      double other = 0.0;
      std::vector<double> x, y;
      for (std::size_t i : insertion_phase(model)) {
        if (!x.empty() && model.depth_m[i] <= x.back()) continue;
        x.push_back(model.depth_m[i]);
        y.push_back(model.force_N[i] - model.tip_force_N[i]);
      }
      interpolate_linear(x, y, ref_ev.punctures[k].depth_m, other);
      const double want = ref_ev.punctures[k].force_N - other;
      if (want > 0.0) param_ref(s, k, ParamKind::CriticalForce) = want;
    }
    if ((tuned(ParamKind::Cutting) || tuned(ParamKind::Friction))) {
      // Least squares of r = ref - model: on the cut, r = dC + dF h; on the
      // withdrawal inside the layer, r = -dF h (h: shaft length in the layer).
      const std::vector<LayerSegments> seg = layer_segments(ref_ev, layers);
      std::vector<double> mx, my, wx, wy;
      for (std::size_t i : insertion_phase(model)) {
        if (!mx.empty() && model.depth_m[i] <= mx.back()) continue;
        mx.push_back(model.depth_m[i]);
        my.push_back(model.force_N[i]);
      }
      std::vector<std::size_t> out = withdrawal_phase(model);
      std::reverse(out.begin(), out.end());
      for (std::size_t i : out) {
        if (!wx.empty() && model.depth_m[i] <= wx.back()) continue;
        wx.push_back(model.depth_m[i]);
        wy.push_back(model.force_N[i]);
      }
      double a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0;
      const double top = layers[k].top_depth_m, t = layers[k].thickness_m;
      auto add_row = [&](double c, double h, double r) {
        a11 += c * c, a12 += c * h, a22 += h * h, b1 += c * r, b2 += h * r;
      };
      if (seg[k].has_after)
        for (std::size_t i : insertion_phase(reference.curve)) {
          const double d = reference.curve.depth_m[i];
          if (d <= seg[k].after_from_m || d >= seg[k].after_to_m) continue;
          double f = 0.0;
          if (interpolate_linear(mx, my, d, f)) add_row(1.0, shaft_length_in_layer_m(d, top, t), reference.curve.force_N[i] - f);
        }
      const double withdrawal_limit = seg[k].has_after ? seg[k].after_to_m - 0.5e-3 : -1.0;
      for (std::size_t i : withdrawal_phase(reference.curve)) {
        const double d = reference.curve.depth_m[i];
        if (d <= top || d > std::min(top + t, withdrawal_limit)) continue;
        double f = 0.0;
        if (interpolate_linear(wx, wy, d, f)) add_row(0.0, -shaft_length_in_layer_m(d, top, t), reference.curve.force_N[i] - f);
      }
      double dC = 0.0, dF = 0.0;
      const bool cut = tuned(ParamKind::Cutting), fric = tuned(ParamKind::Friction);
      const double det = a11 * a22 - a12 * a12;
      if (cut && fric && det > 1e-12 * (a11 * a22) && a11 > 0.0) {
        dC = (a22 * b1 - a12 * b2) / det;
        dF = (a11 * b2 - a12 * b1) / det;
      } else if (cut && a11 > 0.0) {
        dC = b1 / a11;
      } else if (fric && a22 > 0.0) {
        dF = b2 / a22;
      }
      if (cut) param_ref(s, k, ParamKind::Cutting) = std::max(0.0, param_value(s, k, ParamKind::Cutting) + dC);
      if (fric) {
        const double f = std::max(0.0, param_value(s, k, ParamKind::Friction) + dF);
        for (const Parameter& p : parameters)
          if (p.kind == ParamKind::Friction && p.layer == k) set_param(s, p, f);
      }
    }
    clamp_into_bounds(s, parameters);
  }
  return s;
}

std::string bound_name(const Parameter& p, double x) {
  const double span = p.upper - p.lower;
  if (!(span > 0.0)) return "lower";
  // Within 0.1 % of the span, but never farther than 0.1 % of the value's own
  // size: a linear-space parameter with a wide physical range (stiffening
  // 0..1000 N/mm^3) is not "at its bound" at 0.004 N/mm^3.
  const double tol = 1e-3 * std::min(span, std::max(1.0, std::abs(x)));
  if (x <= p.lower + tol) return "lower";
  if (x >= p.upper - tol) return "upper";
  return "";
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
  const std::vector<LayerGeometry> geometry = layer_geometry(scene);
  for (std::size_t r = 0; r < references.size(); ++r) {
    result.reference_events.push_back(reference_events(references[r].curve, geometry,
                                                       r == 0 ? options.puncture_depths_m : std::vector<double>{},
                                                       options.detection));
    result.warnings.push_back(references[r].curve.source + ": " + result.reference_events.back().note);
    check_reference_fittable(references[r].curve, result.reference_events.back(),
                             r == 0 && !options.puncture_depths_m.empty(), options.detection);
  }
  // What the references identify (reference_checks.hpp); the rest keeps its start values.
  std::vector<LayerIdentifiability> ident(geometry.size());
  for (std::size_t r = 0; r < references.size(); ++r) {
    const auto more = layer_identifiability(references[r].curve, result.reference_events[r], geometry);
    for (std::size_t k = 0; k < ident.size(); ++k) {  // any reference counts
      ident[k].pressing_samples = std::max(ident[k].pressing_samples, more[k].pressing_samples);
      ident[k].cut_samples = std::max(ident[k].cut_samples, more[k].cut_samples);
      ident[k].punctured = ident[k].punctured || more[k].punctured;
    }
  }
  std::size_t n_tuned = 0, n_requested = 0;
  for (std::size_t k : layers) {
    const std::vector<ParamKind> requested = layer_kinds(scene, k, options.parameters);
    n_requested += requested.size();
    for (ParamKind kind : requested) {
      const std::string why = unidentified_reason(ident[k], kind);
      if (why.empty()) {
        ++n_tuned;
        continue;
      }
      result.warnings.push_back("layer " + scene.layers[k].name + ": " + info(kind).name + " kept at its start value (" +
                                std::to_string(param_value(scene, k, kind) * info(kind).to_unit) + " " +
                                info(kind).unit + "): " + why);
    }
  }

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
  if (result.damping_tuned && !scene.effects.damping) {
    result.damping_tuned = false;
    result.damping_note = "d kept fixed: the scene's damping effect is off";
  }
  check_enough_samples(references.front().curve, result.reference_events.front(),
                       n_tuned + (result.damping_tuned ? layers.size() : 0), n_requested);

  const SurfaceCache cache(scene);
  int total_evaluations = 0;
  Scene current = scene;
  // Bounds are fixed once, from the scene's values.
  std::vector<Parameter> all_parameters;
  std::vector<bool> moved_inside;

  auto make_context = [&](const std::string& name) {
    StageContext ctx;
    ctx.references = &references;
    ctx.events = &result.reference_events;
    ctx.geometry = &geometry;
    ctx.options = &options;
    ctx.cache = &cache;
    ctx.progress = &progress;
    ctx.total_evaluations = &total_evaluations;
    ctx.name = name;
    return ctx;
  };
  auto parameter_for = [&](const Scene& start, std::size_t k, ParamKind kind) {
    for (std::size_t i = 0; i < all_parameters.size(); ++i)
      if (all_parameters[i].layer == k && all_parameters[i].kind == kind) return all_parameters[i];
    bool moved = false;
    Parameter p = make_parameter(start, k, kind, options.bound_factor, moved);
    all_parameters.push_back(p);
    moved_inside.push_back(moved);
    return p;
  };

  // --- per-layer stages, top to bottom (again, for layers in series) ---
  const int passes = options.passes > 0 ? options.passes
                                        : (scene.effects.layer_interaction && layers.size() > 1 ? 2 : 1);
  for (int pass = 0; pass < passes; ++pass)
  for (std::size_t k : layers) {
    const std::string& lname = scene.layers[k].name;
    const bool first_pass = pass == 0;
    std::vector<TermSelection> selection;
    for (std::size_t r = 0; r < references.size(); ++r) {
      const ReferenceEvents& ev = result.reference_events[r];
      const LayerSegments seg = layer_segments(ev, geometry)[k];
      TermSelection sel;
      // The layer's own terms and those of the calibrated layers above it
      // (in series, layer k's stiffness changes their pressing too).
      for (std::size_t j : layers)
        if (j <= k) sel.layers.push_back(j);
      sel.whole_curve_terms = false;
      sel.dwell = false;
      double end = std::numeric_limits<double>::infinity();
      if (seg.has_after) end = seg.after_to_m;
      else if (ev.punctures[k].found) end = ev.punctures[k].depth_m + options.depth_margin_m;
      else if (seg.has_pressing) end = seg.pressing_to_m;
      sel.max_depth_m = end;
      // Withdrawal inside the layers down to this one (no friction of the
      // layers below), above the end of the cut and clear of the model's own
      // turning point.
      sel.withdrawal_max_depth_m = std::min(end - 0.5e-3, geometry[k].top_depth_m + geometry[k].thickness_m);
      selection.push_back(sel);
    }
    const std::vector<ParamKind> kinds = layer_kinds(current, k, options.parameters, &ident[k]);
    std::vector<int> ring_candidates{current.layers[k].force_mesh.rings_w};
    if (options.parameters.rings && first_pass)
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
      StageContext ctx = make_context(lname + " (w = " + std::to_string(w) + ")" +
                                      (passes > 1 ? ", pass " + std::to_string(pass + 1) : std::string()));
      ctx.scene = candidate;
      ctx.selection = selection;
      for (ParamKind kind : kinds) ctx.parameters.push_back(parameter_for(scene, k, kind));
      if (ctx.parameters.size() > static_cast<std::size_t>(kMaxParameters))
        throw std::invalid_argument("calibrate: too many parameters in one stage");
      CalibrationStageRecord rec;
      rec.stage = ctx.name;
      // The objective at the scene's own values: the "before" of the first
      // candidate, and the stage's start unless the start is scaled.
      double at_scene_values = kFailedObjective;
      if (!have_start || !options.scaled_start) at_scene_values = ctx.evaluate(x_values(candidate, ctx.parameters).data());
      if (!have_start) {
        result.objective_before += at_scene_values;
        have_start = true;
      }
      clamp_into_bounds(candidate, ctx.parameters);
      if (options.scaled_start && first_pass)
        candidate = scaled_start(candidate, k, references.front(), result.reference_events.front(), geometry, options,
                                 cache, ctx.parameters);
      ctx.scene = candidate;
      const std::vector<double> x0 = x_values(candidate, ctx.parameters);
      rec.objective_start = ctx.evaluate(x0.data());
      if (ctx.parameters.empty()) {
        rec.nlopt_result = "nothing to tune";
      } else {
        // The pressing and breakthrough parameters first with the cutting and
        // friction where the scaled start put them, then these with the
        // former fixed, then all together: each step low-dimensional, where
        // Nelder-Mead converges (cutting and friction are small forces next
        // to the puncture peak, nearly flat directions of the whole problem).
        std::vector<Parameter> shape, level;
        for (const Parameter& p : ctx.parameters)
          (p.kind == ParamKind::Cutting || p.kind == ParamKind::Friction ? level : shape).push_back(p);
        if (!shape.empty() && !level.empty()) {
          for (const std::vector<Parameter>* subset : {&shape, &level}) {
            StageContext sub = make_context(ctx.name);
            sub.scene = ctx.best_x.empty() ? ctx.scene : ctx.scene_at(ctx.best_x.data());
            sub.selection = ctx.selection;
            sub.parameters = *subset;
            const std::vector<double> xs = x_values(sub.scene, sub.parameters);
            rec.nlopt_result += (rec.nlopt_result.empty() ? "" : "; ") + run_stage(sub, xs);
            ctx.evaluations += sub.evaluations;
            if (sub.best < ctx.best) {
              const Scene better = sub.scene_at(sub.best_x.data());
              ctx.best = sub.best;
              ctx.best_x = x_values(better, ctx.parameters);
            }
          }
          rec.nlopt_result += "; all: ";
        }
        rec.nlopt_result += run_stage(ctx, ctx.best_x.empty() ? x0 : ctx.best_x);
      }
      rec.objective_best = ctx.best;
      rec.evaluations = ctx.evaluations;
      result.stages.push_back(rec);
      if (ctx.best < stage_best) {
        stage_best = ctx.best;
        stage_best_scene = ctx.best_x.empty() ? candidate : ctx.scene_at(ctx.best_x.data());
      }
    }
    current = stage_best_scene;
  }

  std::vector<TermSelection> whole(references.size());
  // --- damping stage: d of every calibrated layer on the whole trajectory ---
  if (result.damping_tuned) {
    StageContext ctx = make_context("damping");
    ctx.scene = current;
    ctx.selection = whole;
    ctx.with_dwell = true;
    for (std::size_t k : layers) ctx.parameters.push_back(parameter_for(scene, k, ParamKind::Damping));
    const std::vector<double> x0 = x_values(current, ctx.parameters);
    CalibrationStageRecord rec;
    rec.stage = ctx.name;
    rec.objective_start = ctx.evaluate(x0.data());
    rec.nlopt_result = run_stage(ctx, x0);
    rec.objective_best = ctx.best;
    rec.evaluations = ctx.evaluations;
    result.stages.push_back(rec);
    current = ctx.scene_at(ctx.best_x.data());
  }

  // --- joint stage: every tuned parameter on the whole objective ---
  {
    StageContext ctx = make_context("joint");
    ctx.scene = current;
    ctx.selection = whole;
    ctx.with_dwell = true;
    for (const Parameter& p : all_parameters)
      if (std::find(layers.begin(), layers.end(), p.layer) != layers.end()) ctx.parameters.push_back(p);
    const std::vector<double> x0 = x_values(current, ctx.parameters);
    const double at_start = ctx.evaluate(x0.data());
    CalibrationStageRecord rec;
    rec.stage = ctx.name;
    rec.objective_start = at_start;
    const bool worth_it = options.joint_polish && ctx.parameters.size() > 1 && ctx.parameters.size() <= kMaxParameters &&
                          (layers.size() > 1 || result.damping_tuned);
    rec.nlopt_result = worth_it ? run_stage(ctx, x0) : "not run (one layer, or joint_polish off)";
    rec.objective_best = ctx.best;
    rec.evaluations = ctx.evaluations;
    result.stages.push_back(rec);
    if (worth_it && ctx.best < at_start) current = ctx.scene_at(ctx.best_x.data());
    result.objective_after = ctx.best;
  }

  result.tuned_scene = current;
  result.tuned = layer_parameters(current);
  result.evaluations = total_evaluations;
  // Before: the whole objective at the scene's own values (the stages' "before" sum is per stage).
  {
    StageContext ctx = make_context("before");
    ctx.scene = scene;
    ctx.selection = whole;
    ctx.with_dwell = true;
    try {
      result.objective_before = ctx.objective_of(scene);
    } catch (const std::exception&) {
      result.objective_before = kFailedObjective;
    }
  }
  for (std::size_t r = 0; r < references.size(); ++r) {
    const ReferenceCurve& ref = references[r];
    result.model_before.push_back(simulate_insertion_curve(objective_scene(scene, ref, options, true), &cache));
    result.model_after.push_back(simulate_insertion_curve(objective_scene(current, ref, options, true), &cache));
    result.before.push_back(compare_curves(result.model_before.back(), ref.curve));
    result.after.push_back(compare_curves(result.model_after.back(), ref.curve));
    result.trajectory_before.push_back(compare_trajectory(result.model_before.back(), ref.curve,
                                                          result.reference_events[r], geometry, options.weights));
    result.trajectory_after.push_back(compare_trajectory(result.model_after.back(), ref.curve,
                                                         result.reference_events[r], geometry, options.weights));
    for (const std::string& w : result.trajectory_after.back().warnings) result.warnings.push_back(ref.curve.source + ": " + w);
  }
  for (std::size_t i = 0; i < all_parameters.size(); ++i) {
    const Parameter& p = all_parameters[i];
    if (std::find(layers.begin(), layers.end(), p.layer) == layers.end() &&
        p.kind != ParamKind::Damping)
      continue;
    const ParamInfo in = info(p.kind);
    TunedParameterRecord rec;
    rec.layer = scene.layers[p.layer].name;
    rec.name = in.name;
    rec.unit = in.unit;
    rec.start = param_value(scene, p.layer, p.kind) * in.to_unit;
    rec.tuned = param_value(current, p.layer, p.kind) * in.to_unit;
    rec.lower = p.value_lo * in.to_unit;
    rec.upper = p.value_hi * in.to_unit;
    rec.at_bound = bound_name(p, p.x_of(std::max(param_value(current, p.layer, p.kind), p.log_space ? 1e-300 : 0.0)));
    rec.start_moved_inside = moved_inside[i];
    if (rec.start_moved_inside)
      result.warnings.push_back("layer " + rec.layer + ": " + rec.name + " started outside its physical bounds (" +
                                std::to_string(rec.start) + " " + rec.unit + "), moved inside");
    if (!rec.at_bound.empty())
      result.warnings.push_back("layer " + rec.layer + ": " + rec.name + " ended at its " + rec.at_bound + " bound (" +
                                std::to_string(rec.tuned) + " " + rec.unit + ")");
    result.parameters.push_back(rec);
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
                 {"deformed_threshold_mm", p.deformed_threshold_m / kMm},
                 {"breakthrough", p.breakthrough},
                 {"critical_force_N", p.critical_force_N},
                 {"critical_energy_mJ", p.critical_energy_J * 1e3},
                 {"cutting_force_N", p.cutting_force_N},
                 {"friction_dynamic_N_per_mm", p.friction_dynamic_N_per_m * kMm},
                 {"friction_static_N_per_mm", p.friction_static_N_per_m * kMm},
                 {"stiffening_quadratic_N_per_mm2", p.stiffening_quadratic_N_per_m2 * kMm * kMm},
                 {"stiffening_cubic_N_per_mm3", p.stiffening_cubic_N_per_m3 * kMm * kMm * kMm},
                 {"stiffening_exponential_N_per_mm", p.stiffening_exponential_N_per_m * kMm}});
  return a;
}

/// Every term; an unavailable one has value null ("n/a") and its reason.
nlohmann::json terms_json(const TrajectoryComparison& c) {
  nlohmann::json j;
  j["objective"] = c.objective;
  j["reference_peak_force_N"] = c.reference_peak_force_N;
  nlohmann::json terms = nlohmann::json::array();
  for (const ObjectiveTerm& t : c.terms) {
    nlohmann::json tj{{"term", t.name}, {"weight", t.weight}, {"samples", t.samples}, {"note", t.note}};
    if (!t.layer.empty()) tj["layer"] = t.layer;
    tj["value"] = t.available ? nlohmann::json(t.value) : nlohmann::json(nullptr);
    tj["contribution"] = t.available ? nlohmann::json(t.contribution()) : nlohmann::json(nullptr);
    const bool depth = t.name == "puncture_depth";
    tj[depth ? "error_mm" : "error_N"] = t.available ? nlohmann::json(depth ? t.raw / kMm : t.raw) : nlohmann::json(nullptr);
    terms.push_back(tj);
  }
  j["terms"] = terms;
  j["warnings"] = c.warnings;
  return j;
}

nlohmann::json events_json(const ReferenceEvents& ev, const std::vector<std::string>& names) {
  nlohmann::json j{{"source", to_string(ev.source)}, {"note", ev.note}};
  nlohmann::json p = nlohmann::json::array();
  for (std::size_t k = 0; k < ev.punctures.size() && k < names.size(); ++k) {
    nlohmann::json e{{"layer", names[k]}, {"found", ev.punctures[k].found}};
    if (ev.punctures[k].found) e["depth_mm"] = ev.punctures[k].depth_m / kMm, e["force_N"] = ev.punctures[k].force_N;
    p.push_back(e);
  }
  j["punctures"] = p;
  nlohmann::json drops = nlohmann::json::array();
  for (const ForceDrop& d : ev.drops) drops.push_back({{"depth_mm", d.depth_m / kMm}, {"peak_force_N", d.peak_force_N}, {"drop_N", d.drop_N}});
  j["force_drops"] = drops;
  return j;
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
    const Scene s = objective_scene(result.tuned_scene, references[r], options, true);
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
                        {"dwell_s", s.insertion.dwell_s},
                        {"withdrawal_speed_mm_per_s", s.insertion.withdrawal_speed_m_per_s / kMm},
                        {"compared", "insertion, dwell and withdrawal, term by term (objective_terms_*)"}}}};
    if (r < result.before.size()) rj["metrics_before"] = comparison_json(result.before[r]);
    if (r < result.after.size()) rj["metrics_after"] = comparison_json(result.after[r]);
    if (r < result.trajectory_before.size()) rj["objective_terms_before"] = terms_json(result.trajectory_before[r]);
    if (r < result.trajectory_after.size()) rj["objective_terms_after"] = terms_json(result.trajectory_after[r]);
    std::vector<std::string> names;
    for (const Layer& l : result.tuned_scene.layers) names.push_back(l.name);
    if (r < result.reference_events.size()) rj["reference_punctures"] = events_json(result.reference_events[r], names);
    refs.push_back(rj);
  }
  j["references"] = refs;
  j["calibrated_layers"] = result.calibrated_layers;
  j["parameters_before"] = parameters_json(result.initial);
  j["parameters_after"] = parameters_json(result.tuned);
  j["objective_before"] = result.objective_before;
  j["objective_after"] = result.objective_after;
  j["damping"] = {{"tuned", result.damping_tuned}, {"note", result.damping_note}};
  nlohmann::json tuned = nlohmann::json::array();
  for (const TunedParameterRecord& p : result.parameters)
    tuned.push_back({{"layer", p.layer},
                     {"parameter", p.name},
                     {"unit", p.unit},
                     {"start", p.start},
                     {"tuned", p.tuned},
                     {"bounds", {p.lower, p.upper}},
                     {"at_bound", p.at_bound.empty() ? nlohmann::json(nullptr) : nlohmann::json(p.at_bound)},
                     {"start_moved_inside_bounds", p.start_moved_inside}});
  j["tuned_parameters"] = tuned;
  j["warnings"] = result.warnings;
  const TunedParameterSet& t = options.parameters;
  const CalibrationWeights& w = options.weights;
  nlohmann::json opt{{"method", to_string(options.method)},
                     {"sequential", "layers top to bottom, then d of all layers if tuned"},
                     {"tuned",
                      {{"K", t.virtual_stiffness},
                       {"breakthrough_parameter", t.deformed_threshold},
                       {"cutting", t.cutting},
                       {"friction", t.friction},
                       {"stiffening", t.stiffening},
                       {"surface_stiffness", t.surface_stiffness},
                       {"L", t.spacing},
                       {"w", t.rings}}},
                     {"joint_polish", options.joint_polish},
                     {"passes", options.passes},
                     {"puncture_depths_mm", [&] {
                        nlohmann::json d = nlohmann::json::array();
                        for (double x : options.puncture_depths_m) d.push_back(x / kMm);
                        return d;
                      }()},
                     {"bound_factor", options.bound_factor},
                     {"rings_search_radius", options.rings_search_radius},
                     {"max_evaluations_per_stage", options.max_evaluations_per_stage},
                     {"evaluations_per_parameter", options.evaluations_per_parameter},
                     {"log_x_tolerance", options.log_x_tolerance},
                     {"integrator", options.integrator},
                     {"objective_depth_step_mm", options.objective_depth_step_m / kMm},
                     {"depth_margin_mm", options.depth_margin_m / kMm},
                     {"weights",
                      {{"overall_rmse", w.overall_rmse},
                       {"pressing", w.pressing},
                       {"after_puncture", w.after_puncture},
                       {"puncture_depth", w.puncture_depth},
                       {"puncture_force", w.puncture_force},
                       {"missing_puncture", w.missing_puncture},
                       {"withdrawal", w.withdrawal},
                       {"dwell", w.dwell},
                       {"parts", w.parts}}},
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
