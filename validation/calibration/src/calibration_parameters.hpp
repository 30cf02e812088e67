// calibration_parameters.hpp (internal to puncture_calibration): what is
// tuned, in which space and within which bounds.
//
// ParamKind names a tunable parameter of a layer; info() its report name,
// unit and optimisation space; param_ref() where it lives in a Scene (SI);
// physical_range() its absolute physical bounds (calibration.hpp);
// make_parameter() the Parameter an optimiser sees: x = ln(value) for scale
// parameters, value / scale for the ones that may be 0, with bounds in x.
// layer_kinds() lists the parameters of layer k the options and the scene's
// effects call for; unidentified_reason() says why the references cannot
// identify one ("" when they can).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "puncture/scene.hpp"
#include "puncture/validation/calibration.hpp"
#include "puncture/validation/reference_checks.hpp"

namespace puncture::validation::calibration_detail {

constexpr double kMm = 1e-3;
constexpr int kMaxParameters = 32;

enum class ParamKind {
  VirtualStiffness,
  DeformedThreshold,
  CriticalForce,
  CriticalEnergy,
  SurfaceStiffness,
  Spacing,
  Damping,
  Cutting,
  Friction,
  StiffeningQuadratic,
  StiffeningCubic,
  StiffeningExponential,
  Presliding,
  RuptureRelease,
  BreakthroughRate,  ///< n of the breakthrough threshold's rate law (breakthrough_rate.hpp); tuned with d
  CuttingRate,       ///< b, the viscous fraction of the cutting force (cutting.hpp); tuned with d
  ReleaseRate        ///< m, the rate exponent of the rupture release length (cutting.hpp); tuned with d
};

struct ParamInfo {
  const char* name;
  const char* unit;     ///< unit of the reported values
  double to_unit;       ///< SI value x to_unit = reported value
  bool log_space;       ///< scale parameter (> 0), optimised in log space
  double typical;       ///< SI; linear-space parameters are optimised as value / max(|p0|, typical)
  const char* preset_pointer;  ///< its JSON pointer relative to a layer of a scene file
};

ParamInfo info(ParamKind k);
/// The JSON pointers (relative to a layer of a scene file) of what a parameter
/// sets: its own, and for the friction the static coefficient it sets too.
std::vector<std::string> preset_pointers(ParamKind k);
double& param_ref(Scene& s, std::size_t layer, ParamKind k);
double param_value(const Scene& s, std::size_t layer, ParamKind k);
/// Physical range of a parameter (SI); see calibration.hpp.
void physical_range(const Scene& s, std::size_t layer, ParamKind k, double& lo, double& hi);

struct Parameter {
  std::size_t layer;
  ParamKind kind;
  bool log_space;
  double scale = 1.0;             ///< linear space: x = value / scale
  double lower = 0.0, upper = 0.0;        ///< bounds in x
  double value_lo = 0.0, value_hi = 0.0;  ///< bounds in SI
  double friction_ratio = 1.0;    ///< static / dynamic friction kept while tuning the dynamic one
  double x_of(double v) const;
  double value_of(double x) const;
};

void set_param(Scene& s, const Parameter& p, double value);
/// Bounds of a parameter from its start value (the scene's); the start is
/// moved inside when it lies outside (moved = true).
Parameter make_parameter(const Scene& start, std::size_t layer, ParamKind kind, double bound_factor, bool& moved);
/// Why the references do not identify a parameter (reference_checks.hpp); "" when they do.
std::string unidentified_reason(const LayerIdentifiability& id, ParamKind kind);
/// True when layer k's breakthrough threshold has a rate law to tune (a
/// critical force or energy with the surface-force effect).
bool has_breakthrough_rate(const Scene& scene, std::size_t k);
/// The stage parameters of layer k the options and the scene's effects call
/// for; with `id`, only the ones the references identify.
std::vector<ParamKind> layer_kinds(const Scene& scene, std::size_t k, const TunedParameterSet& t,
                                   const LayerIdentifiability* id = nullptr);

/// The parameters' x of a scene (clamped into the bounds).
std::vector<double> x_values(const Scene& s, const std::vector<Parameter>& params);
void clamp_into_bounds(Scene& s, const std::vector<Parameter>& params);
/// "lower", "upper" or "" (x within 0.1 % of the span, and of its own size, of a bound).
std::string bound_name(const Parameter& p, double x);
/// The layers options.layers names (all when empty), top to bottom; std::invalid_argument for a name the scene lacks.
std::vector<std::size_t> selected_layers(const Scene& scene, const CalibrationOptions& options);
/// The result's record of a tuned parameter: start (in `start`) and tuned values, bounds, at a bound.
TunedParameterRecord parameter_record(const Scene& start, const Scene& tuned, const Parameter& p, bool moved_inside);

}  // namespace puncture::validation::calibration_detail
