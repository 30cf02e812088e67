#include "puncture/validation/fem_reference_curve.hpp"
#include "puncture/validation/recording.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace puncture::validation {

namespace {

std::string number_text(double value) {
  std::ostringstream s;
  s.precision(12);
  s << value;
  return s.str();
}

}  // namespace

bool scene_is_viscoelastic(const Scene& scene) {
  for (const Layer& layer : scene.layers)
    if (!layer.material.viscoelastic.terms.empty()) return true;
  return false;
}

InsertionCurve fem_insertion_curve(const Scene& scene, const std::filesystem::path& fem_force_depth_csv) {
  InsertionCurve curve = read_insertion_curve(fem_force_depth_csv);
  curve.metadata["speed_mm_per_s"] = number_text(scene.insertion.speed_m_per_s * 1e3);
  curve.metadata["withdrawal_speed_mm_per_s"] = number_text(scene.insertion.withdrawal_speed_m_per_s * 1e3);
  if (scene_is_viscoelastic(scene)) {
    curve.metadata["rate_dependent"] = "true";
    curve.metadata.erase("quasi_static");
  } else {
    curve.metadata["quasi_static"] = "true";
    curve.metadata.erase("rate_dependent");
  }
  return curve;
}

Scene scene_at_insertion_speed(const Scene& scene, double speed_m_per_s) {
  if (!(speed_m_per_s > 0.0) || !std::isfinite(speed_m_per_s))
    throw std::invalid_argument("insertion speed must be finite and > 0 (got " + number_text(speed_m_per_s * 1e3) +
                                " mm/s)");
  Scene s = scene;
  s.insertion.speed_m_per_s = speed_m_per_s;
  s.insertion.withdrawal_speed_m_per_s = speed_m_per_s;
  s.name = scene.name + "_" + number_text(speed_m_per_s * 1e3) + "mm_per_s";
  return s;
}

}  // namespace puncture::validation
