// measured_reference.hpp: a measured curve or raw rig recording read as the
// commands that take --reference read it (internal to puncture_app_lib;
// calibrate and validate).
//   read_measured_reference(path, recording): the curve (a raw recording
//     through its format), kind "measured", rate dependence assumed unless
//     its metadata says; its insertion phase checked (bad input names the file).
//   require_insertion_speeds(references): with two or more, each must carry
//     its own speed (UsageError naming the file otherwise).
#pragma once

#include <filesystem>
#include <vector>

#include "command_errors.hpp"
#include "puncture/validation/calibration.hpp"
#include "puncture/validation/recording.hpp"

namespace puncture::apps {

inline validation::ReferenceCurve read_measured_reference(const std::filesystem::path& path,
                                                          const validation::ReferenceRecordingOptions& recording) {
  validation::ReferenceCurve reference;
  reference.curve = validation::read_reference_recording(path, recording);
  reference.kind = "measured";
  auto& meta = reference.curve.metadata;
  if (!meta.count("rate_dependent") && !meta.count("quasi_static")) meta["rate_dependent"] = "true";
  validation::insertion_phase(reference.curve);  // bad input before any model run (names the file)
  return reference;
}

inline void require_insertion_speeds(const std::vector<const validation::ReferenceCurve*>& references) {
  if (references.size() < 2) return;
  double speed = 0.0;
  for (const validation::ReferenceCurve* r : references)
    if (r->kind == "measured" && !r->curve.metadata_number("speed_mm_per_s", speed))
      throw UsageError(r->curve.source + ": no insertion speed: with several recordings each needs its own (a raw "
                       "recording's stage gives it; a curve needs a '# speed_mm_per_s: V' line)");
}

}  // namespace puncture::apps
