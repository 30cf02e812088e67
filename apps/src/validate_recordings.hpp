// validate_recordings.hpp: `puncture validate --reference REC ...` (internal
// to puncture_app_lib): the scene's real-time model judged against measured
// recordings instead of the FEM reference.
//
// In:  the validate options (references: measured curves or raw rig
//      recordings, read as `calibrate --reference` reads them, with the same
//      recording options), the scene file.
// Out: in the report folder (written whole or not at all):
//      recordings_validation.md  per recording: speed, force RMSE over its
//                                peak, the whole-trajectory objective, each
//                                layer's puncture found on the recording
//                                beside the model's; with two or more
//                                recordings of one condition, their scatter
//                                beside the model's error
//      recordings_validation.json the same numbers
//      recording_curves.csv      each recording and the model on its trajectory
//      repeat_scatter.csv        the repeats' band (two or more of one speed)
//      Returns the exit code (0; bad input throws, see command_errors.hpp).
#pragma once

#include <filesystem>
#include <ostream>

#include "puncture/apps/commands.hpp"

namespace puncture::apps {

int validate_recordings(const ValidateOptions& options, const std::filesystem::path& scene_path, std::ostream& out);

}  // namespace puncture::apps
