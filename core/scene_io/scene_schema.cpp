// scene_schema.cpp: the table of scene_schema.hpp. Ranges are the reader's
// own checks (scene_validation.cpp, and scene_limits.hpp's limits where they
// bound one field), in the file's units.
#include "puncture/scene_schema.hpp"

#include "puncture/insertion_angle.hpp"
#include "puncture/scene_limits.hpp"

namespace puncture {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

SceneFieldRange any() { return {}; }
SceneFieldRange above(double lo) { return {lo, kInf, true, false}; }
SceneFieldRange at_least(double lo) { return {lo, kInf, false, false}; }
/// [lo, hi], with either end open on request.
SceneFieldRange within(double lo, double hi, bool lo_open = false, bool hi_open = false) { return {lo, hi, lo_open, hi_open}; }

using T = SceneFieldType;
constexpr bool kRequired = true, kOptional = false, kFem = true, kRealtime = false, kWritten = true, kReadOnly = false;

/// The scene, its sample and its needle.
std::vector<SceneField> scene_and_needle_fields() {
  const double max_mm = scene_limits::kMaxLengthMm;
  return {
      {"/schema_version", T::Integer, "", kRequired, within(1, 1), kFem, kWritten},
      {"/name", T::String, "", kRequired, any(), kRealtime, kWritten},
      {"/description", T::String, "", kOptional, any(), kRealtime, kWritten},
      {"/sample/diameter_mm", T::Number, "mm", kRequired, within(0, max_mm, true), kFem, kWritten},
      {"/needle/radius_mm", T::Number, "mm", kRequired, above(0), kFem, kWritten},
      {"/needle/tip", T::String, "", kOptional, any(), kFem, kWritten},
      {"/needle/inner_radius_mm", T::Number, "mm", kOptional, any(), kFem, kWritten},
      {"/needle/tip_angle_deg", T::Number, "deg", kOptional, within(5, 60), kFem, kWritten},
  };
}

/// Each layer: thickness, density, force mesh.
std::vector<SceneField> layer_fields() {
  const double max_mm = scene_limits::kMaxLengthMm;
  return {
      {"/layers/*/name", T::String, "", kRequired, any(), kFem, kWritten},
      {"/layers/*/thickness_mm", T::Number, "mm", kRequired, within(0, max_mm, true), kFem, kWritten},
      {"/layers/*/density_kg_per_m3", T::Number, "kg/m^3", kOptional, above(0), kRealtime, kWritten},
      {"/layers/*/force_mesh/K_N_per_mm", T::Number, "N/mm", kRequired, above(0), kRealtime, kWritten},
      {"/layers/*/force_mesh/w", T::Integer, "", kRequired, within(1, 64), kRealtime, kWritten},
      {"/layers/*/force_mesh/L_mm", T::Number, "mm", kRequired, above(0), kRealtime, kWritten},
      {"/layers/*/force_mesh/surface_stiffness_N_per_mm", T::Number, "N/mm", kOptional, at_least(0), kRealtime, kWritten},
      {"/layers/*/force_mesh/deformed_threshold_mm", T::Number, "mm", kOptional, above(0), kRealtime, kWritten},
      {"/layers/*/force_mesh/node_damping_N_s_per_m", T::Number, "N s/m", kOptional, at_least(0), kRealtime, kWritten},
      {"/layers/*/force_mesh/surface_axial_stiffness_N_per_mm", T::Number, "N/mm", kOptional, at_least(0), kRealtime,
       kWritten},
      {"/layers/*/force_mesh/virtual_stiffening_mm", T::Number, "mm", kOptional, at_least(0), kRealtime, kWritten},
      {"/layers/*/damping_d_N_s_per_m2", T::Number, "N s/m^2", kRequired, at_least(0), kRealtime, kWritten},
      {"/layers/*/resumption_time_s", T::Number, "s", kOptional, above(0), kRealtime, kWritten},
      {"/layers/*/resumption_rate", T::Number, "", kOptional, within(0, 1, true), kRealtime, kReadOnly},
  };
}

/// Each layer's force law (breakthrough, cutting, friction, stiffening).
std::vector<SceneField> force_law_fields() {
  return {
      {"/layers/*/force_law/breakthrough/criterion", T::String, "", kRequired, any(), kRealtime, kWritten},
      {"/layers/*/force_law/breakthrough/critical_force_N", T::Number, "N", kRequired, within(0, 1e3, true), kRealtime,
       kWritten},
      {"/layers/*/force_law/breakthrough/critical_energy_mJ", T::Number, "mJ", kRequired, within(0, 1e6, true),
       kRealtime, kWritten},
      {"/layers/*/force_law/breakthrough/rate_exponent", T::Number, "", kOptional, within(0, 1), kRealtime, kWritten},
      {"/layers/*/force_law/breakthrough/reference_speed_mm_per_s", T::Number, "mm/s", kOptional,
       within(0, 1e4, true), kRealtime, kWritten},
      {"/layers/*/force_law/stiffening/law", T::String, "", kRequired, any(), kRealtime, kWritten},
      {"/layers/*/force_law/stiffening/quadratic_N_per_mm2", T::Number, "N/mm^2", kOptional, at_least(0), kRealtime,
       kWritten},
      {"/layers/*/force_law/stiffening/cubic_N_per_mm3", T::Number, "N/mm^3", kOptional, at_least(0), kRealtime,
       kWritten},
      {"/layers/*/force_law/stiffening/stiffness_N_per_mm", T::Number, "N/mm", kRequired, at_least(0), kRealtime,
       kWritten},
      {"/layers/*/force_law/stiffening/strain_scale_mm", T::Number, "mm", kRequired, above(0), kRealtime, kWritten},
      {"/layers/*/force_law/cutting_force_N", T::Number, "N", kOptional, within(0, 1e3), kRealtime, kWritten},
      {"/layers/*/force_law/cutting_rate/viscous_fraction", T::Number, "", kOptional, within(0, 1), kRealtime, kWritten},
      {"/layers/*/force_law/cutting_rate/reference_speed_mm_per_s", T::Number, "mm/s", kOptional, within(0, 1e4, true),
       kRealtime, kWritten},
      {"/layers/*/force_law/cutting_release_mm", T::Number, "mm", kOptional, above(0), kRealtime, kWritten},
      {"/layers/*/force_law/rupture_release_mm", T::Number, "mm", kOptional, within(0, 50), kRealtime, kWritten},
      {"/layers/*/force_law/rupture_release_rate/exponent", T::Number, "", kOptional, within(0, 1), kRealtime, kWritten},
      {"/layers/*/force_law/rupture_release_rate/reference_speed_mm_per_s", T::Number, "mm/s", kOptional,
       within(0, 1e4, true), kRealtime, kWritten},
      {"/layers/*/force_law/friction/dynamic_N_per_mm", T::Number, "N/mm", kRequired, at_least(0), kRealtime, kWritten},
      {"/layers/*/force_law/friction/static_N_per_mm", T::Number, "N/mm", kOptional, any(), kRealtime, kWritten},
      {"/layers/*/force_law/friction/velocity_band_mm_per_s", T::Number, "mm/s", kOptional, above(0), kRealtime,
       kWritten},
      {"/layers/*/force_law/friction/presliding_mm", T::Number, "mm", kOptional, at_least(0), kRealtime, kWritten},
      {"/layers/*/force_law/friction/pressure_relaxation", T::String, "", kOptional, any(), kRealtime, kWritten},
  };
}

/// Each layer's continuum material (the FEM's and the comparison models').
std::vector<SceneField> material_fields() {
  return {
      {"/layers/*/material/model", T::String, "", kOptional, any(), kFem, kWritten},
      {"/layers/*/material/youngs_modulus_kPa", T::Number, "kPa", kRequired, above(0), kFem, kWritten},
      {"/layers/*/material/poisson_ratio", T::Number, "", kRequired, within(-1, 0.5, true, true), kFem, kWritten},
      {"/layers/*/material/mooney_rivlin_c01_fraction", T::Number, "", kOptional, within(0, 1, false, true), kFem,
       kWritten},
      {"/layers/*/material/ogden_alpha", T::Number, "", kOptional, any(), kFem, kReadOnly},
      {"/layers/*/material/ogden_terms/*/mu_fraction", T::Number, "", kRequired, any(), kFem, kWritten},
      {"/layers/*/material/ogden_terms/*/alpha", T::Number, "", kRequired, any(), kFem, kWritten},
      {"/layers/*/material/veronda_westmann_gamma", T::Number, "", kOptional, within(0, 100, true), kFem, kWritten},
      {"/layers/*/material/viscoelastic/modulus", T::String, "", kRequired, any(), kFem, kWritten},
      {"/layers/*/material/viscoelastic/prony/*/g", T::Number, "", kRequired, within(0, 1, true, true), kFem, kWritten},
      {"/layers/*/material/viscoelastic/prony/*/tau_s", T::Number, "s", kRequired, within(1e-6, 1e6), kFem, kWritten},
      {"/layers/*/material/viscoelastic/source", T::String, "", kOptional, any(), kRealtime, kWritten},
      {"/layers/*/material/source", T::String, "", kOptional, any(), kRealtime, kWritten},
      {"/layers/*/puncture/criterion", T::String, "", kRequired, any(), kFem, kWritten},
      {"/layers/*/puncture/critical_force_N", T::Number, "N", kRequired, above(0), kFem, kWritten},
      {"/layers/*/puncture/critical_stretch", T::Number, "", kRequired, above(1), kFem, kWritten},
      {"/layers/*/puncture/toughness_J_per_m2", T::Number, "J/m^2", kRequired, within(0, 1e6, true), kFem, kWritten},
      {"/layers/*/puncture/cohesive_strength_kPa", T::Number, "kPa", kRequired, within(0, 1e6, true), kFem, kWritten},
      {"/layers/*/puncture/source", T::String, "", kOptional, any(), kRealtime, kWritten},
      {"/layers/*/shaft_friction/coefficient", T::Number, "", kRequired, within(0, 5), kFem, kWritten},
      {"/layers/*/shaft_friction/static_coefficient", T::Number, "", kOptional, within(-kInf, 5), kFem, kWritten},
      {"/layers/*/shaft_friction/source", T::String, "", kOptional, any(), kRealtime, kWritten},
  };
}

/// The insertion and the real-time loop.
std::vector<SceneField> insertion_and_realtime_fields() {
  const double max_mm = scene_limits::kMaxLengthMm;
  return {
      {"/insertion/start_height_mm", T::Number, "mm", kOptional, within(0, max_mm), kFem, kWritten},
      {"/insertion/speed_mm_per_s", T::Number, "mm/s", kRequired, within(0, 1e4, true), kFem, kWritten},
      {"/insertion/target_depth_mm", T::Number, "mm", kRequired, above(0), kFem, kWritten},
      {"/insertion/dwell_s", T::Number, "s", kOptional, within(0, scene_limits::kMaxDurationS), kFem, kWritten},
      {"/insertion/withdrawal_speed_mm_per_s", T::Number, "mm/s", kOptional, above(0), kFem, kWritten},
      {"/insertion/angle_deg", T::Number, "deg", kOptional, within(0, kMaxInsertionAngleDeg), kFem, kWritten},
      {"/insertion/azimuth_deg", T::Number, "deg", kOptional, within(0, 360, false, true), kFem, kWritten},

      {"/realtime/sh_degree", T::Integer, "", kOptional, within(2, 64), kRealtime, kWritten},
      {"/realtime/haptic_rate_Hz", T::Number, "Hz", kOptional, within(0, scene_limits::kMaxHapticRateHz, true),
       kRealtime, kWritten},
      {"/realtime/integrator", T::String, "", kOptional, any(), kRealtime, kWritten},
      {"/realtime/frame_rate_Hz", T::Number, "Hz", kOptional, above(0), kRealtime, kWritten},
  };
}

/// The FEM reference.
std::vector<SceneField> fem_fields() {
  return {
      {"/fem/geometry", T::String, "", kOptional, any(), kFem, kWritten},
      {"/fem/refinement", T::Integer, "", kOptional, within(0, 4), kFem, kWritten},
      {"/fem/element_degree", T::Integer, "", kOptional, within(1, 2), kFem, kWritten},
      {"/fem/load_step_mm", T::Number, "mm", kOptional, above(0), kFem, kWritten},
      {"/fem/max_newton_iterations", T::Integer, "", kOptional, at_least(1), kFem, kWritten},
      {"/fem/newton_tolerance", T::Number, "", kOptional, within(0, 1, true, true), kFem, kWritten},
      {"/fem/cohesive_viscosity_s", T::Number, "s", kOptional, within(0, 1), kFem, kWritten},
      {"/fem/stabilization_time_s", T::Number, "s", kOptional, within(0, 1), kFem, kWritten},
      {"/fem/mesh/elements_per_needle_radius", T::Integer, "", kOptional, within(2, 64), kFem, kWritten},
      {"/fem/mesh/min_elements_per_layer", T::Integer, "", kOptional, within(1, 200), kFem, kWritten},
      {"/fem/mesh/radial_growth", T::Number, "", kOptional, within(1, 2), kFem, kWritten},
      {"/fem/mesh/path_element_size_mm", T::Number, "mm", kOptional, within(0, 10, true), kFem, kWritten},
  };
}

/// The comparison models.
std::vector<SceneField> comparison_fields() {
  return {
      {"/comparison/mesh/kind", T::String, "", kOptional, any(), kRealtime, kWritten},
      {"/comparison/mesh/size_at_axis_mm", T::Number, "mm", kOptional, above(0), kRealtime, kWritten},
      {"/comparison/mesh/size_far_mm", T::Number, "mm", kOptional, any(), kRealtime, kWritten},
      {"/comparison/mesh/grading", T::Number, "", kOptional, at_least(0), kRealtime, kWritten},
      {"/comparison/integrator", T::String, "", kOptional, any(), kRealtime, kWritten},
      {"/comparison/mass_spring_springs", T::String, "", kOptional, any(), kRealtime, kWritten},
      {"/comparison/relative_tolerance", T::Number, "", kOptional, within(0, 1, true, true), kRealtime, kWritten},
      {"/comparison/absolute_tolerance_mm", T::Number, "mm", kOptional, above(0), kRealtime, kWritten},
      {"/comparison/mass_damping_per_s", T::Number, "1/s", kOptional, at_least(0), kRealtime, kWritten},
      {"/comparison/stiffness_damping_s", T::Number, "s", kOptional, at_least(0), kRealtime, kWritten},
      {"/comparison/viscoelastic/prony_g", T::NumberList, "", kRequired, at_least(0), kRealtime, kWritten},
      {"/comparison/viscoelastic/prony_tau_s", T::NumberList, "s", kRequired, above(0), kRealtime, kWritten},
      {"/comparison/stiffness_scale", T::NumberList, "", kOptional, above(0), kRealtime, kWritten},
      {"/comparison/prescribed_puncture_depths_mm", T::NumberList, "mm", kOptional, above(0), kRealtime, kWritten},
      {"/comparison/mass_spring_stiffness_scale", T::NumberList, "", kOptional, above(0), kRealtime, kWritten},
  };
}

/// Effects and haptics.
std::vector<SceneField> effects_and_haptics_fields() {
  return {
      {"/effects", T::StringList, "", kOptional, any(), kRealtime, kWritten},
      {"/haptics/max_force_N", T::Number, "N", kOptional, above(0), kRealtime, kWritten},
      {"/haptics/max_force_rate_N_per_s", T::Number, "N/s", kOptional, above(0), kRealtime, kWritten},
      {"/haptics/device_damping_N_s_per_m", T::Number, "N s/m", kOptional, at_least(0), kRealtime, kWritten},
      {"/haptics/device_max_stiffness_N_per_mm", T::Number, "N/mm", kOptional, above(0), kRealtime, kWritten},
  };
}

std::vector<SceneField> table() {
  std::vector<SceneField> all;
  for (const auto& part : {scene_and_needle_fields(), layer_fields(), force_law_fields(), material_fields(),
                           insertion_and_realtime_fields(), fem_fields(), comparison_fields(),
                           effects_and_haptics_fields()})
    all.insert(all.end(), part.begin(), part.end());
  return all;
}

}  // namespace

const std::vector<SceneField>& scene_schema() {
  static const std::vector<SceneField> fields = table();
  return fields;
}

}  // namespace puncture
