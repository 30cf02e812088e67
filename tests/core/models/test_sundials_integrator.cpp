// SUNDIALS integration (CVODE BDF with a preconditioner, ARKODE ERK) of a
// damped oscillator x'' + 2 zeta w x' + w^2 x = 0 against its exact solution.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "puncture/comparison/sundials_integrator.hpp"

namespace puncture::comparison {
namespace {

class DampedOscillator : public OdeSystem {
 public:
  DampedOscillator(double omega, double zeta, bool exact_preconditioner)
      : omega_(omega), zeta_(zeta), precondition_(exact_preconditioner) {}
  int size() const override { return 2; }
  int rhs(double, const double* y, double* ydot) override {
    ++rhs_calls;
    ydot[0] = y[1];
    ydot[1] = -omega_ * omega_ * y[0] - 2.0 * zeta_ * omega_ * y[1];
    return 0;
  }
  bool has_preconditioner() const override { return precondition_; }
  int preconditioner_setup(double, const double*, bool, bool& updated, double gamma) override {
    gamma_ = gamma;
    updated = true;
    return 0;
  }
  int preconditioner_solve(double, const double*, const double* r, double* z, double gamma) override {
    // (I - gamma J) z = r with J = [[0, 1], [-w^2, -2 zeta w]], solved exactly.
    (void)gamma_;
    const double a = 1.0, b = -gamma, c = gamma * omega_ * omega_, d = 1.0 + 2.0 * gamma * zeta_ * omega_;
    const double det = a * d - b * c;
    z[0] = (d * r[0] - b * r[1]) / det;
    z[1] = (-c * r[0] + a * r[1]) / det;
    return 0;
  }
  /// x(t) for x(0) = 1, x'(0) = 0, zeta < 1.
  double exact(double t) const {
    const double wd = omega_ * std::sqrt(1.0 - zeta_ * zeta_);
    return std::exp(-zeta_ * omega_ * t) * (std::cos(wd * t) + zeta_ * omega_ / wd * std::sin(wd * t));
  }
  long rhs_calls = 0;

 private:
  double omega_, zeta_;
  bool precondition_;
  double gamma_ = 0.0;
};

double max_error(IntegratorKind kind, bool precondition, double rtol, IntegratorStats* stats = nullptr) {
  DampedOscillator oscillator(2.0 * 3.14159265358979 * 5.0, 0.1, precondition);
  IntegratorSettings settings;
  settings.kind = kind;
  settings.relative_tolerance = rtol;
  settings.absolute_tolerance = Eigen::Vector2d(rtol * 1e-2, rtol);
  Eigen::VectorXd y(2);
  y << 1.0, 0.0;
  SundialsIntegrator integrator(oscillator, settings, 0.0, y);
  double error = 0.0;
  for (int i = 1; i <= 100; ++i) {
    const double t = 0.01 * i;
    integrator.advance(t, y);
    error = std::max(error, std::abs(y[0] - oscillator.exact(t)));
  }
  if (stats) *stats = integrator.stats();
  return error;
}

TEST(SundialsIntegrator, ImplicitBdfMatchesTheExactDampedOscillator) {
  IntegratorStats stats;
  const double error = max_error(IntegratorKind::ImplicitBdf, true, 1e-8, &stats);
  EXPECT_LT(error, 1e-5);
  EXPECT_GT(stats.steps, 0);
  EXPECT_GT(stats.preconditioner_setups, 0);
  // Tighter tolerance, smaller error: the error is controlled, not lucky.
  EXPECT_LT(max_error(IntegratorKind::ImplicitBdf, true, 1e-10), error);
  // Without a preconditioner (plain GMRES) the answer is the same.
  EXPECT_LT(max_error(IntegratorKind::ImplicitBdf, false, 1e-8), 1e-5);
}

TEST(SundialsIntegrator, ExplicitRungeKuttaMatchesTheExactDampedOscillator) {
  const double error = max_error(IntegratorKind::ExplicitRungeKutta, false, 1e-8);
  EXPECT_LT(error, 1e-5);
  EXPECT_LT(max_error(IntegratorKind::ExplicitRungeKutta, false, 1e-10), error);
}

TEST(SundialsIntegrator, ImplicitTakesLargeStepsOnAStiffOscillator) {
  // Overdamped stiff mode (w = 1e5, zeta = 5): the explicit method needs steps
  // below ~1e-6 s, BDF follows the slow decay with far fewer.
  auto run = [](IntegratorKind kind) {
    DampedOscillator oscillator(1e5, 5.0, kind == IntegratorKind::ImplicitBdf);
    IntegratorSettings settings;
    settings.kind = kind;
    settings.relative_tolerance = 1e-6;
    settings.absolute_tolerance = Eigen::Vector2d(1e-10, 1e-6);
    Eigen::VectorXd y(2);
    y << 1.0, 0.0;
    SundialsIntegrator integrator(oscillator, settings, 0.0, y);
    integrator.advance(2e-4, y);
    // x = A exp(l1 t) + B exp(l2 t), l = -w (zeta -+ sqrt(zeta^2 - 1)), A = l2 / (l2 - l1).
    const double l1 = -1e5 * (5.0 - std::sqrt(24.0)), l2 = -1e5 * (5.0 + std::sqrt(24.0));
    const double A = l2 / (l2 - l1), B = 1.0 - A;
    const double exact = A * std::exp(l1 * 2e-4) + B * std::exp(l2 * 2e-4);
    EXPECT_NEAR(y[0], exact, 1e-4 * exact);
    integrator.advance(1e-2, y);
    return integrator.stats().steps;
  };
  const long implicit_steps = run(IntegratorKind::ImplicitBdf);
  const long explicit_steps = run(IntegratorKind::ExplicitRungeKutta);
  EXPECT_LT(implicit_steps * 5, explicit_steps);
}

TEST(SundialsIntegrator, RestartAfterAJumpStartsFromItsOwnStepEstimate) {
  // The stiff oscillator above decays to rest with long steps; then its state
  // jumps back to x = 1 (as a puncture frees the nodes that carried the
  // needle). A restart whose first step is a quarter of the last long one
  // fails its error test on the fast transient over and over (here until
  // CVODE gives up, as the tensor-mass model did after every puncture); the
  // integrator's own estimate follows the exact transient.
  struct Restart {
    bool failed = false;
    long error_test_failures = 0;
    double x = 0.0;
  };
  auto restart = [](SundialsIntegrator::FirstStep first_step) {
    DampedOscillator oscillator(1e5, 5.0, true);
    IntegratorSettings settings;
    settings.relative_tolerance = 1e-6;
    settings.absolute_tolerance = Eigen::Vector2d(1e-10, 1e-6);
    Eigen::VectorXd y(2);
    y << 1.0, 0.0;
    SundialsIntegrator integrator(oscillator, settings, 0.0, y);
    integrator.advance(0.05, y);
    y << 1.0, 0.0;
    integrator.reinit(0.05, y, first_step);
    const long before = integrator.stats().error_test_failures;
    Restart r;
    try {
      integrator.advance(0.05 + 2e-4, y);
      r.x = y[0];
    } catch (const std::runtime_error&) {
      r.failed = true;
    }
    r.error_test_failures = integrator.stats().error_test_failures - before;
    return r;
  };
  const double l1 = -1e5 * (5.0 - std::sqrt(24.0)), l2 = -1e5 * (5.0 + std::sqrt(24.0));
  const double A = l2 / (l2 - l1), B = 1.0 - A;
  const double exact = A * std::exp(l1 * 2e-4) + B * std::exp(l2 * 2e-4);
  const Restart from_last = restart(SundialsIntegrator::FirstStep::FromLastStep);
  const Restart estimate = restart(SundialsIntegrator::FirstStep::Estimate);
  EXPECT_GT(from_last.error_test_failures, 0);
  ASSERT_FALSE(estimate.failed);
  EXPECT_NEAR(estimate.x, exact, 1e-4 * exact);
  EXPECT_LT(estimate.error_test_failures, from_last.error_test_failures);
  if (!from_last.failed) EXPECT_NEAR(from_last.x, exact, 1e-4 * exact);
}

class NaNSystem : public OdeSystem {
 public:
  int size() const override { return 1; }
  int rhs(double t, const double* y, double* ydot) override {
    ydot[0] = t > 0.5 ? std::numeric_limits<double>::quiet_NaN() : -y[0];
    return 0;
  }
};

TEST(SundialsIntegrator, NonFiniteRightHandSideIsAClearError) {
  for (IntegratorKind kind : {IntegratorKind::ImplicitBdf, IntegratorKind::ExplicitRungeKutta}) {
    NaNSystem system;
    IntegratorSettings settings;
    settings.kind = kind;
    settings.absolute_tolerance = Eigen::VectorXd::Constant(1, 1e-8);
    settings.max_step_s = 0.01;  // so the first advance does not step past t = 0.5
    Eigen::VectorXd y = Eigen::VectorXd::Ones(1);
    SundialsIntegrator integrator(system, settings, 0.0, y);
    integrator.advance(0.4, y);
    EXPECT_NEAR(y[0], std::exp(-0.4), 1e-3);
    try {
      integrator.advance(1.0, y);
      ADD_FAILURE() << "expected a failure";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("failed at t ="), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(parse_integrator_kind("rk45"), std::invalid_argument);
}

/// y' = -y whose rhs fails (recoverably) when evaluated at `failing_time`:
/// `failures` times, or always (-1). A restart of the integrator at that
/// time makes its first evaluation fail, which CVODE does not retry.
class FlakySystem : public OdeSystem {
 public:
  int size() const override { return 1; }
  int rhs(double t, const double* y, double* ydot) override {
    if (t == failing_time && failures != 0) {
      if (failures > 0) --failures;
      return 1;
    }
    ydot[0] = -y[0];
    return 0;
  }
  double failing_time = -1.0;
  long failures = 0;
};

TEST(SundialsIntegrator, AnIntervalSundialsGivesUpOnIsRestartedWithSmallerSteps) {
  IntegratorSettings settings;
  settings.kind = IntegratorKind::ImplicitBdf;
  settings.absolute_tolerance = Eigen::VectorXd::Constant(1, 1e-10);
  settings.relative_tolerance = 1e-8;
  {
    FlakySystem system;
    Eigen::VectorXd y = Eigen::VectorXd::Ones(1);
    SundialsIntegrator integrator(system, settings, 0.0, y);
    integrator.advance(0.1, y);
    // A restart (as after a contact change) whose first evaluation fails once.
    system.failing_time = 0.1;
    system.failures = 1;
    integrator.reinit(0.1, y);
    integrator.advance(0.2, y);
    EXPECT_EQ(integrator.recoveries(), 1);
    EXPECT_NEAR(y[0], std::exp(-0.2), 1e-6);
    integrator.advance(1.0, y);
    EXPECT_NEAR(y[0], std::exp(-1.0), 1e-6);
  }
  {
    FlakySystem system;  // failing every time: a clear error naming the restarts
    Eigen::VectorXd y = Eigen::VectorXd::Ones(1);
    SundialsIntegrator integrator(system, settings, 0.0, y);
    integrator.advance(0.1, y);
    system.failing_time = 0.1;
    system.failures = -1;
    integrator.reinit(0.1, y);
    try {
      integrator.advance(0.2, y);
      ADD_FAILURE() << "expected a failure";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("also after restarts with smaller steps"), std::string::npos) << e.what();
    }
    EXPECT_EQ(integrator.recoveries(), SundialsIntegrator::kRecoveryAttempts);
    EXPECT_TRUE(y.allFinite());
  }
}

}  // namespace
}  // namespace puncture::comparison
