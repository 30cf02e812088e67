// mass_spring_identification.cpp: simulated annealing (GSL) and ISRES (NLopt)
// on the mass-spring layer stiffness factors; see mass_spring_identification.hpp.
#include "puncture/validation/mass_spring_identification.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <gsl/gsl_rng.h>
#include <gsl/gsl_siman.h>
#include <nlopt.hpp>

#include "puncture/comparison/internal_forces.hpp"
#include "puncture/comparison/volumetric_model.hpp"

namespace puncture::validation {

namespace {

/// The quasi-static mass-spring curve of the insertion, sampled every step_m.
ModelRun quasi_static_run(const Scene& scene, std::shared_ptr<const meshing::TetMesh> mesh,
                          const std::vector<double>& scale, double deepest_m, double step_m) {
  comparison::VolumetricSettings settings = comparison::volumetric_settings(scene);
  settings.quasi_static = true;
  comparison::VolumetricNeedleModel model(
      scene, mesh, std::make_unique<comparison::MassSpringLaw>(*mesh, comparison::layer_elasticity(scene), scale,
                                                 comparison::parse_spring_kind(scene.comparison.mass_spring_springs)),
      settings, "mass-spring, quasi-static");
  ModelRun run;
  run.model = "msm";
  const double speed = scene.insertion.speed_m_per_s > 0.0 ? scene.insertion.speed_m_per_s : 0.01;
  const int n = static_cast<int>(std::ceil((deepest_m + scene.insertion.start_height_m) / step_m)) + 1;
  for (int i = 0; i <= n; ++i) {
    const double depth = std::min(deepest_m, -scene.insertion.start_height_m + i * step_m);
    NeedleState needle;
    needle.tip_position_m = Eigen::Vector3d(0.0, 0.0, -depth);
    needle.axial_velocity_m_per_s = speed;
    needle.time_s = (depth + scene.insertion.start_height_m) / speed;
    const double force = model.step(needle);
    run.time_s.push_back(needle.time_s);
    run.depth_m.push_back(depth);
    run.velocity_m_per_s.push_back(speed);
    run.contact_force_N.push_back(force);
    run.post_puncture_force_N.push_back(0.0);
    std::vector<LayerState> states;
    for (std::size_t k = 0; k < scene.layers.size(); ++k) states.push_back(model.layer_state(k));
    run.states.push_back(states);
    run.step_wall_time_s.push_back(0.0);
    if (depth >= deepest_m) break;
  }
  return run;
}

double deepest_insertion_depth(const InsertionCurve& curve) {
  double deepest = 0.0;
  for (std::size_t i = 0; i < curve.size(); ++i)
    if (curve.velocity_m_per_s[i] > 0.0) deepest = std::max(deepest, curve.depth_m[i]);
  return deepest;
}

struct SearchState {
  const Scene* scene;
  std::shared_ptr<const meshing::TetMesh> mesh;
  const ReferenceData* reference;
  const IdentificationOptions* options;
  std::vector<double> log_start;
  std::vector<IdentificationEvaluation>* history;
  const IdentificationProgress* progress;
  double best = std::numeric_limits<double>::infinity();
  int evaluations = 0;
  double step = 0.5;  // simulated annealing step in log space
  gsl_rng* rng = nullptr;
};

double evaluate_log(SearchState& s, const double* log_scale) {
  std::vector<double> scale(s.log_start.size());
  const double bound = std::log(s.options->bound_factor);
  for (std::size_t k = 0; k < scale.size(); ++k)
    scale[k] = std::exp(std::clamp(log_scale[k], s.log_start[k] - bound, s.log_start[k] + bound));
  const IdentificationEvaluation e = evaluate_mass_spring(*s.scene, s.mesh, *s.reference, scale, *s.options);
  s.history->push_back(e);
  ++s.evaluations;
  s.best = std::min(s.best, e.objective);
  if (*s.progress) (*s.progress)(s.evaluations, e.objective, s.best);
  return e.objective;
}

// ---- GSL simulated annealing: the configuration is a small array of log factors.
constexpr int kMaxLayers = 16;
struct LogPoint {
  int n;
  double x[kMaxLayers];
};
SearchState* g_state = nullptr;  // gsl_siman's callbacks carry no user pointer for the energy

double siman_energy(void* xp) {
  LogPoint* p = static_cast<LogPoint*>(xp);
  if (g_state->evaluations >= g_state->options->max_evaluations) return g_state->best + 1.0;  // budget spent
  return evaluate_log(*g_state, p->x);
}
void siman_step(const gsl_rng* r, void* xp, double step_size) {
  LogPoint* p = static_cast<LogPoint*>(xp);
  const double bound = std::log(g_state->options->bound_factor);
  for (int k = 0; k < p->n; ++k) {
    p->x[k] += step_size * (2.0 * gsl_rng_uniform(r) - 1.0);
    p->x[k] = std::clamp(p->x[k], g_state->log_start[static_cast<std::size_t>(k)] - bound,
                         g_state->log_start[static_cast<std::size_t>(k)] + bound);
  }
}
double siman_distance(void* a, void* b) {
  const LogPoint* p = static_cast<LogPoint*>(a);
  const LogPoint* q = static_cast<LogPoint*>(b);
  double d = 0.0;
  for (int k = 0; k < p->n; ++k) d += (p->x[k] - q->x[k]) * (p->x[k] - q->x[k]);
  return std::sqrt(d);
}

}  // namespace

IdentificationEvaluation evaluate_mass_spring(const Scene& scene, std::shared_ptr<const meshing::TetMesh> mesh,
                                             const ReferenceData& reference, const std::vector<double>& scale,
                                             const IdentificationOptions& options,
                                             std::vector<LayerPunctureComparison>* punctures) {
  const double deepest = deepest_insertion_depth(reference.curve);
  if (!(deepest > 0.0)) throw std::invalid_argument("identification: the reference has no insertion phase");
  IdentificationEvaluation e;
  e.scale = scale;
  ModelRun run;
  try {
    run = quasi_static_run(scene, mesh, scale, deepest, options.step_m);
  } catch (const std::exception&) {
    e.objective = 1e6;  // a parameter set the model cannot run: the worst value
    e.force_rmse_relative = std::numeric_limits<double>::quiet_NaN();
    return e;
  }
  ReferenceData contact_only = reference;
  contact_only.has_shaft_forces = false;
  const ModelMetrics m = metrics_against_reference(scene, run, contact_only, run.steps());
  e.force_rmse_relative = m.force_rmse_relative;
  double objective = std::isfinite(m.force_rmse_relative) ? m.force_rmse_relative * m.force_rmse_relative : 1e3;
  for (std::size_t k = 0; k < m.punctures.size(); ++k) {
    const LayerPunctureComparison& p = m.punctures[k];
    const double length = std::min(scene.layers[k].force_mesh.spacing_L_m, scene.layers[k].thickness_m);
    if (p.reference_punctured && p.model_punctured) {
      const double x = (p.model_depth_m - p.reference_depth_m) / length;
      objective += options.depth_weight * x * x;
    } else if (p.reference_punctured != p.model_punctured) {
      objective += 1.0;
    }
  }
  e.objective = objective;
  if (punctures) *punctures = m.punctures;
  return e;
}

namespace {

/// The seed's simulated annealing (GSL gsl_siman) over the log scale factors, from state.log_start.
void run_simulated_annealing(SearchState& state, const IdentificationOptions& options, double start_objective,
                             double bound) {
  const std::size_t n = state.log_start.size();
  gsl_rng_env_setup();
  state.rng = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(state.rng, options.seed);
  LogPoint x0{};
  x0.n = static_cast<int>(n);
  for (std::size_t k = 0; k < n; ++k) x0.x[k] = state.log_start[k];
  // Temperatures relative to the starting objective; the cooling schedule
  // spends the evaluation budget: T from T0 down to T0 / 100 in
  // ceil(budget / iters) steps.
  const int iters_per_temperature = 4;
  const int temperatures = std::max(2, options.max_evaluations / iters_per_temperature);
  gsl_siman_params_t params{};
  params.n_tries = 1;
  params.iters_fixed_T = iters_per_temperature;
  params.step_size = 0.25 * bound;
  params.k = 1.0;
  params.t_initial = 0.3 * std::max(start_objective, 1e-3);
  params.mu_t = std::pow(100.0, 1.0 / (temperatures - 1));
  params.t_min = params.t_initial / 100.0 * 0.999;
  g_state = &state;
  gsl_siman_solve(state.rng, &x0, siman_energy, siman_step, siman_distance, nullptr, nullptr, nullptr, nullptr,
                  sizeof(LogPoint), params);
  g_state = nullptr;
  gsl_rng_free(state.rng);
}

/// NLopt's ISRES evolution strategy over the log scale factors within +- bound of state.log_start.
void run_evolution_strategy(SearchState& state, const IdentificationOptions& options, double bound) {
  const std::size_t n = state.log_start.size();
  nlopt::opt opt(nlopt::GN_ISRES, static_cast<unsigned>(n));
  std::vector<double> lo(n), hi(n), x(state.log_start);
  for (std::size_t k = 0; k < n; ++k) lo[k] = state.log_start[k] - bound, hi[k] = state.log_start[k] + bound;
  opt.set_lower_bounds(lo);
  opt.set_upper_bounds(hi);
  opt.set_maxeval(options.max_evaluations);
  opt.set_population(static_cast<unsigned>(options.population));
  nlopt::srand(options.seed);
  opt.set_min_objective(
      [](unsigned, const double* xv, double*, void* data) { return evaluate_log(*static_cast<SearchState*>(data), xv); },
      &state);
  double value = 0.0;
  try {
    opt.optimize(x, value);
  } catch (const nlopt::roundoff_limited&) {
  } catch (const nlopt::forced_stop&) {
  }
}

}  // namespace

IdentificationResult identify_mass_spring_stiffness(const Scene& scene, std::shared_ptr<const meshing::TetMesh> mesh,
                                                    const ReferenceData& reference, const IdentificationOptions& options,
                                                    const IdentificationProgress& progress) {
  if (options.method != "simulated_annealing" && options.method != "isres")
    throw std::invalid_argument("identification: unknown method '" + options.method +
                                "' (known: simulated_annealing, isres)");
  if (options.max_evaluations < 2 || !(options.bound_factor > 1.0) || !(options.step_m > 0.0) ||
      options.population < 2)
    throw std::invalid_argument("identification: need max_evaluations >= 2, bound_factor > 1, step_m > 0, population >= 2");
  const std::size_t n = scene.layers.size();
  if (n > static_cast<std::size_t>(kMaxLayers)) throw std::invalid_argument("identification: too many layers");
  const auto start = std::chrono::steady_clock::now();
  IdentificationResult result;
  result.method = options.method;
  result.scale_before = scene.comparison.mass_spring_stiffness_scale.empty()
                            ? std::vector<double>(n, 1.0)
                            : scene.comparison.mass_spring_stiffness_scale;
  result.before = evaluate_mass_spring(scene, mesh, reference, result.scale_before, options, &result.punctures_before);

  SearchState state;
  state.scene = &scene;
  state.mesh = mesh;
  state.reference = &reference;
  state.options = &options;
  state.history = &result.history;
  state.progress = &progress;
  for (double s : result.scale_before) state.log_start.push_back(std::log(s));
  state.best = result.before.objective;
  const double bound = std::log(options.bound_factor);

  if (options.method == "simulated_annealing")
    run_simulated_annealing(state, options, result.before.objective, bound);
  else
    run_evolution_strategy(state, options, bound);

  // The best point seen (both searches may end elsewhere).
  IdentificationEvaluation best = result.before;
  for (const IdentificationEvaluation& e : result.history)
    if (e.objective < best.objective) best = e;
  result.scale_after = best.scale;
  result.after = evaluate_mass_spring(scene, mesh, reference, best.scale, options, &result.punctures_after);
  result.evaluations = state.evaluations;
  result.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.seconds_per_evaluation = result.wall_time_s / std::max(1, state.evaluations + 2);
  return result;
}

}  // namespace puncture::validation
