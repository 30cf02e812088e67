// Bounded Levenberg-Marquardt with parallel finite-difference Jacobians
// (levenberg_marquardt.hpp).
#include "puncture/validation/levenberg_marquardt.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <thread>

namespace puncture::validation {

namespace {

int thread_count(int requested, std::size_t jobs) {
  int t = requested > 0 ? requested : static_cast<int>(std::thread::hardware_concurrency());
  t = std::max(1, t);
  return static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(t), std::max<std::size_t>(jobs, 1)));
}

double sum_sq(const std::vector<double>& r) {
  double s = 0.0;
  for (double v : r) s += v * v;
  return s;
}

Eigen::VectorXd as_vector(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

/// The free parameters: not at a bound with the descent direction -g pointing out of the box.
std::vector<int> free_parameters(const std::vector<double>& x, const Eigen::VectorXd& g,
                                 const std::vector<double>& lower, const std::vector<double>& upper) {
  std::vector<int> free;
  for (std::size_t j = 0; j < x.size(); ++j) {
    const double tol = 1e-12 * std::max(1.0, upper[j] - lower[j]);
    const bool at_lower = x[j] <= lower[j] + tol && g(static_cast<Eigen::Index>(j)) > 0.0;
    const bool at_upper = x[j] >= upper[j] - tol && g(static_cast<Eigen::Index>(j)) < 0.0;
    if (!at_lower && !at_upper) free.push_back(static_cast<int>(j));
  }
  return free;
}

/// The damped Gauss-Newton step over the free parameters, projected into the box.
std::vector<double> trial_point(const std::vector<double>& x, const Eigen::MatrixXd& J, const Eigen::VectorXd& r,
                                const std::vector<int>& free, double lambda, const std::vector<double>& lower,
                                const std::vector<double>& upper) {
  const Eigen::Index nf = static_cast<Eigen::Index>(free.size());
  Eigen::MatrixXd Jf(J.rows(), nf);
  for (Eigen::Index c = 0; c < nf; ++c) Jf.col(c) = J.col(free[static_cast<std::size_t>(c)]);
  Eigen::MatrixXd A = Jf.transpose() * Jf;
  const Eigen::VectorXd b = -Jf.transpose() * r;
  const double floor = 1e-12 * std::max(1e-300, A.diagonal().maxCoeff());
  for (Eigen::Index c = 0; c < nf; ++c) A(c, c) += lambda * std::max(A(c, c), floor);
  const Eigen::VectorXd dx = A.ldlt().solve(b);
  std::vector<double> t = x;
  for (Eigen::Index c = 0; c < nf; ++c) {
    const std::size_t j = static_cast<std::size_t>(free[static_cast<std::size_t>(c)]);
    const double step = std::isfinite(dx(c)) ? dx(c) : 0.0;
    t[j] = std::clamp(x[j] + step, lower[j], upper[j]);
  }
  return t;
}

double max_abs_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

void check_problem(const std::vector<double>& x0, const std::vector<double>& lower, const std::vector<double>& upper) {
  if (x0.empty()) throw std::invalid_argument("levenberg_marquardt: no parameters");
  if (lower.size() != x0.size() || upper.size() != x0.size())
    throw std::invalid_argument("levenberg_marquardt: x0, lower and upper differ in size");
  for (std::size_t j = 0; j < x0.size(); ++j)
    if (!(lower[j] <= upper[j])) throw std::invalid_argument("levenberg_marquardt: empty box in coordinate " + std::to_string(j));
}

}  // namespace

void evaluate_residuals_parallel(const ResidualFunction& r, const std::vector<std::vector<double>>& points,
                                 std::vector<std::vector<double>>& residuals, std::vector<char>& ok, int threads) {
  residuals.assign(points.size(), {});
  ok.assign(points.size(), 0);
  std::atomic<std::size_t> next{0};
  auto work = [&]() {
    for (std::size_t i = next++; i < points.size(); i = next++) {
      try {
        ok[i] = r(points[i], residuals[i]) ? 1 : 0;
        for (double v : residuals[i]) ok[i] = ok[i] && std::isfinite(v);
      } catch (const std::exception&) {
        ok[i] = 0;
      }
    }
  };
  const int n = thread_count(threads, points.size());
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
}

namespace {

/// The difference points x + step_j e_j of a forward-difference Jacobian
/// (backward where x + h > upper, towards the farther bound in a box narrower than h).
std::vector<std::vector<double>> difference_points(const std::vector<double>& x, const std::vector<double>& lower,
                                                   const std::vector<double>& upper, double h,
                                                   std::vector<double>& step) {
  std::vector<std::vector<double>> points(x.size(), x);
  step.assign(x.size(), h);
  for (std::size_t j = 0; j < x.size(); ++j) {
    if (x[j] + h > upper[j]) step[j] = x[j] - h >= lower[j] ? -h : (upper[j] - x[j] >= x[j] - lower[j] ? upper[j] - x[j] : lower[j] - x[j]);
    if (step[j] == 0.0) step[j] = h;  // an empty box (lower = upper): r is tried just outside it
    points[j][j] += step[j];
  }
  return points;
}

/// The Jacobian from the residuals at the difference points (a failed column is zero).
Eigen::MatrixXd jacobian_from(const std::vector<std::vector<double>>& rs, const std::vector<char>& ok,
                              const std::vector<double>& r0, const std::vector<double>& step) {
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(r0.size()), static_cast<Eigen::Index>(step.size()));
  for (std::size_t j = 0; j < step.size(); ++j) {
    if (!ok[j] || rs[j].size() != r0.size()) continue;
    J.col(static_cast<Eigen::Index>(j)) = (as_vector(rs[j]) - as_vector(r0)) / step[j];
  }
  return J;
}

}  // namespace

Eigen::MatrixXd finite_difference_jacobian(const ResidualFunction& r, const std::vector<double>& x,
                                           const std::vector<double>& r0, const std::vector<double>& lower,
                                           const std::vector<double>& upper, double h, int threads, int* evaluations) {
  std::vector<double> step;
  const std::vector<std::vector<double>> points = difference_points(x, lower, upper, h, step);
  std::vector<std::vector<double>> rs;
  std::vector<char> ok;
  evaluate_residuals_parallel(r, points, rs, ok, threads);
  if (evaluations) *evaluations += static_cast<int>(points.size());
  return jacobian_from(rs, ok, r0, step);
}

namespace {

/// The start: r at x0 (clamped into the box). With `with_jacobian` the
/// difference points of the first Jacobian (step h) are evaluated together
/// with it on `threads` threads (they do not need r(x0)), so a fit that will
/// need that Jacobian anyway does not wait for the start alone; the Jacobian
/// is the same as finite_difference_jacobian's.
LevenbergMarquardtResult start_point(const ResidualFunction& r, const std::vector<double>& x0,
                                     const std::vector<double>& lower, const std::vector<double>& upper,
                                     bool with_jacobian, double h, int threads) {
  check_problem(x0, lower, upper);
  LevenbergMarquardtResult res;
  res.x = x0;
  for (std::size_t j = 0; j < x0.size(); ++j) res.x[j] = std::clamp(x0[j], lower[j], upper[j]);
  std::vector<std::vector<double>> points{res.x};
  std::vector<double> step;
  if (with_jacobian) {
    const std::vector<std::vector<double>> columns = difference_points(res.x, lower, upper, h, step);
    points.insert(points.end(), columns.begin(), columns.end());
  }
  std::vector<std::vector<double>> rs;
  std::vector<char> ok;
  evaluate_residuals_parallel(r, points, rs, ok, threads);
  res.evaluations = static_cast<int>(points.size());
  res.residuals = rs[0];
  if (!ok[0] || res.residuals.empty()) throw std::invalid_argument("levenberg_marquardt: the residuals cannot be evaluated at x0");
  res.cost = res.initial_cost = sum_sq(res.residuals);
  if (with_jacobian)
    res.jacobian = jacobian_from(std::vector<std::vector<double>>(rs.begin() + 1, rs.end()),
                                 std::vector<char>(ok.begin() + 1, ok.end()), res.residuals, step);
  return res;
}

/// The trial points of one iteration: lambda and, on a second lane, 8 lambda.
struct Trial {
  bool accepted = false;        ///< a trial lowered the cost
  double lambda = 0.0;          ///< the accepted trial's, else the largest tried
  double cost = 0.0;
  std::vector<double> x, residuals;
  /// The other lane's point and residuals when both were evaluated (for a secant).
  std::vector<double> other_x, other_residuals;
};

Trial try_steps(const ResidualFunction& r, LevenbergMarquardtResult& res, const Eigen::VectorXd& rv,
                const std::vector<int>& free, double lambda, int lanes, const std::vector<double>& lower,
                const std::vector<double>& upper) {
  std::vector<std::vector<double>> points, rs;
  std::vector<double> lambdas;
  for (int lane = 0; lane < lanes; ++lane) {
    lambdas.push_back(lane == 0 ? lambda : 8.0 * lambda);
    points.push_back(trial_point(res.x, res.jacobian, rv, free, lambdas.back(), lower, upper));
  }
  // Both steps projected onto the same point of the box's boundary: evaluated
  // once, the second lane given the first's result (the iteration goes on as
  // if both had run: a failure counts as 8 lambda tried).
  const bool same = points.size() == 2 && points[1] == points[0];
  const std::vector<std::vector<double>> run(points.begin(), same ? points.begin() + 1 : points.end());
  std::vector<char> ok;
  evaluate_residuals_parallel(r, run, rs, ok, static_cast<int>(run.size()));
  res.evaluations += static_cast<int>(run.size());
  if (same) {
    rs.push_back(rs.front());
    ok.push_back(ok.front());
  }
  Trial t;
  t.cost = res.cost;
  t.lambda = lambdas.back();
  t.x = points.back();
  std::size_t accepted = points.size();
  for (std::size_t i = 0; i < points.size(); ++i)
    if (ok[i] && rs[i].size() == res.residuals.size() && sum_sq(rs[i]) < t.cost) {
      t = Trial{true, lambdas[i], sum_sq(rs[i]), points[i], rs[i], {}, {}};
      accepted = i;
    }
  if (t.accepted && points.size() == 2) {
    const std::size_t other = 1 - accepted;
    if (ok[other] && rs[other].size() == res.residuals.size()) {
      t.other_x = points[other];
      t.other_residuals = rs[other];
    }
  }
  return t;
}

/// The secant through the accepted trial and the other lane's (one
/// parameter): false when there is no other point or it is the same.
bool secant_jacobian(const Trial& t, Eigen::MatrixXd& J) {
  if (t.x.size() != 1 || t.other_x.size() != 1) return false;
  const double dx = t.other_x[0] - t.x[0];
  if (!(std::abs(dx) > 1e-12)) return false;
  J = (as_vector(t.other_residuals) - as_vector(t.residuals)) / dx;
  return true;
}

}  // namespace

LevenbergMarquardtResult levenberg_marquardt(const ResidualFunction& r, const std::vector<double>& x0,
                                             const std::vector<double>& lower, const std::vector<double>& upper,
                                             const LevenbergMarquardtOptions& o) {
  // The first Jacobian's columns beside the start when there is a thread
  // for them and no chance the start alone ends the fit.
  const bool jacobian_with_start = o.accept_start_cost < 0.0 && thread_count(o.threads, 2) >= 2 &&
                                   1 + static_cast<int>(x0.size()) <= o.max_evaluations;
  LevenbergMarquardtResult res = start_point(r, x0, lower, upper, jacobian_with_start, o.fd_step,
                                             jacobian_with_start ? o.threads : 1);
  if (o.accept_start_cost >= 0.0 && res.cost <= o.accept_start_cost) {
    res.status = "start_accepted";
    return res;
  }
  const int lanes = thread_count(o.threads, 2) >= 2 ? 2 : 1;
  double lambda = o.initial_lambda;
  double fd_step = o.fd_step;
  int stalls = 0;
  // A stall with a coarse difference step may be the Jacobian's error across
  // a kink: refine the step and go on from the same point.
  bool need_jacobian = !jacobian_with_start;
  bool secant = false;  // the Jacobian in use is a secant (options.secant_jacobian)
  double cycle_start_cost = res.cost;
  auto refine = [&](const char* why) {
    if (fd_step / 10.0 < 0.999 * o.fd_step_min) {
      // At the finest step: another cycle from the coarse step while the last one paid
      // (none without a coarser step: it would go on at the step that just stalled).
      if (!(o.fd_step > o.fd_step_min) || !(res.cost < (1.0 - 10.0 * o.cost_tolerance) * cycle_start_cost)) {
        res.status = why;
        return false;
      }
      cycle_start_cost = res.cost;
      fd_step = o.fd_step * 10.0;
    }
    fd_step /= 10.0;
    lambda = o.initial_lambda;
    stalls = 0;
    need_jacobian = true;
    return true;
  };
  res.status = "max_iterations";
  for (res.iterations = 0; res.iterations < o.max_iterations; ++res.iterations) {
    if (need_jacobian) {
      if (res.evaluations + static_cast<int>(x0.size()) > o.max_evaluations) { res.status = "max_evaluations"; break; }
      res.jacobian = finite_difference_jacobian(r, res.x, res.residuals, lower, upper, fd_step, o.threads, &res.evaluations);
      need_jacobian = false;
      secant = false;
    }
    const Eigen::VectorXd rv = as_vector(res.residuals);
    const Eigen::VectorXd g = res.jacobian.transpose() * rv;
    const std::vector<int> free = free_parameters(res.x, g, lower, upper);
    if (free.empty()) { res.status = "at_bounds"; break; }
    if (g.norm() == 0.0) { res.status = "zero_gradient"; break; }
    Trial trial = try_steps(r, res, rv, free, lambda, lanes, lower, upper);
    if (!trial.accepted) {
      lambda = 8.0 * trial.lambda;
      if (secant) {  // the secant may have misled: a difference Jacobian before any verdict
        secant = false;
        need_jacobian = true;
        continue;
      }
      const bool stalled = lambda > 1e12 || max_abs_difference(trial.x, res.x) < o.step_tolerance;
      if (stalled && !refine(lambda > 1e12 ? "no_descent" : "step_tolerance")) break;
      continue;
    }
    const double step = max_abs_difference(trial.x, res.x);
    const double decrease = (res.cost - trial.cost) / std::max(res.cost, 1e-300);
    secant = o.secant_jacobian && secant_jacobian(trial, res.jacobian);
    need_jacobian = !secant;
    res.x = std::move(trial.x);
    res.residuals = std::move(trial.residuals);
    res.cost = trial.cost;
    lambda = std::max(1e-9, trial.lambda / 3.0);
    stalls = decrease < o.cost_tolerance ? stalls + 1 : 0;
    if ((stalls >= std::max(1, o.stalls_to_stop) && !refine("cost_tolerance")) || (step < o.step_tolerance && !refine("step_tolerance"))) {
      ++res.iterations;
      break;
    }
    if (res.evaluations >= o.max_evaluations) { res.status = "max_evaluations"; ++res.iterations; break; }
  }
  res.jacobian_at_x = !need_jacobian && !secant;
  return res;
}

}  // namespace puncture::validation
