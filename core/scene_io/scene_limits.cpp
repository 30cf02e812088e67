// scene_limits.cpp: see puncture/scene_limits.hpp.
#include "puncture/scene_limits.hpp"

#include <cmath>
#include <sstream>

#include "puncture/scene_io.hpp"

namespace puncture::scene_limits {

namespace {
constexpr double kMm = 1e-3;

std::string num(double x) {
  std::ostringstream s;
  s.precision(6);
  s << x;
  return s.str();
}

void check_text(const std::string& text, const std::string& file, const std::string& path) {
  if (text.size() > kMaxTextLength)
    throw SceneError(file, path, "too long (" + std::to_string(text.size()) + " characters; the limit is " +
                                     std::to_string(kMaxTextLength) + ")");
}

void check_length(double value_m, const std::string& file, const std::string& path) {
  if (value_m / kMm > kMaxLengthMm)
    throw SceneError(file, path, "must be <= " + num(kMaxLengthMm) + " mm (got " + num(value_m / kMm) + ")");
}
}  // namespace

double scripted_duration_s(const Insertion& in) {
  // Start height and target depth are vertical; the needle travels along its inclined axis (needle.hpp).
  const double travel = (in.start_height_m + in.target_depth_m) / std::cos(in.angle_deg * (M_PI / 180.0));
  return travel / in.speed_m_per_s + in.dwell_s + travel / in.withdrawal_speed_m_per_s;
}

double scripted_ticks(const Scene& scene) {
  return std::ceil(scripted_duration_s(scene.insertion) * scene.realtime.haptic_rate_Hz) + 1.0;
}

void check_scene_limits(const Scene& s, const std::string& file) {
  check_text(s.name, file, "/name");
  check_text(s.description, file, "/description");
  // The name becomes the default output folder out/<name>: it must be one
  // plain folder name.
  if (s.name.empty()) throw SceneError(file, "/name", "must not be empty");
  if (s.name[0] == '.' || s.name.find_first_of("/\\") != std::string::npos)
    throw SceneError(file, "/name", "must be a plain folder name (no '/', '\\\\', no leading '.'; got '" + s.name + "')");
  for (unsigned char c : s.name)
    if (c < 0x20) throw SceneError(file, "/name", "must not contain control characters");

  if (s.layers.size() > kMaxLayers)
    throw SceneError(file, "/layers", "at most " + std::to_string(kMaxLayers) + " layers (got " +
                                          std::to_string(s.layers.size()) + ")");
  check_length(s.sample.diameter_m, file, "/sample/diameter_mm");
  for (std::size_t i = 0; i < s.layers.size(); ++i) {
    const std::string p = "/layers/" + std::to_string(i);
    check_text(s.layers[i].name, file, p + "/name");
    check_text(s.layers[i].material.source, file, p + "/material/source");
    check_length(s.layers[i].thickness_m, file, p + "/thickness_mm");
  }
  check_length(s.insertion.start_height_m, file, "/insertion/start_height_mm");

  const RealtimeSettings& rt = s.realtime;
  if (rt.haptic_rate_Hz > kMaxHapticRateHz)
    throw SceneError(file, "/realtime/haptic_rate_Hz",
                     "must be <= " + num(kMaxHapticRateHz) + " Hz (got " + num(rt.haptic_rate_Hz) + ")");
  if (s.insertion.dwell_s > kMaxDurationS)
    throw SceneError(file, "/insertion/dwell_s", "must be <= " + num(kMaxDurationS) + " s (got " + num(s.insertion.dwell_s) + ")");
  const double duration = scripted_duration_s(s.insertion);
  if (duration > kMaxDurationS) {
    // Name the slower of the two speeds: that is what makes the run long.
    const bool withdrawal_slower = s.insertion.withdrawal_speed_m_per_s < s.insertion.speed_m_per_s;
    throw SceneError(file, withdrawal_slower ? "/insertion/withdrawal_speed_mm_per_s" : "/insertion/speed_mm_per_s",
                     "the scripted insertion (approach, insertion, dwell, withdrawal) would take " + num(duration) +
                         " s; the limit is " + num(kMaxDurationS) + " s (raise the speed or shorten the travel)");
  }
  const double ticks = scripted_ticks(s);
  const double product = ticks * static_cast<double>(s.layers.size() + 2);
  if (product > kMaxTickLayerProduct)
    throw SceneError(file, "/realtime/haptic_rate_Hz",
                     "the scripted insertion (" + num(duration) + " s) at " + num(rt.haptic_rate_Hz) + " Hz is " +
                         num(ticks) + " ticks with " + std::to_string(s.layers.size()) +
                         " layers; the limit is ticks x (layers + 2) <= " + num(kMaxTickLayerProduct) +
                         " (every tick is kept in memory and written to realtime_curve.csv): lower the rate or "
                         "shorten the insertion");
  if (s.effects.surface_output) {
    const double frames = std::floor(duration * rt.frame_rate_Hz) + 1.0;
    const double files = 2.0 * frames * static_cast<double>(s.layers.size());
    if (files > kMaxFrameFiles)
      throw SceneError(file, "/realtime/frame_rate_Hz",
                       "the surface output would write " + num(frames) + " frames x " +
                           std::to_string(s.layers.size()) + " layers = " + num(files) +
                           " VTK files (about " + num(files * 0.1) + " MB); the limit is " + num(kMaxFrameFiles) +
                           " files: lower frame_rate_Hz or leave surface_output out of the effects");
  }
}

}  // namespace puncture::scene_limits
