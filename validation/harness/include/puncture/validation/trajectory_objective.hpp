// trajectory_objective.hpp: a model curve against a reference curve over the
// whole trajectory, term by term; what calibration minimises and what its
// report shows.
//
// In:  the model curve (a real-time run: states, parts, phases), the
//      reference (FEM, measured, synthetic), the reference's punctures
//      (puncture_events.hpp), the scene's layer geometry, weights and a term
//      selection (which layers, down to which depth).
// Out: TrajectoryComparison: one ObjectiveTerm per term; a term that cannot
//      be computed is marked unavailable ("n/a" in reports, never 0) with the
//      reason; the objective is sum weight x value^2 over available terms.
//
// Terms (values dimensionless; P = the reference's insertion peak |F|):
//   overall             RMSE of the force over the insertion / P
//   pressing <layer>    RMSE over the layer's pressing segment / P
//   puncture_force <l>  (model - reference puncture force) / reference puncture force
//   puncture_depth <l>  (model - reference puncture depth) / min(L, thickness)
//   missing_puncture <l> 1 if exactly one of the curves punctures the layer, else 0
//   after_puncture <l>  RMSE over the layer's after segment (cutting and friction) / P
//   withdrawal          RMSE over the reference's withdrawal samples (depth-aligned) / P
//   dwell               RMSE over the reference's dwell samples (aligned on the time since the dwell began) / P
//   tip_force, cutting_force, friction_force
//                       RMSE of each part over the insertion / P (both curves need the part columns)
// Force comparisons interpolate the model linearly at the reference's depths
// (insertion and withdrawal branches separately) or dwell times; reference
// samples sharing a depth with a neighbour (a force drop at one instant)
// are skipped. Warnings: a puncture depth error above the layer's L, a
// reference without any puncture, a puncture only one curve has.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "puncture/validation/metrics.hpp"
#include "puncture/validation/puncture_events.hpp"

namespace puncture::validation {

struct ObjectiveWeights {
  double overall_rmse = 1.0;
  double pressing = 1.0;
  double after_puncture = 1.0;
  double puncture_depth = 1.0;
  double puncture_force = 1.0;
  double missing_puncture = 1.0;
  double withdrawal = 1.0;
  double dwell = 1.0;
  double parts = 1.0;
};

struct ObjectiveTerm {
  std::string name;          ///< see the header comment
  std::string layer;         ///< empty for whole-curve terms
  bool available = false;    ///< false: n/a (note says why)
  double value = 0.0;        ///< dimensionless error
  double raw = 0.0;          ///< the error in N (forces) or m (depths)
  std::size_t samples = 0;   ///< reference samples compared
  double weight = 0.0;
  std::string note;
  /// Weighted residuals, sum of squares = contribution(): sqrt(weight) x
  /// value for a single-value term; for an RMSE term one per reference
  /// sample in its range, sqrt(weight / n) x error / P (0 where the model
  /// curve does not reach the sample). All 0 when unavailable. Their number
  /// depends on the reference and the selection only, so least-squares
  /// calibration sees a residual vector of fixed size.
  std::vector<double> residuals;
  double contribution() const { return available ? weight * value * value : 0.0; }
  std::string label() const { return layer.empty() ? name : name + " " + layer; }
};

/// Which terms enter (calibration stages select one layer and a depth range).
struct TermSelection {
  std::vector<std::size_t> layers;  ///< per-layer terms of these layers; empty = every layer
  double max_depth_m = std::numeric_limits<double>::infinity();  ///< insertion samples compared down to here
  bool whole_curve_terms = true;    ///< overall and parts
  bool withdrawal = true;
  double withdrawal_max_depth_m = std::numeric_limits<double>::infinity();
  bool dwell = true;
};

struct TrajectoryComparison {
  std::vector<ObjectiveTerm> terms;
  double objective = 0.0;
  double reference_peak_force_N = 0.0;
  std::vector<PunctureEventMetrics> model_punctures;  ///< per layer, from the model's states
  std::vector<std::string> warnings;
  /// The term, or nullptr.
  const ObjectiveTerm* term(const std::string& name, const std::string& layer = "") const;
  /// Every term's residuals in term order: sum of squares = objective.
  std::vector<double> residuals() const;
};

TrajectoryComparison compare_trajectory(const InsertionCurve& model, const InsertionCurve& reference,
                                        const ReferenceEvents& reference_events,
                                        const std::vector<LayerGeometry>& layers, const ObjectiveWeights& weights = {},
                                        const TermSelection& selection = {});

}  // namespace puncture::validation
