// scene_writer.cpp: a Scene back to the file schema (scene_to_json_text,
// scene_io.hpp), mm where the key says so; parse_scene of the text
// reproduces the scene.
#include <nlohmann/json.hpp>

#include "puncture/scene_io.hpp"
#include "scene_fields.hpp"

namespace puncture {
namespace {

using json = nlohmann::json;
using detail::kMm;

json viscoelastic_json(const Viscoelasticity& v) {
  json terms = json::array();
  for (const PronyRelaxationTerm& t : v.terms) terms.push_back({{"g", t.g}, {"tau_s", t.tau_s}});
  return {{"prony", terms},
          {"modulus", v.modulus_basis == Viscoelasticity::ModulusBasis::Instantaneous ? "instantaneous" : "long_term"},
          {"source", v.source}};
}

json force_law_json(const ForceLaw& law) {
  json j;
  const BreakthroughCriterion& b = law.breakthrough;
  switch (b.kind) {
    case BreakthroughCriterion::Kind::Rings: j["breakthrough"] = {{"criterion", "rings"}}; break;
    case BreakthroughCriterion::Kind::CriticalForce:
      j["breakthrough"] = {{"criterion", "critical_force"}, {"critical_force_N", b.critical_force_N}};
      break;
    case BreakthroughCriterion::Kind::CriticalEnergy:
      j["breakthrough"] = {{"criterion", "critical_energy"}, {"critical_energy_mJ", b.critical_energy_J * 1e3}};
      break;
  }
  if (b.kind != BreakthroughCriterion::Kind::Rings && b.rate_exponent != 0.0) {  // written when used
    j["breakthrough"]["rate_exponent"] = b.rate_exponent;
    j["breakthrough"]["reference_speed_mm_per_s"] = b.reference_speed_m_per_s / kMm;
  }
  const StiffeningLaw& st = law.stiffening;
  if (st.kind == StiffeningLaw::Kind::Polynomial)
    j["stiffening"] = {{"law", "polynomial"},
                       {"quadratic_N_per_mm2", st.quadratic_N_per_m2 / 1e6},
                       {"cubic_N_per_mm3", st.cubic_N_per_m3 / 1e9}};
  else
    j["stiffening"] = {{"law", "exponential"},
                       {"stiffness_N_per_mm", st.exponential_stiffness_N_per_m * kMm},
                       {"strain_scale_mm", st.strain_scale_m / kMm}};
  j["cutting_force_N"] = law.cutting_force_N;
  if (law.cutting_rate.viscous_fraction != 0.0)  // written when used
    j["cutting_rate"] = {{"viscous_fraction", law.cutting_rate.viscous_fraction},
                         {"reference_speed_mm_per_s", law.cutting_rate.reference_speed_m_per_s / kMm}};
  j["cutting_release_mm"] = law.cutting_release_m / kMm;
  j["rupture_release_mm"] = law.rupture_release_m / kMm;
  if (law.rupture_release_rate.exponent != 0.0)  // written when used
    j["rupture_release_rate"] = {{"exponent", law.rupture_release_rate.exponent},
                                 {"reference_speed_mm_per_s", law.rupture_release_rate.reference_speed_m_per_s / kMm}};
  j["friction"] = {{"static_N_per_mm", law.friction.static_N_per_m * kMm},
                   {"dynamic_N_per_mm", law.friction.dynamic_N_per_m * kMm},
                   {"velocity_band_mm_per_s", law.friction.velocity_band_m_per_s / kMm},
                   {"presliding_mm", law.friction.presliding_m / kMm}};
  if (law.friction.pressure_relaxes_with_material) j["friction"]["pressure_relaxation"] = "layer_material";  // written when used
  return j;
}

json force_mesh_json(const ForceMeshParams& fm) {
  json j = {{"K_N_per_mm", fm.virtual_stiffness_N_per_m * kMm},
            {"w", fm.rings_w},
            {"L_mm", fm.spacing_L_m / kMm},
            {"surface_stiffness_N_per_mm", fm.surface_stiffness_N_per_m * kMm},
            {"deformed_threshold_mm", fm.deformed_threshold_m / kMm},
            {"node_damping_N_s_per_m", fm.node_damping_N_s_per_m}};
  // The stiffening of the mesh is written only when on (a linear mesh's file stays as it was).
  if (fm.surface_axial_stiffness_N_per_m > 0.0) j["surface_axial_stiffness_N_per_mm"] = fm.surface_axial_stiffness_N_per_m * kMm;
  if (fm.virtual_stiffening_m > 0.0) j["virtual_stiffening_mm"] = fm.virtual_stiffening_m / kMm;
  return j;
}

json material_json(const ContinuumMaterial& m) {
  json j = {{"model", m.model},
            {"youngs_modulus_kPa", m.youngs_modulus_Pa / 1e3},
            {"poisson_ratio", m.poisson_ratio},
            {"mooney_rivlin_c01_fraction", m.mooney_rivlin_c01_fraction},
            {"veronda_westmann_gamma", m.veronda_westmann_gamma},
            {"source", m.source}};
  if (!m.ogden_terms.empty()) {
    json terms = json::array();
    for (const OgdenTerm& t : m.ogden_terms) terms.push_back({{"mu_fraction", t.mu_fraction}, {"alpha", t.alpha}});
    j["ogden_terms"] = terms;
  }
  if (m.viscoelastic.enabled()) j["viscoelastic"] = viscoelastic_json(m.viscoelastic);
  return j;
}

json puncture_json(const PunctureCriterion& c) {
  json j;
  if (c.kind == PunctureCriterion::Kind::CriticalForce)
    j = {{"criterion", "critical_force"}, {"critical_force_N", c.critical_force_N}};
  else if (c.kind == PunctureCriterion::Kind::CriticalStretch)
    j = {{"criterion", "critical_stretch"}, {"critical_stretch", c.critical_stretch}};
  else
    j = {{"criterion", "fracture_energy"},
         {"toughness_J_per_m2", c.toughness_J_per_m2},
         {"cohesive_strength_kPa", c.cohesive_strength_Pa / 1e3}};
  j["source"] = c.source;
  return j;
}

json layer_json(const Layer& l) {
  json j;
  j["name"] = l.name;
  j["thickness_mm"] = l.thickness_m / kMm;
  j["density_kg_per_m3"] = l.density_kg_per_m3;
  j["force_mesh"] = force_mesh_json(l.force_mesh);
  j["damping_d_N_s_per_m2"] = l.damping_N_s_per_m2;
  j["resumption_time_s"] = l.resumption_time_s;
  j["force_law"] = force_law_json(l.force_law);
  j["material"] = material_json(l.material);
  j["puncture"] = puncture_json(l.puncture);
  j["shaft_friction"] = {{"coefficient", l.shaft_friction.dynamic_coefficient},
                         {"static_coefficient", l.shaft_friction.static_coefficient},
                         {"source", l.shaft_friction.source}};
  return j;
}

json fem_json(const FemSettings& f) {
  return {{"geometry", f.geometry},
          {"refinement", f.refinement},
          {"element_degree", f.element_degree},
          {"load_step_mm", f.load_step_m / kMm},
          {"max_newton_iterations", f.max_newton_iterations},
          {"newton_tolerance", f.newton_tolerance},
          {"cohesive_viscosity_s", f.cohesive_viscosity_s},
          {"stabilization_time_s", f.stabilization_time_s},
          {"mesh",
           {{"elements_per_needle_radius", f.mesh.elements_per_needle_radius},
            {"min_elements_per_layer", f.mesh.min_elements_per_layer},
            {"radial_growth", f.mesh.radial_growth},
            {"path_element_size_mm", f.mesh.path_element_size_mm}}}};
}

json effects_json(const Effects& e) {
  json effects = json::array();
  if (e.surface_force) effects.push_back("surface_force");
  if (e.damping) effects.push_back("damping");
  if (e.resumption) effects.push_back("resumption");
  if (e.surface_output) effects.push_back("surface_output");
  if (e.cutting) effects.push_back("cutting");
  if (e.friction) effects.push_back("friction");
  if (e.stiffening) effects.push_back("stiffening");
  if (e.layer_interaction) effects.push_back("layer_interaction");
  if (e.coupled_surfaces) effects.push_back("coupled_surfaces");
  return effects;
}

json comparison_json(const ComparisonSettings& c) {
  json comparison = {{"mesh",
                      {{"kind", c.mesh.kind},
                       {"size_at_axis_mm", c.mesh.size_at_axis_m / kMm},
                       {"size_far_mm", c.mesh.size_far_m / kMm},
                       {"grading", c.mesh.grading}}},
                     {"integrator", c.integrator},
                     {"relative_tolerance", c.relative_tolerance},
                     {"absolute_tolerance_mm", c.absolute_tolerance_m / kMm},
                     {"mass_damping_per_s", c.mass_damping_per_s},
                     {"stiffness_damping_s", c.stiffness_damping_s},
                     {"viscoelastic", {{"prony_g", c.prony_g}, {"prony_tau_s", c.prony_tau_s}}}};
  if (!c.stiffness_scale.empty()) comparison["stiffness_scale"] = c.stiffness_scale;
  if (!c.prescribed_puncture_depths_m.empty()) {
    std::vector<double> mm;
    for (double d : c.prescribed_puncture_depths_m) mm.push_back(d / kMm);
    comparison["prescribed_puncture_depths_mm"] = mm;
  }
  if (!c.mass_spring_stiffness_scale.empty()) comparison["mass_spring_stiffness_scale"] = c.mass_spring_stiffness_scale;
  if (c.mass_spring_springs != "linear")  // the default is not written
    comparison["mass_spring_springs"] = c.mass_spring_springs;
  return comparison;
}

}  // namespace

std::string scene_to_json_text(const Scene& s) {
  json root;
  root["schema_version"] = detail::kSchemaVersion;
  root["name"] = s.name;
  root["description"] = s.description;
  root["sample"] = {{"diameter_mm", s.sample.diameter_m / kMm}};
  root["needle"] = {{"radius_mm", s.needle.radius_m / kMm},
                    {"tip", s.needle.tip},
                    {"inner_radius_mm", s.needle.inner_radius_m / kMm},
                    {"tip_angle_deg", s.needle.tip_angle_deg}};
  json layers = json::array();
  for (const Layer& l : s.layers) layers.push_back(layer_json(l));
  root["layers"] = layers;
  const Insertion& in = s.insertion;
  root["insertion"] = {{"start_height_mm", in.start_height_m / kMm},
                       {"speed_mm_per_s", in.speed_m_per_s / kMm},
                       {"target_depth_mm", in.target_depth_m / kMm},
                       {"dwell_s", in.dwell_s},
                       {"withdrawal_speed_mm_per_s", in.withdrawal_speed_m_per_s / kMm},
                       {"angle_deg", in.angle_deg},
                       {"azimuth_deg", in.azimuth_deg}};
  root["realtime"] = {{"sh_degree", s.realtime.sh_degree},
                      {"haptic_rate_Hz", s.realtime.haptic_rate_Hz},
                      {"integrator", s.realtime.integrator},
                      {"frame_rate_Hz", s.realtime.frame_rate_Hz}};
  root["fem"] = fem_json(s.fem);
  root["effects"] = effects_json(s.effects);
  root["haptics"] = {{"max_force_N", s.haptics.max_force_N},
                     {"max_force_rate_N_per_s", s.haptics.max_force_rate_N_per_s},
                     {"device_damping_N_s_per_m", s.haptics.device_damping_N_s_per_m},
                     {"device_max_stiffness_N_per_mm", s.haptics.device_max_stiffness_N_per_m * kMm}};
  root["comparison"] = comparison_json(s.comparison);
  return root.dump(2) + "\n";
}

}  // namespace puncture
