// The calibration's method names and what a reference's metadata says about
// it (calibration.hpp), apart from the calibration itself.
#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "puncture/validation/calibration.hpp"

namespace puncture::validation {

CalibrationMethod parse_calibration_method(const std::string& name) {
  if (name == "levenberg_marquardt") return CalibrationMethod::LevenbergMarquardt;
  if (name == "bobyqa") return CalibrationMethod::Bobyqa;
  if (name == "nelder_mead") return CalibrationMethod::NelderMead;
  if (name == "simulated_annealing") return CalibrationMethod::SimulatedAnnealing;
  throw std::invalid_argument("unknown calibration method '" + name +
                              "' (expected levenberg_marquardt, bobyqa, nelder_mead or simulated_annealing)");
}

const char* to_string(CalibrationMethod method) {
  switch (method) {
    case CalibrationMethod::LevenbergMarquardt: return "levenberg_marquardt";
    case CalibrationMethod::Bobyqa: return "bobyqa";
    case CalibrationMethod::NelderMead: return "nelder_mead";
    case CalibrationMethod::SimulatedAnnealing: return "simulated_annealing";
  }
  return "unknown";
}

bool reference_is_quasi_static(const ReferenceCurve& reference) {
  if (reference_is_rate_dependent(reference.curve)) return false;
  if (reference.kind == "fem") return true;
  const auto it = reference.curve.metadata.find("quasi_static");
  return it != reference.curve.metadata.end() && (it->second == "true" || it->second == "yes" || it->second == "1");
}

bool reference_is_rate_dependent(const InsertionCurve& curve) {
  const auto it = curve.metadata.find("rate_dependent");
  if (it == curve.metadata.end()) return false;
  std::string v = it->second;
  std::transform(v.begin(), v.end(), v.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return v == "true" || v == "yes" || v == "1";
}

}  // namespace puncture::validation
