// measured_reference.hpp: a measured curve or raw rig recording read as the
// commands that take --reference read it (internal to puncture_app_lib;
// calibrate and validate).
//   read_measured_reference(path, recording): the curve (a raw recording
//     through its format), kind "measured", rate dependence assumed unless
//     its metadata says; its insertion phase checked (bad input names the file).
//     A scene at an angle (needle.hpp): a raw recording's stage moves the
//     needle along its own axis, so its travel is the depth along the needle;
//     the curve's depths (vertical, as `puncture run` writes depth_mm) are the
//     travel times cos a. A curve's depth_mm is vertical at any angle.
//   require_insertion_speeds(references): with two or more, each must carry
//     its own speed (UsageError naming the file otherwise).
//   require_axial_for_fem(scene, file, what): the FEM reference and the
//     comparison models insert along the sample axis only; a scene at an angle
//     is refused before any FEM run (SceneError naming /insertion/angle_deg).
#pragma once

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "command_errors.hpp"
#include "puncture/needle.hpp"
#include "puncture/validation/calibration.hpp"
#include "puncture/validation/recording.hpp"

namespace puncture::apps {

inline validation::ReferenceCurve read_measured_reference(const std::filesystem::path& path,
                                                          const validation::ReferenceRecordingOptions& recording,
                                                          const Insertion& insertion) {
  validation::ReferenceCurve reference;
  reference.curve = validation::read_reference_recording(path, recording);
  reference.kind = "measured";
  auto& meta = reference.curve.metadata;
  if (insertion.angle_deg != 0.0 && meta.count("recording_format")) {
    const double cos_a = -insertion_direction(insertion).z();
    for (double& d : reference.curve.depth_m) d *= cos_a;
    std::ostringstream angle;
    angle << insertion.angle_deg;
    meta["stage_along_needle_at_angle_deg"] = angle.str();
  }
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

inline void require_axial_for_fem(const Scene& scene, const std::string& file, const std::string& what) {
  if (scene.insertion.angle_deg == 0.0) return;
  std::ostringstream msg;
  msg << scene.insertion.angle_deg << " deg: " << what
      << " inserts along the sample axis only (angle 0); the real-time model runs at any angle up to the limit "
         "(puncture run), and validate and calibrate take a recording of the inclined insertion (--reference)";
  throw SceneError(file, "/insertion/angle_deg", msg.str());
}

}  // namespace puncture::apps
