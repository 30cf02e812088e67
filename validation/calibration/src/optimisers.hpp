// optimisers.hpp (internal to puncture_calibration): the optimisers a stage
// can run on its StageObjective, from x0 (the stage parameters' x).
//
// Levenberg-Marquardt (the default): least squares on the stage's residual
// vector (levenberg_marquardt.hpp), Jacobian columns and trial points on
// CalibrationOptions::threads threads. Nelder-Mead and BOBYQA (NLopt) with
// restarts while a run improves by more than 1 %; simulated annealing (GSL)
// with a Nelder-Mead polish. Each returns a record of what it did; the best
// point is the objective's best_x().
#pragma once

#include <string>
#include <vector>

#include "stage_objective.hpp"

namespace puncture::validation::calibration_detail {

std::string run_stage(StageObjective& stage, const std::vector<double>& x0);


}  // namespace puncture::validation::calibration_detail
