// sundials_integrator.hpp: time integration of y' = f(t, y) through SUNDIALS
// for the volumetric comparison models (the real-time model keeps its own
// tick integrators).
//
//   implicit  CVODE, variable-order BDF (orders 1-5) with Newton iterations;
//             linear systems (I - gamma J) by GMRES (SUNLinSol_SPGMR) with the
//             system's own preconditioner and, when it has one, its own
//             Jacobian-vector product (else SUNDIALS' difference quotient).
//             For stiff meshes.
//   explicit  ARKODE ERKStep, adaptive explicit Runge-Kutta (ARKODE's default
//             4th-order embedded table). Stable only below the mesh's
//             critical step.
// Error control: weighted RMS norm with the relative tolerance and one
// absolute tolerance per component.
//
// In:  an OdeSystem (size, rhs, optional preconditioner / J v), settings,
//      t0, y0. Out: advance(t_out, y) = y(t_out) (dense output of the
//      integrator when it stepped past t_out), statistics.
// Recovery: when SUNDIALS gives up on an interval (error test or
// convergence failures, repeated recoverable rhs failures), advance()
// restarts it from the state at its start with a first step and a largest
// step kRecoveryStepCut times smaller at each of kRecoveryAttempts attempts
// (a restart also drops the BDF order back to 1); the caps are lifted again
// once the interval is done. What still fails (rhs returning a fatal error,
// too many steps, every attempt failing) throws std::runtime_error with
// SUNDIALS's message and the time reached; nothing non-finite is returned:
// a non-finite rhs is reported to SUNDIALS as recoverable, so it retries with
// a smaller step.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace puncture::comparison {

class OdeSystem {
 public:
  virtual ~OdeSystem() = default;
  virtual int size() const = 0;
  /// ydot = f(t, y). Return 0 on success, > 0 for a recoverable failure (the
  /// integrator retries with a smaller step), < 0 for a fatal one.
  virtual int rhs(double t, const double* y, double* ydot) = 0;

  virtual bool has_preconditioner() const { return false; }
  /// Prepares P ~ I - gamma J at (t, y). jok: the system may reuse its
  /// Jacobian data; set jacobian_updated when it recomputed it. Return as rhs.
  virtual int preconditioner_setup(double t, const double* y, bool jok, bool& jacobian_updated, double gamma) {
    (void)t, (void)y, (void)jok, (void)gamma;
    jacobian_updated = false;
    return 0;
  }
  /// z = P^-1 r.
  virtual int preconditioner_solve(double t, const double* y, const double* r, double* z, double gamma);

  virtual bool has_jacobian_times() const { return false; }
  /// Jv = J v (with the Jacobian data of the last preconditioner_setup).
  virtual int jacobian_times(double t, const double* y, const double* v, double* Jv) {
    (void)t, (void)y, (void)v, (void)Jv;
    return -1;
  }
};

enum class IntegratorKind { ImplicitBdf, ExplicitRungeKutta };
/// "implicit" or "explicit" (ComparisonSettings::integrator); throws
/// std::invalid_argument naming comparison.integrator otherwise.
IntegratorKind parse_integrator_kind(const std::string& name);
const char* to_string(IntegratorKind kind);

struct IntegratorSettings {
  IntegratorKind kind = IntegratorKind::ImplicitBdf;
  double relative_tolerance = 1e-4;
  Eigen::VectorXd absolute_tolerance;  ///< one per component (> 0)
  long max_steps_per_call = 200000;    ///< internal steps allowed in one advance()
  int krylov_dimension = 10;           ///< GMRES subspace (implicit)
  double max_step_s = 0.0;             ///< > 0: bound on the internal step
  /// Largest BDF order (1..5). BDF above order 2 is not A-stable: the lightly
  /// damped oscillations of an elastic mesh need 2.
  int max_bdf_order = 5;
};

struct IntegratorStats {
  long steps = 0;
  long rhs_evaluations = 0;
  long nonlinear_iterations = 0;
  long linear_iterations = 0;
  long preconditioner_setups = 0;
  long error_test_failures = 0;
  long convergence_failures = 0;
  long reinitialisations = 0;
};

class SundialsIntegrator {
 public:
  SundialsIntegrator(OdeSystem& system, const IntegratorSettings& settings, double t0, const Eigen::VectorXd& y0);
  ~SundialsIntegrator();
  SundialsIntegrator(const SundialsIntegrator&) = delete;
  SundialsIntegrator& operator=(const SundialsIntegrator&) = delete;

  /// Restarts of one interval after SUNDIALS gave up on it (see above).
  static constexpr int kRecoveryAttempts = 3;
  static constexpr double kRecoveryStepCut = 10.0;

  /// Integrates to t_out (> current time) and returns y(t_out).
  void advance(double t_out, Eigen::VectorXd& y);
  /// Intervals restarted after a failure (each attempt counts), since construction.
  long recoveries() const { return recoveries_; }
  /// How a restart chooses its first step.
  enum class FirstStep {
    /// A quarter of the last step taken (the integrator's own estimate when
    /// nothing was taken yet), so a restart after a small change of the
    /// forcing (a contact change) does not climb up from a microsecond again.
    FromLastStep,
    /// The integrator's own estimate from the new state's derivatives: after
    /// a jump of the state far from equilibrium (a puncture frees the nodes
    /// that carried the needle), where a long first step fails its error
    /// test over and over.
    Estimate,
  };
  /// Restart from (t, y) (after a state change: contact, puncture).
  void reinit(double t, const Eigen::VectorXd& y, FirstStep first_step = FirstStep::FromLastStep);
  /// The integrator does not step past t_stop (a kink of the forcing).
  void set_stop_time(double t_stop);

  double time() const { return time_; }
  /// Totals since construction (over every restart).
  IntegratorStats stats() const;
  IntegratorKind kind() const { return settings_.kind; }

  struct Impl;

 private:
  OdeSystem& system_;
  IntegratorSettings settings_;
  double time_ = 0.0;
  long reinits_ = 0;
  long recoveries_ = 0;
  int integrate_to(double t_out, double& t_reached);
  IntegratorStats before_restarts_;  ///< totals of the runs before the last restart
  IntegratorStats current_stats() const;
  std::unique_ptr<Impl> impl_;
};

}  // namespace puncture::comparison
