// Optimisers of a calibration stage (optimisers.hpp).
#include "optimisers.hpp"

#include <gsl/gsl_rng.h>
#include <gsl/gsl_siman.h>

#include <algorithm>
#include <cmath>
#include <nlopt.hpp>
#include <sstream>
#include <stdexcept>

#include "puncture/validation/levenberg_marquardt.hpp"

namespace puncture::validation::calibration_detail {

namespace {

double nlopt_objective(unsigned n, const double* x, double* grad, void* data) {
  (void)n;
  (void)grad;  // derivative-free algorithms only
  return static_cast<StageObjective*>(data)->evaluate(x);
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
std::string run_nlopt_once(StageObjective& ctx, nlopt::algorithm algorithm, std::vector<double> x, int max_evaluations) {
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
  opt.set_xtol_abs(ctx.inputs().options->log_x_tolerance);
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
std::string run_nlopt(StageObjective& ctx, nlopt::algorithm algorithm, const std::vector<double>& x0) {
  const int budget = std::max(ctx.inputs().options->max_evaluations_per_stage,
                              ctx.inputs().options->evaluations_per_parameter * static_cast<int>(ctx.parameters.size()));
  const int start_evaluations = ctx.evaluations();
  std::string record;
  std::vector<double> x = x0;
  for (int run = 0; run < 20; ++run) {
    const int left = budget - (ctx.evaluations() - start_evaluations);
    if (left < 2 * static_cast<int>(ctx.parameters.size()) + 2) break;
    const double before = ctx.best();
    record = run_nlopt_once(ctx, algorithm, x, left);
    if (!ctx.best_x().empty()) x = ctx.best_x();
    if (!(ctx.best() < before - 0.01 * std::abs(before))) break;
    if (run > 0) record += " (restart " + std::to_string(run) + ")";
  }
  return record;
}

// --- simulated annealing (GSL gsl_siman, fixed-size state) ---
struct AnnealState {
  int n;
  double x[kMaxParameters];
};
thread_local StageObjective* g_anneal_ctx = nullptr;
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

std::string run_annealing(StageObjective& ctx, const std::vector<double>& x0) {
  const AnnealingSettings& a = ctx.inputs().options->annealing;
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
  if (a.polish_locally) record += " + nelder_mead: " + run_nlopt(ctx, nlopt::LN_NELDERMEAD, ctx.best_x());
  return record;
}

/// Levenberg-Marquardt on the stage's residuals; returns its stop reason,
/// iterations and objective.
std::string run_levenberg_marquardt(StageObjective& ctx, const std::vector<double>& x0) {
  const CalibrationOptions& o = *ctx.inputs().options;
  std::vector<double> lo, hi;
  for (const Parameter& p : ctx.parameters) lo.push_back(p.lower), hi.push_back(p.upper);
  std::vector<double> x = x0;
  for (std::size_t j = 0; j < x.size(); ++j) x[j] = std::clamp(x[j], lo[j], hi[j]);
  if (!ctx.set_layout(x)) return "levenberg_marquardt: the start point cannot be run";
  LevenbergMarquardtOptions lm;
  lm.threads = o.threads;
  lm.max_evaluations = std::max(o.max_evaluations_per_stage,
                                o.evaluations_per_parameter * static_cast<int>(ctx.parameters.size()));
  lm.max_iterations = o.lm_max_iterations;
  lm.fd_step = o.lm_difference_step;
  lm.fd_step_min = o.lm_difference_step_min;
  const ResidualFunction r = [&ctx](const std::vector<double>& xi, std::vector<double>& out) {
    return ctx.residuals_at(xi, out);
  };
  try {
    const LevenbergMarquardtResult res = levenberg_marquardt(r, x, lo, hi, lm);
    std::ostringstream s;
    s << "levenberg_marquardt: " << res.status << " after " << res.iterations << " iterations";
    return s.str();
  } catch (const std::invalid_argument& e) {
    return std::string("levenberg_marquardt: ") + e.what();
  }
}

}  // namespace

std::string run_stage(StageObjective& ctx, const std::vector<double>& x0) {
  switch (ctx.inputs().options->method) {
    case CalibrationMethod::LevenbergMarquardt: return run_levenberg_marquardt(ctx, x0);
    case CalibrationMethod::Bobyqa: return run_nlopt(ctx, nlopt::LN_BOBYQA, x0);
    case CalibrationMethod::NelderMead: return run_nlopt(ctx, nlopt::LN_NELDERMEAD, x0);
    case CalibrationMethod::SimulatedAnnealing: return run_annealing(ctx, x0);
  }
  throw std::logic_error("run_stage: unknown method");
}

}  // namespace puncture::validation::calibration_detail
