// identifiability_report.hpp (internal to puncture_calibration): the
// identifiability report of a calibration (calibration.hpp, identifiability.hpp).
//
// In:  the whole-objective stage at the tuned values over every tuned
//      parameter, the parameters withheld before tuning (with the reason the
//      references cannot identify them), the options (difference step, threads).
// Out: per tuned parameter its sensitivity, standard error (in its unit) and
//      status; the correlation matrix and the pairs above 0.95; the withheld
//      ones as "not identifiable" with their reason.
// Status of a tuned parameter: "not identifiable" when the objective does
// not change with it (its Jacobian column below 1e-6 of the largest, e.g. a
// presliding length with no friction left); else "at a bound" when it ended
// within 0.1 % of a bound; else "not identifiable" when J^T J is singular in
// its direction or its standard error in x exceeds 1 (for x = ln p: a
// standard error above the value itself); else "identified".
#pragma once

#include <string>
#include <vector>

#include "calibration_parameters.hpp"
#include "stage_objective.hpp"

namespace puncture::validation::calibration_detail {

struct WithheldParameter {
  std::size_t layer;
  ParamKind kind;
  std::string reason;
};

IdentifiabilityReport identifiability_report(StageObjective& whole, const std::vector<WithheldParameter>& withheld,
                                             const CalibrationOptions& options);

}  // namespace puncture::validation::calibration_detail
