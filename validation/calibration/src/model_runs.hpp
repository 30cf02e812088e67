// model_runs.hpp (internal to puncture_calibration): the real-time model runs
// the objective compares with a reference.
//
// objective_scene(current, reference, options, with_dwell, turn_depth_m): a
// copy of `current` that runs the reference's trajectory (its speed, its
// deepest depth or turn_depth_m if shallower, its dwell when with_dwell, its
// withdrawal speed), the options' integrator, no surface output, and a
// haptic rate raised so that one tick moves the needle at most
// options.objective_depth_step_m (calibration.hpp, "Model runs").
#pragma once

#include <limits>

#include "puncture/scene.hpp"
#include "puncture/validation/calibration.hpp"

namespace puncture::validation::calibration_detail {

/// Insertion speed of a reference (m/s): its metadata "speed_mm_per_s" if
/// present (std::invalid_argument if not > 0), else the scene's.
double reference_speed(const Scene& scene, const InsertionCurve& reference);

Scene objective_scene(const Scene& current, const ReferenceCurve& reference, const CalibrationOptions& options,
                      bool with_dwell, double turn_depth_m = std::numeric_limits<double>::infinity());

}  // namespace puncture::validation::calibration_detail
