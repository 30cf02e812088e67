// What is tuned, in which space, within which bounds (calibration_parameters.hpp).
#include "calibration_parameters.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace puncture::validation::calibration_detail {

double Parameter::x_of(double v) const { return log_space ? std::log(v) : v / scale; }
// Clamped into [value_lo, value_hi]: exp(ln hi) can round above hi, and a
// value one ulp outside the scene's limits fails its validation.
double Parameter::value_of(double x) const {
  return std::clamp(log_space ? std::exp(x) : x * scale, value_lo, value_hi);
}

ParamInfo info(ParamKind k) {
  switch (k) {
    case ParamKind::VirtualStiffness:
      return {"K", "N/mm", kMm, true, 0.0, "/force_mesh/K_N_per_mm"};
    case ParamKind::DeformedThreshold:
      return {"deformed_threshold", "mm", 1.0 / kMm, true, 0.0, "/force_mesh/deformed_threshold_mm"};
    case ParamKind::CriticalForce:
      return {"critical_force", "N", 1.0, true, 0.0, "/force_law/breakthrough/critical_force_N"};
    case ParamKind::CriticalEnergy:
      return {"critical_energy", "mJ", 1e3, true, 0.0, "/force_law/breakthrough/critical_energy_mJ"};
    case ParamKind::SurfaceStiffness:
      return {"surface_stiffness", "N/mm", kMm, true, 0.0, "/force_mesh/surface_stiffness_N_per_mm"};
    case ParamKind::Spacing:
      return {"L", "mm", 1.0 / kMm, true, 0.0, "/force_mesh/L_mm"};
    case ParamKind::Damping:
      return {"d", "N s/m^2", 1.0, true, 0.0, "/damping_d_N_s_per_m2"};
    case ParamKind::Cutting:
      return {"cutting_force", "N", 1.0, false, 0.1, "/force_law/cutting_force_N"};
    case ParamKind::Friction:
      return {"friction_dynamic", "N/mm", kMm, false, 1.0, "/force_law/friction/dynamic_N_per_mm"};
    case ParamKind::StiffeningQuadratic:
      return {"stiffening_quadratic", "N/mm^2", kMm * kMm, false, 1e4, "/force_law/stiffening/quadratic_N_per_mm2"};
    case ParamKind::StiffeningCubic:
      return {"stiffening_cubic", "N/mm^3", kMm * kMm * kMm, false, 1e6, "/force_law/stiffening/cubic_N_per_mm3"};
    case ParamKind::StiffeningExponential:
      return {"stiffening_exponential", "N/mm", kMm, false, 10.0, "/force_law/stiffening/stiffness_N_per_mm"};
    case ParamKind::Presliding:
      return {"friction_presliding", "mm", 1.0 / kMm, false, 1e-3, "/force_law/friction/presliding_mm"};
    case ParamKind::RuptureRelease:
      return {"rupture_release", "mm", 1.0 / kMm, true, 0.0, "/force_law/rupture_release_mm"};
    case ParamKind::BreakthroughRate:
      return {"breakthrough_rate_exponent", "-", 1.0, false, 0.1, "/force_law/breakthrough/rate_exponent"};
    case ParamKind::CuttingRate:
      return {"cutting_viscous_fraction", "-", 1.0, false, 0.1, "/force_law/cutting_rate/viscous_fraction"};
    case ParamKind::ReleaseRate:
      return {"rupture_release_rate_exponent", "-", 1.0, false, 0.1, "/force_law/rupture_release_rate/exponent"};
  }
  throw std::logic_error("info");
}

std::vector<std::string> preset_pointers(ParamKind k) {
  std::vector<std::string> pointers{info(k).preset_pointer};
  if (k == ParamKind::Friction) pointers.emplace_back("/force_law/friction/static_N_per_mm");  // set_param sets it too
  return pointers;
}

double& param_ref(Scene& s, std::size_t layer, ParamKind k) {
  Layer& l = s.layers[layer];
  switch (k) {
    case ParamKind::VirtualStiffness: return l.force_mesh.virtual_stiffness_N_per_m;
    case ParamKind::DeformedThreshold: return l.force_mesh.deformed_threshold_m;
    case ParamKind::CriticalForce: return l.force_law.breakthrough.critical_force_N;
    case ParamKind::CriticalEnergy: return l.force_law.breakthrough.critical_energy_J;
    case ParamKind::SurfaceStiffness: return l.force_mesh.surface_stiffness_N_per_m;
    case ParamKind::Spacing: return l.force_mesh.spacing_L_m;
    case ParamKind::Damping: return l.damping_N_s_per_m2;
    case ParamKind::Cutting: return l.force_law.cutting_force_N;
    case ParamKind::Friction: return l.force_law.friction.dynamic_N_per_m;
    case ParamKind::StiffeningQuadratic: return l.force_law.stiffening.quadratic_N_per_m2;
    case ParamKind::StiffeningCubic: return l.force_law.stiffening.cubic_N_per_m3;
    case ParamKind::StiffeningExponential: return l.force_law.stiffening.exponential_stiffness_N_per_m;
    case ParamKind::Presliding: return l.force_law.friction.presliding_m;
    case ParamKind::RuptureRelease: return l.force_law.rupture_release_m;
    case ParamKind::BreakthroughRate: return l.force_law.breakthrough.rate_exponent;
    case ParamKind::CuttingRate: return l.force_law.cutting_rate.viscous_fraction;
    case ParamKind::ReleaseRate: return l.force_law.rupture_release_rate.exponent;
  }
  throw std::logic_error("param_ref");
}
double param_value(const Scene& s, std::size_t layer, ParamKind k) { return param_ref(const_cast<Scene&>(s), layer, k); }

/// The release length's floor (m) and its number of haptic ticks (physical_range).
constexpr double kMinRuptureRelease_m = 1e-4;
constexpr double kRuptureReleaseTicks = 5.0;

/// Physical range of a parameter (SI); see calibration.hpp.
void physical_range(const Scene& s, std::size_t layer, ParamKind k, double& lo, double& hi) {
  const Layer& l = s.layers[layer];
  switch (k) {
    case ParamKind::VirtualStiffness: lo = 1e-2, hi = 1e6; return;                 // 1e-5 .. 1000 N/mm
    case ParamKind::DeformedThreshold: lo = 1e-6, hi = l.thickness_m; return;      // 1 um .. the layer thickness
    case ParamKind::CriticalForce: lo = 1e-4, hi = 50.0; return;                   // measured punctures: 0.5 mN .. 19 N
    case ParamKind::CriticalEnergy: lo = 1e-9, hi = 1.0; return;                   // G_c w t: 1 J/m^2 x 1 mm^2 .. 1e5 J/m^2 x 1 cm^2
    case ParamKind::SurfaceStiffness: lo = 1e-3, hi = 1e6; return;
    case ParamKind::Spacing: {
      lo = 1e-5;
      hi = l.force_mesh.rings_w > 1 ? 0.5 * s.sample.diameter_m / (l.force_mesh.rings_w - 1) : 0.5 * s.sample.diameter_m;
      return;
    }
    case ParamKind::Damping: lo = 1e-3, hi = 1e6; return;
    case ParamKind::Cutting: lo = 0.0, hi = 20.0; return;                          // G_c w: up to 1.6e4 J/m^2 x 1.27 mm
    case ParamKind::Friction: lo = 0.0, hi = 1e3; return;                          // 0 .. 1 N per mm of shaft
    case ParamKind::StiffeningQuadratic: lo = 0.0, hi = 1e9; return;               // 0 .. 1000 N/mm^2
    case ParamKind::StiffeningCubic: lo = 0.0, hi = 1e12; return;                  // 0 .. 1000 N/mm^3
    case ParamKind::StiffeningExponential: lo = 0.0, hi = 1e6; return;
    case ParamKind::Presliding: lo = 0.0, hi = 0.05; return;                       // 0 .. 50 mm of shaft travel
    case ParamKind::RuptureRelease: {
      // The release exp(-s / l) is applied once per haptic tick: a length
      // shorter than a few ticks' travel is a one-tick drop whose size is set
      // by the tick, not by the tissue (at 1 kHz and 10 mm/s a tick is 10 um:
      // l = 10 um keeps 37 % of R on the tick after the break, 82 % at the
      // calibration's 2 um steps). Lower bound: 5 ticks at the scene's
      // insertion speed and haptic rate, and never below 0.1 mm (5 ticks at
      // 20 mm/s, the fastest held-out speed; the FEM's shortest decay after a
      // break is 0.21 mm, at 1 mm/s). Upper: 50 mm (the scene's limit).
      const double tick_m = s.realtime.haptic_rate_Hz > 0.0 ? s.insertion.speed_m_per_s / s.realtime.haptic_rate_Hz : 0.0;
      lo = std::max(kMinRuptureRelease_m, kRuptureReleaseTicks * tick_m);
      hi = 0.05;
      return;
    }
    case ParamKind::BreakthroughRate: lo = 0.0, hi = 1.0; return;                  // n in [0, 1] (the scene's limit)
    case ParamKind::CuttingRate: lo = 0.0, hi = 1.0; return;                       // b in [0, 1]: a fraction of C
    case ParamKind::ReleaseRate: lo = 0.0, hi = 1.0; return;                       // m in [0, 1]: fixed travel .. fixed time
  }
}


void set_param(Scene& s, const Parameter& p, double value) {
  param_ref(s, p.layer, p.kind) = value;
  if (p.kind == ParamKind::Friction) s.layers[p.layer].force_law.friction.static_N_per_m = value * p.friction_ratio;
}

/// Bounds of a parameter from its start value (the scene's); the start is
/// moved inside when it lies outside (moved = true).
Parameter make_parameter(const Scene& start, std::size_t layer, ParamKind kind, double bound_factor, bool& moved) {
  const ParamInfo in = info(kind);
  double p0 = param_value(start, layer, kind);
  double lo = 0.0, hi = 0.0;
  physical_range(start, layer, kind, lo, hi);
  Parameter p{layer, kind, in.log_space};
  if (in.log_space) {
    if (!(p0 > 0.0) || !std::isfinite(p0))
      throw std::invalid_argument(std::string("calibrate: layer '") + start.layers[layer].name + "': parameter " +
                                  in.name + " must be > 0 to be tuned");
    const double q0 = std::clamp(p0, lo, hi);
    lo = std::max(lo, q0 / bound_factor);
    hi = std::min(hi, q0 * bound_factor);
  } else {
    if (!std::isfinite(p0)) throw std::invalid_argument("calibrate: non-finite start value");
    p.scale = std::max(std::abs(p0), in.typical);
  }
  moved = p0 < lo || p0 > hi;
  p.value_lo = lo;
  p.value_hi = hi;
  p.lower = p.log_space ? std::log(lo) : lo / p.scale;
  p.upper = p.log_space ? std::log(hi) : hi / p.scale;
  if (kind == ParamKind::Friction) {
    const ShaftFrictionLaw& f = start.layers[layer].force_law.friction;
    p.friction_ratio = f.dynamic_N_per_m > 0.0 ? f.static_N_per_m / f.dynamic_N_per_m : 1.0;
  }
  return p;
}

/// Why the references do not identify a parameter (reference_checks.hpp); "" when they do.
std::string unidentified_reason(const LayerIdentifiability& id, ParamKind kind) {
  const std::string fewer = "the reference has fewer than " + std::to_string(kMinIdentifyingSamples);
  switch (kind) {
    case ParamKind::CriticalForce: case ParamKind::CriticalEnergy:  // the puncture's depth and force set them
      return id.punctured ? "" : "the reference has no puncture of this layer";
    case ParamKind::DeformedThreshold:  // a ring deflection: read off the pressing curve
      return !id.punctured ? "the reference has no puncture of this layer"
             : id.pressing() ? "" : fewer + " pressing samples of this layer before its puncture";
    case ParamKind::Cutting: case ParamKind::Friction: case ParamKind::Presliding: case ParamKind::RuptureRelease:
      return id.cut() ? "" : fewer + " samples of the cut through this layer";
    case ParamKind::CuttingRate: case ParamKind::ReleaseRate:  // and by the speeds
      return id.cut() ? "" : fewer + " samples of the cut through this layer";
    case ParamKind::Damping: case ParamKind::BreakthroughRate: return "";  // decided by the references' speeds
    default: return id.pressing() ? "" : fewer + " pressing samples of this layer";
  }
}

bool has_breakthrough_rate(const Scene& scene, std::size_t k) {
  const BreakthroughCriterion::Kind kind = scene.layers[k].force_law.breakthrough.kind;
  return scene.effects.surface_force && kind != BreakthroughCriterion::Kind::Rings;
}

/// With `id`: only the parameters the references identify.
std::vector<ParamKind> layer_kinds(const Scene& scene, std::size_t k, const TunedParameterSet& t,
                                   const LayerIdentifiability* id) {
  std::vector<ParamKind> kinds;
  const Layer& l = scene.layers[k];
  const bool mesh_identified = std::find(t.mesh_identified_layers.begin(), t.mesh_identified_layers.end(), l.name) !=
                               t.mesh_identified_layers.end();
  if (t.virtual_stiffness && !mesh_identified && scene.effects.surface_force)
    kinds.push_back(ParamKind::VirtualStiffness);
  if (t.deformed_threshold && scene.effects.surface_force) {
    switch (l.force_law.breakthrough.kind) {
      case BreakthroughCriterion::Kind::Rings: kinds.push_back(ParamKind::DeformedThreshold); break;
      case BreakthroughCriterion::Kind::CriticalForce: kinds.push_back(ParamKind::CriticalForce); break;
      case BreakthroughCriterion::Kind::CriticalEnergy: kinds.push_back(ParamKind::CriticalEnergy); break;
    }
  }
  if (t.surface_stiffness && scene.effects.surface_force) kinds.push_back(ParamKind::SurfaceStiffness);
  if (t.spacing && scene.effects.surface_force) kinds.push_back(ParamKind::Spacing);
  if (t.stiffening && !mesh_identified && scene.effects.stiffening && scene.effects.surface_force) {
    if (l.force_law.stiffening.kind == StiffeningLaw::Kind::Polynomial) {
      // a2 and a3: a measured pre-puncture rise is often closer to z^3 than z^2
      // (the default FEM's skin: F(8 mm) / F(4 mm) = 9.3).
      kinds.push_back(ParamKind::StiffeningQuadratic);
      kinds.push_back(ParamKind::StiffeningCubic);
    } else {
      kinds.push_back(ParamKind::StiffeningExponential);
    }
  }
  if (t.cutting && scene.effects.cutting) {
    kinds.push_back(ParamKind::Cutting);
    // The rupture release is tuned when the scene uses it (a start > 0).
    if (l.force_law.rupture_release_m > 0.0) kinds.push_back(ParamKind::RuptureRelease);
  }
  if (t.friction && scene.effects.friction) {
    kinds.push_back(ParamKind::Friction);
    // Presliding is tuned when the scene uses it (a start > 0): the
    // withdrawal's reversal over the shaft travel identifies it.
    if (l.force_law.friction.presliding_m > 0.0) kinds.push_back(ParamKind::Presliding);
  }
  if (id) kinds.erase(std::remove_if(kinds.begin(), kinds.end(), [&](ParamKind kind) {
    return !unidentified_reason(*id, kind).empty(); }), kinds.end());
  return kinds;
}

std::vector<double> x_values(const Scene& s, const std::vector<Parameter>& params) {
  std::vector<double> x;
  for (const Parameter& p : params) x.push_back(std::clamp(p.x_of(param_value(s, p.layer, p.kind)), p.lower, p.upper));
  return x;
}

void clamp_into_bounds(Scene& s, const std::vector<Parameter>& params) {
  for (const Parameter& p : params)
    set_param(s, p, std::clamp(param_value(s, p.layer, p.kind), p.value_lo, p.value_hi));
}

std::string bound_name(const Parameter& p, double x) {
  const double span = p.upper - p.lower;
  if (!(span > 0.0)) return "lower";
  // Within 0.1 % of the span, but never farther than 0.1 % of the value's own
  // size: a linear-space parameter with a wide physical range (stiffening
  // 0..1000 N/mm^3) is not "at its bound" at 0.004 N/mm^3.
  const double tol = 1e-3 * std::min(span, std::max(1.0, std::abs(x)));
  if (x <= p.lower + tol) return "lower";
  if (x >= p.upper - tol) return "upper";
  return "";
}

TunedParameterRecord parameter_record(const Scene& start, const Scene& tuned, const Parameter& p, bool moved_inside) {
  const ParamInfo in = info(p.kind);
  TunedParameterRecord rec;
  rec.layer = start.layers[p.layer].name;
  rec.name = in.name;
  rec.unit = in.unit;
  rec.start = param_value(start, p.layer, p.kind) * in.to_unit;
  rec.tuned = param_value(tuned, p.layer, p.kind) * in.to_unit;
  rec.lower = p.value_lo * in.to_unit;
  rec.upper = p.value_hi * in.to_unit;
  rec.at_bound = bound_name(p, p.x_of(std::max(param_value(tuned, p.layer, p.kind), p.log_space ? 1e-300 : 0.0)));
  rec.start_moved_inside = moved_inside;
  return rec;
}

std::vector<std::size_t> selected_layers(const Scene& scene, const CalibrationOptions& options) {
  for (const std::string& name : options.layers) {
    bool found = false;
    for (const Layer& l : scene.layers) found = found || l.name == name;
    if (!found) throw std::invalid_argument("calibrate: the scene has no layer '" + name + "'");
  }
  std::vector<std::size_t> layers;
  for (std::size_t k = 0; k < scene.layers.size(); ++k)
    if (options.layers.empty() ||
        std::find(options.layers.begin(), options.layers.end(), scene.layers[k].name) != options.layers.end())
      layers.push_back(k);
  return layers;
}

}  // namespace puncture::validation::calibration_detail
