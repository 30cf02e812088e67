// levenberg_marquardt.hpp: bounded nonlinear least squares, min_x sum_i r_i(x)^2
// with lower <= x <= upper, by Levenberg-Marquardt with forward-difference
// Jacobians evaluated in parallel.
//
// In:  ResidualFunction r(x) -> residual vector (size m, the same for every
//      x; returns false when x cannot be evaluated, e.g. a simulation that
//      throws), x0 and the box (size n each), LevenbergMarquardtOptions. The
//      function is called from several threads at once: it must not share
//      mutable state.
// Out: LevenbergMarquardtResult: the best x found, its residuals and cost
//      (sum r^2), the last Jacobian computed (m x n, forward differences;
//      jacobian_at_x says whether at the returned x), and what stopped the
//      iteration.
//
// Method (Nielsen's damping, Marquardt's scaling): at x, J by forward
// differences of step fd_step in x (backward where x + h leaves the box),
// the columns evaluated concurrently on `threads` threads (the first
// Jacobian's together with the start when there are two or more threads and
// accept_start_cost is not set). A step solves
// (J^T J + lambda D) dx = -J^T r, D = diag(J^T J) with a floor, over the free
// parameters: those not at a bound with the gradient pushing them out (an
// active set); the trial point is projected into the box. With two or more
// threads two trial points (lambda and 8 lambda) are evaluated together and
// the better one kept. A trial that lowers the cost is accepted and lambda
// shrinks; otherwise lambda grows and the same Jacobian is reused (with
// secant_jacobian, one parameter: the next Jacobian is the secant through the
// two trial points, and a failed trial on it gets a forward difference).
// Stalls when the relative cost decrease of an accepted step is below
// cost_tolerance stalls_to_stop times in a row (twice by default), the step
// is below step_tolerance (max |dx|), or lambda exceeds 1e12 (no descent direction: a kink or a flat
// valley). On a stall the difference step is divided by 10 (the Jacobian of
// a piecewise smooth objective across a kink misleads at a coarse step) and
// the iteration goes on from the same point, while the step stays at or
// above fd_step_min; at the finest step, a new cycle starts from fd_step if
// fd_step is coarser and the last cycle lowered the cost by more than
// 10 cost_tolerance; else it stops (with fd_step == fd_step_min at the first
// stall), as it does when the iteration or evaluation budget is used up.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace puncture::validation {

using ResidualFunction = std::function<bool(const std::vector<double>& x, std::vector<double>& residuals)>;

struct LevenbergMarquardtOptions {
  int max_iterations = 40;
  int max_evaluations = 2000;      ///< residual evaluations, Jacobian columns included
  double fd_step = 1e-2;           ///< forward-difference step in x (x = ln p: 1 % of p)
  double fd_step_min = 1e-2;       ///< on a stall the step is divided by 10 while it stays >= this
  double initial_lambda = 1e-2;    ///< relative to diag(J^T J)
  double cost_tolerance = 1e-4;    ///< relative decrease of an accepted step counted as stalling
  double step_tolerance = 1e-6;    ///< max |dx| below which the iteration stops
  /// Accepted steps in a row below cost_tolerance that make a stall. Two by
  /// default (one small decrease may be a step along a flat stretch); one
  /// where each evaluation is a long simulation and a fit converged within
  /// cost_tolerance is all the caller needs (the comparison's factor fits).
  int stalls_to_stop = 2;
  /// One parameter, two lanes: after an accepted trial the Jacobian is the
  /// secant through the iteration's two trial points (evaluated together)
  /// instead of a forward difference at the new point (one evaluation alone,
  /// the other lane idle); a trial that fails on a secant gets a forward
  /// difference before lambda is judged. For fits whose evaluations are long
  /// simulations (the comparison's factor fits).
  bool secant_jacobian = false;
  int threads = 0;                 ///< 0: std::thread::hardware_concurrency()
  /// When >= 0 and the cost at x0 is at most this, x0 is returned after its
  /// one evaluation (status "start_accepted"): a caller that knows what cost
  /// is good enough saves the Jacobian's evaluations.
  double accept_start_cost = -1.0;
};

struct LevenbergMarquardtResult {
  std::vector<double> x;
  std::vector<double> residuals;
  double cost = 0.0;               ///< sum of squared residuals at x
  double initial_cost = 0.0;
  Eigen::MatrixXd jacobian;        ///< d r / d x at the last point where one was computed; empty if none
  bool jacobian_at_x = false;      ///< true if that point is the returned x
  int iterations = 0;
  int evaluations = 0;
  std::string status;              ///< why it stopped
};

/// Evaluates r at every point of `points` on up to `threads` threads (0:
/// hardware concurrency). ok[i] is false where r returned false or threw.
void evaluate_residuals_parallel(const ResidualFunction& r, const std::vector<std::vector<double>>& points,
                                 std::vector<std::vector<double>>& residuals, std::vector<char>& ok, int threads);

/// Forward-difference Jacobian of r at x (r0 = r(x)), step h per coordinate
/// (backward where x + h > upper, towards the farther bound in a box
/// narrower than h); a column whose evaluation fails, or whose
/// residual vector changes size, is zero. Adds the evaluations made.
Eigen::MatrixXd finite_difference_jacobian(const ResidualFunction& r, const std::vector<double>& x,
                                           const std::vector<double>& r0, const std::vector<double>& lower,
                                           const std::vector<double>& upper, double h, int threads,
                                           int* evaluations = nullptr);

/// Throws std::invalid_argument for mismatched sizes, an empty box, or an x0
/// at which r cannot be evaluated.
LevenbergMarquardtResult levenberg_marquardt(const ResidualFunction& r, const std::vector<double>& x0,
                                             const std::vector<double>& lower, const std::vector<double>& upper,
                                             const LevenbergMarquardtOptions& options = {});

}  // namespace puncture::validation
