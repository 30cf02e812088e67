// stage_objective.hpp (internal to puncture_calibration): the objective of one
// calibration stage as a scalar (derivative-free optimisers) and as a
// residual vector (Levenberg-Marquardt).
//
// A StageObjective holds the stage's scene, parameters and term selection
// (one per reference). value_of(scene) runs the model against every
// reference and sums the selected terms (trajectory_objective.hpp);
// residuals_at(x) returns their residuals, laid out as at the stage's start
// point (set_layout): a term whose residual count differs at x (e.g. a cut
// whose end follows the model when the reference has no part columns) gives
// sqrt(contribution) in its first slot and zeros, so that the sum of squares
// is always the objective. residuals_at and value_of are const and may run
// concurrently; record() books an evaluation (count, best point, progress)
// under a lock.
#pragma once

#include <atomic>
#include <exception>
#include <limits>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "calibration_parameters.hpp"
#include "puncture/validation/calibration.hpp"

namespace puncture::validation::calibration_detail {

/// A calibration stopped by its progress callback (calibration.hpp): the
/// callback's exception, kept for calibrate() to rethrow.
class CalibrationStop {
 public:
  bool requested() const { return requested_; }
  void capture(std::exception_ptr error) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!error_) error_ = std::move(error);
    requested_ = true;
  }
  void rethrow_if_requested() const {
    if (requested_) std::rethrow_exception(error_);
  }

 private:
  std::atomic<bool> requested_{false};
  mutable std::mutex mutex_;
  std::exception_ptr error_;
};

struct StageInputs {
  const std::vector<ReferenceCurve>* references = nullptr;
  const std::vector<ReferenceEvents>* events = nullptr;
  const std::vector<LayerGeometry>* geometry = nullptr;
  const CalibrationOptions* options = nullptr;
  const SurfaceCache* cache = nullptr;
  const CalibrationProgressCallback* progress = nullptr;
  int* total_evaluations = nullptr;
  CalibrationStop* stop = nullptr;  ///< set when the progress callback threw
};

class StageObjective {
 public:
  StageObjective(const StageInputs& inputs, std::string name) : in_(inputs), name_(std::move(name)) {}
  StageObjective(const StageObjective& other);

  Scene scene;                           ///< current values (the parameters are overwritten per evaluation)
  std::vector<Parameter> parameters;
  std::vector<TermSelection> selection;  ///< per reference
  bool with_dwell = false;
  /// Model runs turn at min(reference's deepest, turn_depth_m) (a stage whose
  /// terms end above the reference's deepest sample); a run that then misses a
  /// puncture the reference has within the compared depths is repeated whole.
  double turn_depth_m = std::numeric_limits<double>::infinity();

  const std::string& name() const { return name_; }
  /// The calibration was stopped by its progress callback: evaluations fail at once.
  bool stopped() const { return in_.stop && in_.stop->requested(); }
  const StageInputs& inputs() const { return in_; }
  Scene scene_at(const double* x) const;
  /// Every reference's comparison of the model run of `s`.
  std::vector<TrajectoryComparison> compare(const Scene& s) const;
  /// The stage objective of `s` (kFailedObjective if not finite); throws if a run throws.
  double value_of(const Scene& s) const;
  /// Scalar objective at x, booked (NLopt, annealing).
  double evaluate(const double* x);
  /// Fixes the residual layout from the comparisons at x; false if x cannot be run.
  bool set_layout(const std::vector<double>& x);
  /// Residuals at x in the stage's layout, booked; false if the run fails.
  bool residuals_at(const std::vector<double>& x, std::vector<double>& r);
  /// Books one evaluation with objective f at x.
  void record(const double* x, double f);

  int evaluations() const { return evaluations_; }
  void add_evaluations(int n) { evaluations_ += n; }
  double best() const { return best_; }
  const std::vector<double>& best_x() const { return best_x_; }
  /// Adopts a better point found by a sub-stage (objective f at x in this stage's parameters).
  void offer(const std::vector<double>& x, double f);

 private:
  /// True if (f, x) beats the best so far: a lower f, or the same f at a
  /// lexicographically smaller x (call under mutex_, as record and offer do).
  bool better(double f, const std::vector<double>& x) const;
  StageInputs in_;
  std::string name_;
  std::vector<std::vector<std::pair<std::string, std::size_t>>> layout_;  ///< per reference: term label, residual count
  std::mutex mutex_;
  int evaluations_ = 0;
  double best_ = std::numeric_limits<double>::infinity();
  std::vector<double> best_x_;
};

}  // namespace puncture::validation::calibration_detail
