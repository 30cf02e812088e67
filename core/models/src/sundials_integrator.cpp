// sundials_integrator.cpp: CVODE BDF (Newton-Krylov) and ARKODE ERK behind one
// interface; see sundials_integrator.hpp.
#include "puncture/comparison/sundials_integrator.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_spgmr.h>

namespace puncture::comparison {

int OdeSystem::preconditioner_solve(double, const double*, const double* r, double* z, double) {
  std::memcpy(z, r, sizeof(double) * static_cast<std::size_t>(size()));
  return 0;
}

IntegratorKind parse_integrator_kind(const std::string& name) {
  if (name == "implicit") return IntegratorKind::ImplicitBdf;
  if (name == "explicit") return IntegratorKind::ExplicitRungeKutta;
  throw std::invalid_argument("comparison.integrator: unknown integrator '" + name + "' (known: implicit, explicit)");
}

const char* to_string(IntegratorKind kind) {
  return kind == IntegratorKind::ImplicitBdf ? "implicit (CVODE BDF, Newton-GMRES)" : "explicit (ARKODE ERK)";
}

struct SundialsIntegrator::Impl {
  SUNContext context = nullptr;
  N_Vector y = nullptr;
  N_Vector abstol = nullptr;
  void* memory = nullptr;
  SUNLinearSolver linear_solver = nullptr;
  OdeSystem* system = nullptr;
  std::string last_error;
  int n = 0;

  ~Impl() {
    if (memory) {
      if (linear_solver)
        CVodeFree(&memory);
      else
        ERKStepFree(&memory);
    }
    if (linear_solver) SUNLinSolFree(linear_solver);
    if (abstol) N_VDestroy(abstol);
    if (y) N_VDestroy(y);
    if (context) SUNContext_Free(&context);
  }
};

namespace {

using Impl = SundialsIntegrator::Impl;

int rhs_callback(realtype t, N_Vector y, N_Vector ydot, void* data) {
  Impl* impl = static_cast<Impl*>(data);
  double* out = N_VGetArrayPointer(ydot);
  int status = impl->system->rhs(t, N_VGetArrayPointer(y), out);
  if (status == 0) {
    for (int i = 0; i < impl->n; ++i)
      if (!std::isfinite(out[i])) return 1;  // recoverable: SUNDIALS retries with a smaller step
  }
  return status;
}

int prec_setup_callback(realtype t, N_Vector y, N_Vector, booleantype jok, booleantype* jcur, realtype gamma,
                        void* data) {
  Impl* impl = static_cast<Impl*>(data);
  bool updated = false;
  const int status = impl->system->preconditioner_setup(t, N_VGetArrayPointer(y), jok != 0, updated, gamma);
  *jcur = updated ? SUNTRUE : SUNFALSE;
  return status;
}

int prec_solve_callback(realtype t, N_Vector y, N_Vector, N_Vector r, N_Vector z, realtype gamma, realtype, int,
                        void* data) {
  Impl* impl = static_cast<Impl*>(data);
  return impl->system->preconditioner_solve(t, N_VGetArrayPointer(y), N_VGetArrayPointer(r), N_VGetArrayPointer(z),
                                            gamma);
}

int jtimes_callback(N_Vector v, N_Vector Jv, realtype t, N_Vector y, N_Vector, void* data, N_Vector) {
  Impl* impl = static_cast<Impl*>(data);
  return impl->system->jacobian_times(t, N_VGetArrayPointer(y), N_VGetArrayPointer(v), N_VGetArrayPointer(Jv));
}

void error_callback(int code, const char* module, const char* function, char* message, void* data) {
  Impl* impl = static_cast<Impl*>(data);
  std::ostringstream s;
  s << module << "::" << function << " (" << code << "): " << message;
  impl->last_error = s.str();
}

void check(int flag, const char* what) {
  if (flag < 0) throw std::runtime_error(std::string("SUNDIALS: ") + what + " failed (flag " + std::to_string(flag) + ")");
}

}  // namespace

SundialsIntegrator::SundialsIntegrator(OdeSystem& system, const IntegratorSettings& settings, double t0,
                                       const Eigen::VectorXd& y0)
    : system_(system), settings_(settings), time_(t0), impl_(std::make_unique<Impl>()) {
  const int n = system.size();
  if (n <= 0) throw std::invalid_argument("SundialsIntegrator: empty system");
  if (y0.size() != n) throw std::invalid_argument("SundialsIntegrator: y0 has the wrong size");
  if (settings.absolute_tolerance.size() != n || !(settings.absolute_tolerance.array() > 0.0).all())
    throw std::invalid_argument("SundialsIntegrator: need one absolute tolerance > 0 per component");
  if (!(settings.relative_tolerance > 0.0)) throw std::invalid_argument("SundialsIntegrator: relative tolerance must be > 0");
  impl_->system = &system;
  impl_->n = n;
  check(SUNContext_Create(nullptr, &impl_->context), "SUNContext_Create");
  impl_->y = N_VNew_Serial(n, impl_->context);
  impl_->abstol = N_VNew_Serial(n, impl_->context);
  if (!impl_->y || !impl_->abstol) throw std::runtime_error("SUNDIALS: cannot allocate vectors");
  std::copy(y0.data(), y0.data() + n, N_VGetArrayPointer(impl_->y));
  std::copy(settings.absolute_tolerance.data(), settings.absolute_tolerance.data() + n,
            N_VGetArrayPointer(impl_->abstol));

  if (settings.kind == IntegratorKind::ImplicitBdf) {
    impl_->memory = CVodeCreate(CV_BDF, impl_->context);
    if (!impl_->memory) throw std::runtime_error("SUNDIALS: CVodeCreate failed");
    impl_->linear_solver = SUNLinSol_SPGMR(impl_->y, system.has_preconditioner() ? SUN_PREC_LEFT : SUN_PREC_NONE,
                                           settings.krylov_dimension, impl_->context);
    if (!impl_->linear_solver) throw std::runtime_error("SUNDIALS: SUNLinSol_SPGMR failed");
    check(CVodeInit(impl_->memory, rhs_callback, t0, impl_->y), "CVodeInit");
    check(CVodeSetUserData(impl_->memory, impl_.get()), "CVodeSetUserData");
    check(CVodeSetErrHandlerFn(impl_->memory, error_callback, impl_.get()), "CVodeSetErrHandlerFn");
    check(CVodeSVtolerances(impl_->memory, settings.relative_tolerance, impl_->abstol), "CVodeSVtolerances");
    check(CVodeSetLinearSolver(impl_->memory, impl_->linear_solver, nullptr), "CVodeSetLinearSolver");
    if (system.has_preconditioner())
      check(CVodeSetPreconditioner(impl_->memory, prec_setup_callback, prec_solve_callback), "CVodeSetPreconditioner");
    if (system.has_jacobian_times()) check(CVodeSetJacTimes(impl_->memory, nullptr, jtimes_callback), "CVodeSetJacTimes");
    check(CVodeSetMaxNumSteps(impl_->memory, settings.max_steps_per_call), "CVodeSetMaxNumSteps");
    if (settings.max_step_s > 0.0) check(CVodeSetMaxStep(impl_->memory, settings.max_step_s), "CVodeSetMaxStep");
    if (settings.max_bdf_order < 1 || settings.max_bdf_order > 5)
      throw std::invalid_argument("SundialsIntegrator: max_bdf_order must be in 1..5");
    check(CVodeSetMaxOrd(impl_->memory, settings.max_bdf_order), "CVodeSetMaxOrd");
  } else {
    impl_->memory = ERKStepCreate(rhs_callback, t0, impl_->y, impl_->context);
    if (!impl_->memory) throw std::runtime_error("SUNDIALS: ERKStepCreate failed");
    check(ERKStepSetUserData(impl_->memory, impl_.get()), "ERKStepSetUserData");
    check(ERKStepSetErrHandlerFn(impl_->memory, error_callback, impl_.get()), "ERKStepSetErrHandlerFn");
    check(ERKStepSVtolerances(impl_->memory, settings.relative_tolerance, impl_->abstol), "ERKStepSVtolerances");
    check(ERKStepSetMaxNumSteps(impl_->memory, settings.max_steps_per_call), "ERKStepSetMaxNumSteps");
    if (settings.max_step_s > 0.0) check(ERKStepSetMaxStep(impl_->memory, settings.max_step_s), "ERKStepSetMaxStep");
  }
}

SundialsIntegrator::~SundialsIntegrator() = default;

int SundialsIntegrator::integrate_to(double t_out, double& t_reached) {
  realtype reached = time_;
  impl_->last_error.clear();
  const int flag = settings_.kind == IntegratorKind::ImplicitBdf
                       ? CVode(impl_->memory, t_out, impl_->y, &reached, CV_NORMAL)
                       : ERKStepEvolve(impl_->memory, t_out, impl_->y, &reached, ARK_NORMAL);
  t_reached = reached;
  return flag;
}

namespace {
/// Failures a restart with smaller steps can cure (not a fatal rhs, not too much work).
bool restartable(IntegratorKind kind, int flag) {
  if (kind == IntegratorKind::ImplicitBdf)
    return flag == CV_ERR_FAILURE || flag == CV_CONV_FAILURE || flag == CV_REPTD_RHSFUNC_ERR ||
           flag == CV_FIRST_RHSFUNC_ERR || flag == CV_LSETUP_FAIL || flag == CV_LSOLVE_FAIL;
  return flag == ARK_ERR_FAILURE || flag == ARK_REPTD_RHSFUNC_ERR || flag == ARK_FIRST_RHSFUNC_ERR;
}
}  // namespace

void SundialsIntegrator::advance(double t_out, Eigen::VectorXd& y) {
  if (!(t_out > time_)) throw std::invalid_argument("SundialsIntegrator::advance: t_out must be after the current time");
  const double t_start = time_;
  const Eigen::VectorXd y_start = Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(impl_->y), impl_->n);
  double t_reached = t_start;
  int flag = integrate_to(t_out, t_reached);
  const bool bdf = settings_.kind == IntegratorKind::ImplicitBdf;
  for (int attempt = 1; flag < 0 && attempt <= kRecoveryAttempts && restartable(settings_.kind, flag); ++attempt) {
    // Restart the interval from its start with smaller first and largest steps.
    ++recoveries_;
    const std::string failure = impl_->last_error;
    const double cut = std::pow(kRecoveryStepCut, attempt);
    const double span = t_out - t_start;
    const double max_step = settings_.max_step_s > 0.0 ? std::min(settings_.max_step_s, span) / cut : span / cut;
    reinit(t_start, y_start, FirstStep::Estimate);
    if (bdf) {
      check(CVodeSetInitStep(impl_->memory, max_step / cut), "CVodeSetInitStep");
      check(CVodeSetMaxStep(impl_->memory, max_step), "CVodeSetMaxStep");
    } else {
      check(ERKStepSetInitStep(impl_->memory, max_step / cut), "ERKStepSetInitStep");
      check(ERKStepSetMaxStep(impl_->memory, max_step), "ERKStepSetMaxStep");
    }
    flag = integrate_to(t_out, t_reached);
    if (flag < 0 && impl_->last_error.empty()) impl_->last_error = failure;
    // The caps hold for the interval only.
    const double settings_max = settings_.max_step_s > 0.0 ? settings_.max_step_s : 0.0;  // 0: no limit
    if (bdf)
      check(CVodeSetMaxStep(impl_->memory, settings_max), "CVodeSetMaxStep");
    else
      check(ERKStepSetMaxStep(impl_->memory, settings_max), "ERKStepSetMaxStep");
  }
  if (flag < 0) {
    std::ostringstream s;
    s << "time integration (" << to_string(settings_.kind) << ") failed at t = " << t_reached << " s on the way to "
      << t_out << " s" << (restartable(settings_.kind, flag) ? " (also after restarts with smaller steps)" : "") << ": "
      << (impl_->last_error.empty() ? "flag " + std::to_string(flag) : impl_->last_error);
    throw std::runtime_error(s.str());
  }
  time_ = t_out;
  const double* data = N_VGetArrayPointer(impl_->y);
  y = Eigen::Map<const Eigen::VectorXd>(data, impl_->n);
  if (!y.allFinite()) throw std::runtime_error("time integration returned a non-finite state at t = " + std::to_string(t_out));
}

void SundialsIntegrator::reinit(double t, const Eigen::VectorXd& y, FirstStep first_step) {
  if (y.size() != impl_->n) throw std::invalid_argument("SundialsIntegrator::reinit: wrong size");
  std::copy(y.data(), y.data() + impl_->n, N_VGetArrayPointer(impl_->y));
  before_restarts_ = stats();  // the counters restart with the integrator
  realtype last_step = 0.0;
  if (settings_.kind == IntegratorKind::ImplicitBdf) {
    if (first_step == FirstStep::FromLastStep) CVodeGetLastStep(impl_->memory, &last_step);
    check(CVodeReInit(impl_->memory, t, impl_->y), "CVodeReInit");
    check(CVodeSetInitStep(impl_->memory, last_step > 0.0 ? 0.25 * last_step : 0.0), "CVodeSetInitStep");
  } else {
    if (first_step == FirstStep::FromLastStep) ERKStepGetLastStep(impl_->memory, &last_step);
    check(ERKStepReInit(impl_->memory, rhs_callback, t, impl_->y), "ERKStepReInit");
    check(ERKStepSetInitStep(impl_->memory, last_step > 0.0 ? 0.25 * last_step : 0.0), "ERKStepSetInitStep");
  }
  time_ = t;
  ++reinits_;
}

void SundialsIntegrator::set_stop_time(double t_stop) {
  if (settings_.kind == IntegratorKind::ImplicitBdf)
    check(CVodeSetStopTime(impl_->memory, t_stop), "CVodeSetStopTime");
  else
    check(ERKStepSetStopTime(impl_->memory, t_stop), "ERKStepSetStopTime");
}

IntegratorStats SundialsIntegrator::stats() const {
  const IntegratorStats now = current_stats();
  IntegratorStats s = before_restarts_;
  s.steps += now.steps;
  s.rhs_evaluations += now.rhs_evaluations;
  s.nonlinear_iterations += now.nonlinear_iterations;
  s.linear_iterations += now.linear_iterations;
  s.preconditioner_setups += now.preconditioner_setups;
  s.error_test_failures += now.error_test_failures;
  s.convergence_failures += now.convergence_failures;
  s.reinitialisations = reinits_;
  return s;
}

IntegratorStats SundialsIntegrator::current_stats() const {
  IntegratorStats s;
  if (settings_.kind == IntegratorKind::ImplicitBdf) {
    CVodeGetNumSteps(impl_->memory, &s.steps);
    CVodeGetNumRhsEvals(impl_->memory, &s.rhs_evaluations);
    CVodeGetNumNonlinSolvIters(impl_->memory, &s.nonlinear_iterations);
    CVodeGetNumLinIters(impl_->memory, &s.linear_iterations);
    CVodeGetNumPrecEvals(impl_->memory, &s.preconditioner_setups);
    CVodeGetNumErrTestFails(impl_->memory, &s.error_test_failures);
    CVodeGetNumNonlinSolvConvFails(impl_->memory, &s.convergence_failures);
  } else {
    long explicit_evals = 0;
    ERKStepGetNumSteps(impl_->memory, &s.steps);
    ERKStepGetNumRhsEvals(impl_->memory, &explicit_evals);
    s.rhs_evaluations = explicit_evals;
    ERKStepGetNumErrTestFails(impl_->memory, &s.error_test_failures);
  }
  return s;
}

}  // namespace puncture::comparison
