// identifiability.hpp: what a least-squares fit's Jacobian says about its
// parameters.
//
// In:  J (m x n), the residuals' derivatives at the optimum with respect to
//      the optimiser's coordinates x (x = ln p for scale parameters, so a
//      column is the change per relative change of p; x = p / s for the
//      others), and the residuals r (size m) there.
// Out: JacobianStatistics: per column the sensitivity |J_j| (2-norm), the
//      approximate standard error of x_j, sqrt(sigma^2 [(J^T J)^-1]_jj) with
//      sigma^2 = |r|^2 / max(m - n, 1) (Gauss-Newton covariance, e.g. Bates &
//      Watts 1988, ch. 2), infinite where J^T J is singular in a direction
//      the parameter takes part in (|V_jk| > 0.05 for a singular value below
//      1e-8 of the largest); the correlation matrix of that covariance (NaN
//      for a parameter with an infinite error), and the pairs above a
//      threshold.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

namespace puncture::validation {

struct CorrelatedPair {
  int first = 0, second = 0;
  double correlation = 0.0;
};

struct JacobianStatistics {
  Eigen::VectorXd sensitivity;     ///< |J_j|
  Eigen::VectorXd standard_error;  ///< of x_j; +inf where not determined
  Eigen::MatrixXd correlation;     ///< n x n
  std::vector<CorrelatedPair> correlated;  ///< |correlation| > threshold, first < second
  double residual_variance = 0.0;  ///< sigma^2
  int residuals = 0, parameters = 0;
};

JacobianStatistics jacobian_statistics(const Eigen::MatrixXd& J, const Eigen::VectorXd& r,
                                       double correlation_threshold = 0.95);

/// One tuned (or withheld) parameter in a calibration's identifiability report.
struct ParameterIdentifiability {
  std::string layer, name, unit;
  double value = 0.0;               ///< in unit
  double sensitivity = 0.0;         ///< |d residuals / d x|, x = ln p or p / scale
  double standard_error = 0.0;      ///< in unit (delta method: p x se_x for ln p); +inf: not determined
  std::string status;               ///< "identified", "at a bound" or "not identifiable"
  bool insensitive = false;         ///< tuned, and the objective does not change with it
  std::string reason;               ///< why, for the latter two
  /// Where the value lives in a layer of the tuned preset (JSON pointers
  /// relative to the layer, e.g. "/force_law/cutting_force_N"; the friction
  /// sets its dynamic and static coefficients).
  std::vector<std::string> preset_pointers;
};

struct IdentifiabilityReport {
  std::vector<ParameterIdentifiability> parameters;  ///< the tuned ones first, then those withheld
  Eigen::MatrixXd correlation;                       ///< of the tuned ones
  std::vector<std::pair<std::string, std::string>> correlated_names;  ///< "layer name" pairs above 0.95
  std::vector<double> correlated_values;
  double residual_variance = 0.0;
  int residuals = 0;
  std::string note;                                  ///< what the Jacobian is of
  bool available() const { return !parameters.empty(); }
};

}  // namespace puncture::validation
