// Levenberg-Marquardt (levenberg_marquardt.hpp) against problems with known
// solutions, and its finite-difference Jacobian against analytic derivatives.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "puncture/validation/levenberg_marquardt.hpp"

namespace pv = puncture::validation;

namespace {

/// y = a exp(-b t) sampled at t = 0, 0.1, ..., 2 with a = 2.5, b = 1.3.
std::vector<double> exponential_times() {
  std::vector<double> t;
  for (int i = 0; i <= 20; ++i) t.push_back(0.1 * i);
  return t;
}

pv::ResidualFunction exponential_fit(double a_true, double b_true) {
  return [a_true, b_true](const std::vector<double>& x, std::vector<double>& r) {
    r.clear();
    for (double t : exponential_times()) r.push_back(x[0] * std::exp(-x[1] * t) - a_true * std::exp(-b_true * t));
    return true;
  };
}

/// Rosenbrock as least squares: r = (10 (y - x^2), 1 - x); minimum (1, 1), cost 0.
bool rosenbrock(const std::vector<double>& x, std::vector<double>& r) {
  r = {10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]};
  return true;
}

}  // namespace

TEST(LevenbergMarquardt, RecoversExponentialDecayParameters) {
  const auto r = exponential_fit(2.5, 1.3);
  const pv::LevenbergMarquardtResult res = pv::levenberg_marquardt(r, {1.0, 0.5}, {0.0, 0.0}, {10.0, 10.0});
  EXPECT_NEAR(res.x[0], 2.5, 1e-5);
  EXPECT_NEAR(res.x[1], 1.3, 1e-5);
  EXPECT_LT(res.cost, 1e-10);
  EXPECT_GT(res.initial_cost, 1.0);
}

TEST(LevenbergMarquardt, AcceptsAStartThatIsGoodEnoughWithoutAJacobian) {
  const auto r = exponential_fit(2.5, 1.3);
  std::vector<double> r0;
  r({2.4, 1.3}, r0);
  double start_cost = 0.0;
  for (double v : r0) start_cost += v * v;
  pv::LevenbergMarquardtOptions o;
  o.accept_start_cost = 1.01 * start_cost;
  const pv::LevenbergMarquardtResult kept = pv::levenberg_marquardt(r, {2.4, 1.3}, {0.0, 0.0}, {10.0, 10.0}, o);
  EXPECT_EQ(kept.status, "start_accepted");
  EXPECT_EQ(kept.evaluations, 1);
  EXPECT_EQ(kept.x, (std::vector<double>{2.4, 1.3}));
  EXPECT_DOUBLE_EQ(kept.cost, start_cost);
  // Just below the start's cost the fit runs and finds the truth.
  o.accept_start_cost = 0.99 * start_cost;
  const pv::LevenbergMarquardtResult fitted = pv::levenberg_marquardt(r, {2.4, 1.3}, {0.0, 0.0}, {10.0, 10.0}, o);
  EXPECT_NE(fitted.status, "start_accepted");
  EXPECT_NEAR(fitted.x[0], 2.5, 1e-5);
}

TEST(LevenbergMarquardt, SolvesRosenbrockValley) {
  pv::LevenbergMarquardtOptions o;
  o.max_iterations = 200;
  o.fd_step = 1e-6;
  o.fd_step_min = 1e-6;
  o.cost_tolerance = 1e-12;
  o.step_tolerance = 1e-12;
  const pv::LevenbergMarquardtResult res = pv::levenberg_marquardt(rosenbrock, {-1.2, 1.0}, {-5.0, -5.0}, {5.0, 5.0}, o);
  EXPECT_NEAR(res.x[0], 1.0, 1e-4);
  EXPECT_NEAR(res.x[1], 1.0, 1e-4);
  EXPECT_LT(res.cost, 1e-8);
}

TEST(LevenbergMarquardt, StopsAtTheBoundWhenTheMinimumLiesOutside) {
  // min (x - 3)^2 + (y - 1)^2 with x <= 2: the constrained minimum is (2, 1), cost 1.
  const pv::ResidualFunction r = [](const std::vector<double>& x, std::vector<double>& out) {
    out = {x[0] - 3.0, x[1] - 1.0};
    return true;
  };
  const pv::LevenbergMarquardtResult res = pv::levenberg_marquardt(r, {0.0, 0.0}, {-10.0, -10.0}, {2.0, 10.0});
  EXPECT_DOUBLE_EQ(res.x[0], 2.0);
  EXPECT_NEAR(res.x[1], 1.0, 1e-6);
  EXPECT_NEAR(res.cost, 1.0, 1e-9);
}

TEST(LevenbergMarquardt, TwoTrialStepsProjectedOntoOneBoundPointAreEvaluatedOnce) {
  // r = x - 3 with x <= 2 from 0 on two lanes: both trial steps (lambda and
  // 8 lambda) overshoot past the bound and are projected onto x = 2, which is
  // evaluated once (a model run is not repeated for nothing); the fit ends
  // there (the gradient pushes out of the box).
  std::mutex mutex;
  std::vector<double> evaluated;
  const pv::ResidualFunction r = [&](const std::vector<double>& x, std::vector<double>& out) {
    const std::lock_guard<std::mutex> lock(mutex);
    evaluated.push_back(x[0]);
    out = {x[0] - 3.0};
    return true;
  };
  pv::LevenbergMarquardtOptions o;
  o.threads = 2;
  o.initial_lambda = 1e-6;
  const pv::LevenbergMarquardtResult res = pv::levenberg_marquardt(r, {0.0}, {-10.0}, {2.0}, o);
  EXPECT_DOUBLE_EQ(res.x[0], 2.0);
  EXPECT_EQ(std::count(evaluated.begin(), evaluated.end(), 2.0), 1);
  EXPECT_EQ(res.evaluations, static_cast<int>(evaluated.size()));
}

namespace {

double sum_of_squares_at(const pv::ResidualFunction& r, const std::vector<double>& x) {
  std::vector<double> out;
  r(x, out);
  double sum = 0.0;
  for (double v : out) sum += v * v;
  return sum;
}

/// Runs the fit of the tests below with stalls_to_stop and checks that it
/// ends at its first stall: stalls_to_stop small decreases in a row.
void expect_the_fit_to_end_at_its_first_stall(int stalls_to_stop) {
  // r = (x - 3)^2 + 0.01 from x = 0 on one thread: the cost falls by orders
  // of magnitude, then, near its floor 1e-4, by under 5 % a step.
  // stalls_to_stop such steps in a row are a stall. With fd_step == fd_step_min there is no
  // coarser step to start a new cycle from, so the fit ends at the first
  // stall (each further iteration would cost a Jacobian and a trial, i.e.
  // simulation runs, for a few 1e-5 of the cost). The runs are read back
  // from the order of the evaluations (start, then per iteration a Jacobian
  // column after every accepted step and a trial).
  std::vector<double> costs;
  const pv::ResidualFunction r = [&](const std::vector<double>& x, std::vector<double>& out) {
    out = {(x[0] - 3.0) * (x[0] - 3.0) + 0.01};
    costs.push_back(out[0] * out[0]);
    return true;
  };
  pv::LevenbergMarquardtOptions o;
  o.max_iterations = 100;
  o.fd_step = o.fd_step_min = 0.02;
  o.cost_tolerance = 0.05;
  o.threads = 1;
  o.stalls_to_stop = stalls_to_stop;
  const pv::LevenbergMarquardtResult res = pv::levenberg_marquardt(r, {0.0}, {-1e3}, {1e3}, o);
  EXPECT_LT(res.cost, 1.5e-4);  // near the minimum, cost 1e-4 at x = 3
  EXPECT_EQ(res.status, "cost_tolerance");
  ASSERT_GE(costs.size(), 3u);
  double current = costs[0];
  bool jacobian_next = true;
  int stalls = 0;
  std::size_t first_stall_end = 0;
  for (std::size_t i = 1; i < costs.size(); ++i) {
    if (jacobian_next) {
      jacobian_next = false;
      continue;
    }
    if (costs[i] < current) {  // an accepted trial
      stalls = (current - costs[i]) / current < o.cost_tolerance ? stalls + 1 : 0;
      current = costs[i];
      jacobian_next = true;
      if (stalls == stalls_to_stop && first_stall_end == 0) first_stall_end = i;
    }
  }
  ASSERT_GT(first_stall_end, 0u) << "the fit never stalled";
  EXPECT_EQ(costs.size(), first_stall_end + 1) << "the fit went on after its first stall";
  EXPECT_DOUBLE_EQ(res.cost, current);
}

}  // namespace

TEST(LevenbergMarquardt, WithoutACoarserDifferenceStepTheFirstStallEndsTheFit) {
  expect_the_fit_to_end_at_its_first_stall(2);
}

TEST(LevenbergMarquardt, OneSmallDecreaseIsAStallWhenTheCallerSaysSo) {
  // As above with stalls_to_stop = 1 (the comparison's factor fits, whose
  // evaluations are model runs): the first accepted step that lowers the cost
  // by under cost_tolerance ends the fit, one Jacobian and trial earlier.
  expect_the_fit_to_end_at_its_first_stall(1);
}

TEST(LevenbergMarquardt, ASecantThroughTheTwoTrialsSavesTheDifferenceRunsOfAOneFactorFit) {
  // A factor fit as the comparison runs it: r_i = t_i e^x - y_i (a force
  // proportional to a stiffness factor e^x) from e^x = 6.5, two lanes, the
  // factor fits' options. The least-squares factor in closed form is
  // sum t y / sum t^2. With the secant through each iteration's two trials
  // as the next Jacobian the fit reaches it as closely as with a difference
  // Jacobian after every accepted step, in fewer evaluations.
  std::vector<double> t, y;
  for (int i = 0; i < 12; ++i) {
    t.push_back(0.1 + 0.05 * i);
    y.push_back(21.0 * t.back() * (1.0 + 0.04 * std::sin(1.7 * i)));
  }
  double ty = 0.0, tt = 0.0;
  for (std::size_t i = 0; i < t.size(); ++i) ty += t[i] * y[i], tt += t[i] * t[i];
  const double best = ty / tt;
  const pv::ResidualFunction r = [&](const std::vector<double>& x, std::vector<double>& out) {
    out.resize(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) out[i] = t[i] * std::exp(x[0]) - y[i];
    return true;
  };
  auto fit = [&](bool secant) {
    pv::LevenbergMarquardtOptions o;
    o.max_iterations = 6;
    o.max_evaluations = 14;
    o.fd_step = o.fd_step_min = 0.02;
    o.cost_tolerance = 1e-3;
    o.step_tolerance = 1e-3;
    o.stalls_to_stop = 1;
    o.threads = 2;
    o.secant_jacobian = secant;
    return pv::levenberg_marquardt(r, {std::log(6.5)}, {-std::log(1000.0)}, {std::log(1000.0)}, o);
  };
  const pv::LevenbergMarquardtResult difference = fit(false), secant = fit(true);
  EXPECT_NEAR(std::exp(difference.x[0]) / best, 1.0, 0.01);
  EXPECT_NEAR(std::exp(secant.x[0]) / best, 1.0, 0.01);
  EXPECT_LT(secant.cost, 1.01 * sum_of_squares_at(r, {std::log(best)}));
  EXPECT_EQ(secant.status, "cost_tolerance");  // converged within the budget of 14
  EXPECT_LT(secant.evaluations, difference.evaluations);
}

TEST(LevenbergMarquardt, NeverAcceptsAPointThatCannotBeEvaluated) {
  // r fails for x > 1.5 (e.g. a simulation that throws); the unconstrained minimum is at 3.
  std::atomic<int> failures{0};
  const pv::ResidualFunction r = [&failures](const std::vector<double>& x, std::vector<double>& out) {
    if (x[0] > 1.5) {
      ++failures;
      throw std::runtime_error("cannot run");
    }
    out = {x[0] - 3.0};
    return true;
  };
  const pv::LevenbergMarquardtResult res = pv::levenberg_marquardt(r, {0.0}, {-10.0}, {10.0});
  EXPECT_LE(res.x[0], 1.5);
  EXPECT_LT(res.cost, 9.0);  // it did move towards the minimum
  EXPECT_GT(failures.load(), 0);
  EXPECT_THROW(pv::levenberg_marquardt(r, {2.0}, {-10.0}, {10.0}), std::invalid_argument);
}

TEST(LevenbergMarquardt, RejectsMismatchedBoxes) {
  EXPECT_THROW(pv::levenberg_marquardt(rosenbrock, {0.0, 0.0}, {0.0}, {1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(pv::levenberg_marquardt(rosenbrock, {0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}), std::invalid_argument);
}

TEST(FiniteDifferenceJacobian, MatchesAnalyticDerivativesAndIsTheSameOnAnyThreadCount) {
  const auto r = exponential_fit(2.5, 1.3);
  const std::vector<double> x{2.0, 1.0};
  std::vector<double> r0;
  ASSERT_TRUE(r(x, r0));
  int evaluations = 0;
  const Eigen::MatrixXd J1 = pv::finite_difference_jacobian(r, x, r0, {0.0, 0.0}, {10.0, 10.0}, 1e-7, 1, &evaluations);
  const Eigen::MatrixXd J2 = pv::finite_difference_jacobian(r, x, r0, {0.0, 0.0}, {10.0, 10.0}, 1e-7, 2);
  EXPECT_EQ(evaluations, 2);
  const std::vector<double> ts = exponential_times();
  for (std::size_t i = 0; i < ts.size(); ++i) {
    const double e = std::exp(-x[1] * ts[i]);
    EXPECT_NEAR(J1(static_cast<Eigen::Index>(i), 0), e, 1e-6);                   // d/da a e^{-bt}
    EXPECT_NEAR(J1(static_cast<Eigen::Index>(i), 1), -x[0] * ts[i] * e, 1e-6);   // d/db
  }
  EXPECT_EQ((J1 - J2).cwiseAbs().maxCoeff(), 0.0);
}

TEST(FiniteDifferenceJacobian, StepsBackwardAtTheUpperBoundAndZeroesFailedColumns) {
  const pv::ResidualFunction r = [](const std::vector<double>& x, std::vector<double>& out) {
    if (x[1] != 0.5) return false;  // any move of the second coordinate fails
    out = {x[0] * x[0]};
    return true;
  };
  const std::vector<double> x{1.0, 0.5};
  const std::vector<double> r0{1.0};
  // x[0] sits at its upper bound: a forward step would leave the box.
  const Eigen::MatrixXd J = pv::finite_difference_jacobian(r, x, r0, {0.0, 0.0}, {1.0, 1.0}, 1e-6, 2);
  EXPECT_NEAR(J(0, 0), 2.0, 1e-5);
  EXPECT_EQ(J(0, 1), 0.0);
}

TEST(EvaluateResidualsParallel, UsesSeveralThreadsWhenAsked) {
  std::atomic<int> concurrent{0}, most{0};
  const pv::ResidualFunction r = [&](const std::vector<double>& x, std::vector<double>& out) {
    const int now = ++concurrent;
    int seen = most.load();
    while (now > seen && !most.compare_exchange_weak(seen, now)) {
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    --concurrent;
    out = {x[0]};
    return true;
  };
  std::vector<std::vector<double>> points{{1.0}, {2.0}, {3.0}, {4.0}};
  std::vector<std::vector<double>> rs;
  std::vector<char> ok;
  pv::evaluate_residuals_parallel(r, points, rs, ok, 2);
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_TRUE(ok[i]);
    EXPECT_EQ(rs[i], points[i]);
  }
  EXPECT_EQ(most.load(), 2);
}

TEST(LevenbergMarquardt, EvaluatesTheStartAndItsFirstJacobianTogetherWithTheSameResult) {
  // With two threads the start and the first Jacobian's difference point of a
  // one-parameter fit run at once, and that Jacobian is finite_difference_jacobian's.
  std::atomic<int> concurrent{0}, most{0}, calls{0};
  const auto line = exponential_fit(2.5, 1.3);
  const pv::ResidualFunction r = [&](const std::vector<double>& x, std::vector<double>& out) {
    const int now = ++concurrent;
    int seen = most.load();
    while (now > seen && !most.compare_exchange_weak(seen, now)) {
    }
    if (++calls <= 2) std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the first batch overlaps
    --concurrent;
    return line({x[0], 1.3}, out);
  };
  pv::LevenbergMarquardtOptions o;
  o.threads = 1;
  const pv::LevenbergMarquardtResult serial = pv::levenberg_marquardt(r, {1.0}, {0.0}, {10.0}, o);
  EXPECT_EQ(most.load(), 1);
  calls = 0;
  o.threads = 2;
  const pv::LevenbergMarquardtResult together = pv::levenberg_marquardt(r, {1.0}, {0.0}, {10.0}, o);
  EXPECT_EQ(most.load(), 2);
  EXPECT_NEAR(together.x[0], 2.5, 1e-6);
  EXPECT_NEAR(serial.x[0], 2.5, 1e-6);
  // One thread tries one lambda per iteration, two threads two: compare the
  // first Jacobian instead, which both compute at the start.
  pv::LevenbergMarquardtOptions first = o;
  first.max_iterations = 0;
  const pv::LevenbergMarquardtResult a = pv::levenberg_marquardt(r, {1.0}, {0.0}, {10.0}, first);
  first.threads = 1;
  const pv::LevenbergMarquardtResult b = pv::levenberg_marquardt(r, {1.0}, {0.0}, {10.0}, first);
  EXPECT_EQ(a.evaluations, 2);
  EXPECT_EQ(a.jacobian.rows(), static_cast<Eigen::Index>(exponential_times().size()));
  EXPECT_TRUE(a.jacobian_at_x);
  EXPECT_EQ(a.cost, b.cost);
  std::vector<double> r0;
  line({1.0, 1.3}, r0);
  std::vector<double> lower{0.0}, upper{10.0};
  const Eigen::MatrixXd J = pv::finite_difference_jacobian(r, {1.0}, r0, lower, upper, o.fd_step, 1, nullptr);
  EXPECT_EQ((a.jacobian - J).norm(), 0.0);
}
