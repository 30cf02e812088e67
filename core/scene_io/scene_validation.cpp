// scene_validation.cpp: the value and cross-field rules of a scene
// (validate_scene, scene_io.hpp), checked after reading and before writing.
// Each rule throws SceneError naming the file and the JSON path of the field,
// in the order the fields appear in a scene file.
#include <cctype>
#include <cmath>
#include <set>
#include <sstream>

#include "puncture/insertion_angle.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/scene_limits.hpp"
#include "scene_fields.hpp"

namespace puncture {
namespace {

using detail::kMm;
/// Largest rupture release length: a cohesive zone opens over millimetres, not centimetres.
constexpr double kMaxRuptureRelease_m = 50e-3;

/// Throws SceneError(file, path, "must be <rule> (got value)") unless ok.
void require(bool ok, const std::string& file, const std::string& path, const std::string& rule, double value) {
  if (ok) return;
  std::ostringstream msg;
  msg << "must be " << rule << " (got " << value << ")";
  throw SceneError(file, path, msg.str());
}

/// Prony terms: each g_i in (0, 1) and tau_i in [1e-6, 1e6] s; the g_i sum
/// to less than 1 (a solid keeps part of its stress at equilibrium).
void validate_viscoelastic(const Viscoelasticity& v, const std::string& file, const std::string& p) {
  double sum = 0.0;
  for (std::size_t i = 0; i < v.terms.size(); ++i) {
    const std::string tp = p + "/prony/" + std::to_string(i);
    require(v.terms[i].g > 0 && v.terms[i].g < 1, file, tp + "/g", "in (0, 1)", v.terms[i].g);
    require(v.terms[i].tau_s >= 1e-6 && v.terms[i].tau_s <= 1e6, file, tp + "/tau_s", "in [1e-6, 1e6] s",
            v.terms[i].tau_s);
    sum += v.terms[i].g;
  }
  require(sum < 0.99, file, p + "/prony",
          "g_i summing to less than 0.99 (the relaxed fraction 1 - sum g_i must stay above 1 %)", sum);
}

/// The layer's force_law object (every value is checked, used or not: a
/// scene that switches an effect on later must already be valid).
void validate_force_law(const ForceLaw& law, const std::string& file, const std::string& p, double thickness_m) {
  const BreakthroughCriterion& b = law.breakthrough;
  if (b.kind == BreakthroughCriterion::Kind::CriticalForce)
    require(b.critical_force_N > 0 && b.critical_force_N <= 1e3, file, p + "/breakthrough/critical_force_N",
            "in (0, 1000]", b.critical_force_N);
  if (b.kind == BreakthroughCriterion::Kind::CriticalEnergy)
    require(b.critical_energy_J > 0 && b.critical_energy_J <= 1e3, file, p + "/breakthrough/critical_energy_mJ",
            "in (0, 1e6]", b.critical_energy_J * 1e3);
  require(b.rate_exponent >= 0 && b.rate_exponent <= 1, file, p + "/breakthrough/rate_exponent", "in [0, 1]",
          b.rate_exponent);
  require(b.reference_speed_m_per_s > 0 && b.reference_speed_m_per_s <= 10.0, file,
          p + "/breakthrough/reference_speed_mm_per_s", "in (0, 10000]", b.reference_speed_m_per_s / kMm);
  const StiffeningLaw& st = law.stiffening;
  require(st.quadratic_N_per_m2 >= 0, file, p + "/stiffening/quadratic_N_per_mm2", ">= 0", st.quadratic_N_per_m2 * kMm * kMm);
  require(st.cubic_N_per_m3 >= 0, file, p + "/stiffening/cubic_N_per_mm3", ">= 0", st.cubic_N_per_m3 * kMm * kMm * kMm);
  require(st.exponential_stiffness_N_per_m >= 0, file, p + "/stiffening/stiffness_N_per_mm", ">= 0",
          st.exponential_stiffness_N_per_m * kMm);
  require(st.strain_scale_m > 0, file, p + "/stiffening/strain_scale_mm", "> 0", st.strain_scale_m / kMm);
  require(law.cutting_force_N >= 0 && law.cutting_force_N <= 1e3, file, p + "/cutting_force_N", "in [0, 1000]",
          law.cutting_force_N);
  require(law.cutting_rate.viscous_fraction >= 0 && law.cutting_rate.viscous_fraction <= 1, file,
          p + "/cutting_rate/viscous_fraction", "in [0, 1]", law.cutting_rate.viscous_fraction);
  require(law.cutting_rate.reference_speed_m_per_s > 0 && law.cutting_rate.reference_speed_m_per_s <= 10.0, file,
          p + "/cutting_rate/reference_speed_mm_per_s", "in (0, 10000]", law.cutting_rate.reference_speed_m_per_s / kMm);
  require(law.cutting_release_m > 0 && law.cutting_release_m <= thickness_m + 1e-3, file, p + "/cutting_release_mm",
          "> 0 and at most the layer thickness + 1 mm", law.cutting_release_m / kMm);
  require(law.rupture_release_m >= 0 && law.rupture_release_m <= kMaxRuptureRelease_m, file, p + "/rupture_release_mm",
          "in [0, 50]", law.rupture_release_m / kMm);
  require(law.rupture_release_rate.exponent >= 0 && law.rupture_release_rate.exponent <= 1, file,
          p + "/rupture_release_rate/exponent", "in [0, 1]", law.rupture_release_rate.exponent);
  require(law.rupture_release_rate.reference_speed_m_per_s > 0 && law.rupture_release_rate.reference_speed_m_per_s <= 10.0,
          file, p + "/rupture_release_rate/reference_speed_mm_per_s", "in (0, 10000]",
          law.rupture_release_rate.reference_speed_m_per_s / kMm);
  const ShaftFrictionLaw& f = law.friction;
  require(f.dynamic_N_per_m >= 0, file, p + "/friction/dynamic_N_per_mm", ">= 0", f.dynamic_N_per_m * kMm);
  require(f.static_N_per_m >= f.dynamic_N_per_m, file, p + "/friction/static_N_per_mm",
          ">= dynamic_N_per_mm (the shaft cannot stick with less force than it slides with)", f.static_N_per_m * kMm);
  require(f.velocity_band_m_per_s > 0, file, p + "/friction/velocity_band_mm_per_s", "> 0",
          f.velocity_band_m_per_s / kMm);
  require(f.presliding_m >= 0, file, p + "/friction/presliding_mm", ">= 0", f.presliding_m / kMm);
}

void validate_needle(const Scene& s, const std::string& file) {
  require(s.sample.diameter_m > 0, file, "/sample/diameter_mm", "> 0", s.sample.diameter_m / kMm);
  const double sample_radius = 0.5 * s.sample.diameter_m;
  require(s.needle.radius_m > 0, file, "/needle/radius_mm", "> 0", s.needle.radius_m / kMm);
  require(s.needle.radius_m < 0.25 * sample_radius, file, "/needle/radius_mm",
          "smaller than a quarter of the sample radius", s.needle.radius_m / kMm);
  if (s.needle.tip != "blunt" && s.needle.tip != "bevel" && s.needle.tip != "hollow")
    throw SceneError(file, "/needle/tip", "unknown tip shape '" + s.needle.tip + "' (known: blunt, bevel, hollow)");
  if (s.needle.tip == "hollow")
    require(s.needle.inner_radius_m > 0.2 * s.needle.radius_m && s.needle.inner_radius_m < 0.95 * s.needle.radius_m,
            file, "/needle/inner_radius_mm", "between 0.2 and 0.95 times the outer radius",
            s.needle.inner_radius_m / kMm);
  require(s.needle.tip_angle_deg >= 5.0 && s.needle.tip_angle_deg <= 60.0, file, "/needle/tip_angle_deg",
          "in [5, 60] degrees", s.needle.tip_angle_deg);
}

/// The layer's force mesh (Table 2's K, w, L and the mesh's own springs);
/// it must fit inside the sample radius.
void validate_force_mesh(const ForceMeshParams& fm, const std::string& file, const std::string& p,
                         double sample_radius_m) {
  require(fm.virtual_stiffness_N_per_m > 0, file, p + "/force_mesh/K_N_per_mm", "> 0",
          fm.virtual_stiffness_N_per_m * kMm);
  require(fm.rings_w >= 1, file, p + "/force_mesh/w", ">= 1", fm.rings_w);
  require(fm.rings_w <= 64, file, p + "/force_mesh/w", "<= 64", fm.rings_w);
  require(fm.spacing_L_m > 0, file, p + "/force_mesh/L_mm", "> 0", fm.spacing_L_m / kMm);
  require((fm.rings_w - 1) * fm.spacing_L_m < sample_radius_m, file, p + "/force_mesh/L_mm",
          "small enough that the force mesh ((w-1) L) fits inside the sample radius", fm.spacing_L_m / kMm);
  require(fm.surface_stiffness_N_per_m >= 0, file, p + "/force_mesh/surface_stiffness_N_per_mm", ">= 0",
          fm.surface_stiffness_N_per_m * kMm);
  require(fm.deformed_threshold_m > 0, file, p + "/force_mesh/deformed_threshold_mm", "> 0",
          fm.deformed_threshold_m / kMm);
  require(fm.node_damping_N_s_per_m >= 0, file, p + "/force_mesh/node_damping_N_s_per_m", ">= 0",
          fm.node_damping_N_s_per_m);
  require(fm.surface_axial_stiffness_N_per_m >= 0, file, p + "/force_mesh/surface_axial_stiffness_N_per_mm",
          ">= 0 (0: linear surface springs)", fm.surface_axial_stiffness_N_per_m * kMm);
  require(fm.virtual_stiffening_m >= 0, file, p + "/force_mesh/virtual_stiffening_mm",
          ">= 0 (0: linear virtual springs)", fm.virtual_stiffening_m / kMm);
}

/// Ogden terms: each |alpha| in [0.1, 40], mu_p alpha_p > 0, shares summing to 1.
void validate_ogden_terms(const ContinuumMaterial& m, const std::string& file, const std::string& p) {
  if (m.ogden_terms.empty())
    throw SceneError(file, p + "/material/ogden_alpha", "missing: an ogden material needs ogden_alpha or ogden_terms");
  double share = 0.0;
  for (std::size_t k = 0; k < m.ogden_terms.size(); ++k) {
    const OgdenTerm& t = m.ogden_terms[k];
    const std::string tp = m.ogden_terms.size() == 1 && t.mu_fraction == 1.0
                               ? p + "/material/ogden_alpha"
                               : p + "/material/ogden_terms/" + std::to_string(k) + "/alpha";
    require(std::abs(t.alpha) >= 0.1 && std::abs(t.alpha) <= 40, file, tp, "nonzero, with 0.1 <= |alpha| <= 40",
            t.alpha);
    require(t.mu_fraction * t.alpha > 0, file, p + "/material/ogden_terms/" + std::to_string(k) + "/mu_fraction",
            "of the same sign as alpha (each term must be stable: mu_p alpha_p > 0)", t.mu_fraction);
    share += t.mu_fraction;
  }
  require(std::abs(share - 1.0) < 1e-9, file, p + "/material/ogden_terms",
          "shares of the initial shear modulus summing to 1", share);
}

/// The continuum material of the FEM reference.
void validate_material(const ContinuumMaterial& m, const std::string& file, const std::string& p) {
  if (m.model != "neo_hookean" && m.model != "mooney_rivlin" && m.model != "ogden" && m.model != "veronda_westmann")
    throw SceneError(file, p + "/material/model",
                     "unknown material model '" + m.model +
                         "' (known: neo_hookean, mooney_rivlin, ogden, veronda_westmann)");
  require(m.youngs_modulus_Pa > 0, file, p + "/material/youngs_modulus_kPa", "> 0", m.youngs_modulus_Pa / 1e3);
  require(m.poisson_ratio > -1 && m.poisson_ratio < 0.5, file, p + "/material/poisson_ratio", "in (-1, 0.5)",
          m.poisson_ratio);
  require(m.mooney_rivlin_c01_fraction >= 0 && m.mooney_rivlin_c01_fraction < 1, file,
          p + "/material/mooney_rivlin_c01_fraction", "in [0, 1)", m.mooney_rivlin_c01_fraction);
  if (m.model == "ogden")
    validate_ogden_terms(m, file, p);
  else if (!m.ogden_terms.empty())
    throw SceneError(file, p + "/material/ogden_terms", "only an ogden material takes Ogden terms");
  require(m.veronda_westmann_gamma > 0 && m.veronda_westmann_gamma <= 100, file,
          p + "/material/veronda_westmann_gamma", "in (0, 100]", m.veronda_westmann_gamma);
  validate_viscoelastic(m.viscoelastic, file, p + "/material/viscoelastic");
}

/// The FEM's puncture criterion and shaft friction of one layer.
void validate_puncture(const Layer& l, const std::string& file, const std::string& p) {
  const PunctureCriterion& c = l.puncture;
  if (c.kind == PunctureCriterion::Kind::CriticalForce)
    require(c.critical_force_N > 0, file, p + "/puncture/critical_force_N", "> 0", c.critical_force_N);
  else if (c.kind == PunctureCriterion::Kind::CriticalStretch)
    require(c.critical_stretch > 1, file, p + "/puncture/critical_stretch", "> 1", c.critical_stretch);
  else {
    require(c.toughness_J_per_m2 > 0 && c.toughness_J_per_m2 <= 1e6, file, p + "/puncture/toughness_J_per_m2",
            "in (0, 1e6] J/m^2", c.toughness_J_per_m2);
    require(c.cohesive_strength_Pa > 0 && c.cohesive_strength_Pa <= 1e9, file,
            p + "/puncture/cohesive_strength_kPa", "in (0, 1e6] kPa", c.cohesive_strength_Pa / 1e3);
  }
  const ShaftFriction& sf = l.shaft_friction;
  require(sf.dynamic_coefficient >= 0 && sf.dynamic_coefficient <= 5, file, p + "/shaft_friction/coefficient",
          "in [0, 5]", sf.dynamic_coefficient);
  require(sf.static_coefficient >= sf.dynamic_coefficient && sf.static_coefficient <= 5, file,
          p + "/shaft_friction/static_coefficient", "in [coefficient, 5]", sf.static_coefficient);
}

void validate_layers(const Scene& s, const std::string& file) {
  if (s.layers.empty()) throw SceneError(file, "/layers", "must list at least one layer");
  std::set<std::string> names;
  for (std::size_t i = 0; i < s.layers.size(); ++i) {
    const Layer& l = s.layers[i];
    const std::string p = "/layers/" + std::to_string(i);
    if (l.name.empty()) throw SceneError(file, p + "/name", "must not be empty");
    for (char c : l.name)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_'))
        throw SceneError(file, p + "/name", "may contain only letters, digits and '_' (got '" + l.name + "')");
    if (!names.insert(l.name).second) throw SceneError(file, p + "/name", "layer name '" + l.name + "' used twice");
    require(l.thickness_m > 0, file, p + "/thickness_mm", "> 0", l.thickness_m / kMm);
    require(l.density_kg_per_m3 > 0, file, p + "/density_kg_per_m3", "> 0", l.density_kg_per_m3);
    validate_force_mesh(l.force_mesh, file, p, 0.5 * s.sample.diameter_m);
    require(l.damping_N_s_per_m2 >= 0, file, p + "/damping_d_N_s_per_m2", ">= 0", l.damping_N_s_per_m2);
    require(l.resumption_time_s > 0 && std::isfinite(l.resumption_time_s), file, p + "/resumption_time_s", "> 0",
            l.resumption_time_s);
    validate_force_law(l.force_law, file, p + "/force_law", l.thickness_m);
    validate_material(l.material, file, p);
    if (l.force_law.friction.pressure_relaxes_with_material && !l.material.viscoelastic.enabled())
      throw SceneError(file, p + "/force_law/friction/pressure_relaxation",
                       "'layer_material' needs the layer's material/viscoelastic/prony terms (the layer has none)");
    validate_puncture(l, file, p);
  }
}

/// An inclined insertion (needle.hpp) must stay inside the sample: the tip at
/// its start and at the target depth, and the force mesh of every layer it
/// reaches, laid where the path crosses the layer's top, (w - 1) L around it.
void validate_inclined_path(const Scene& s, const std::string& file) {
  const Insertion& in = s.insertion;
  const double tan_a = std::tan(in.angle_deg * (M_PI / 180.0));
  const double radius = 0.5 * s.sample.diameter_m;
  auto outside = [&](const std::string& what, double off_axis_m) {
    std::ostringstream msg;
    msg << "too steep for the sample: at " << in.angle_deg << " deg " << what << " lies " << off_axis_m / kMm
        << " mm off the sample axis, beyond the sample radius " << radius / kMm
        << " mm (reduce the angle or the target depth, or widen /sample/diameter_mm)";
    throw SceneError(file, "/insertion/angle_deg", msg.str());
  };
  if (in.start_height_m * tan_a >= radius) outside("the tip's start", in.start_height_m * tan_a);
  if (in.target_depth_m * tan_a + s.needle.radius_m >= radius)
    outside("the needle at the target depth", in.target_depth_m * tan_a + s.needle.radius_m);
  for (std::size_t k = 0; k < s.layers.size(); ++k) {
    const double top = s.layer_top_depth_m(k);
    if (top >= in.target_depth_m) break;
    const ForceMeshParams& fm = s.layers[k].force_mesh;
    const double reach = top * tan_a + (fm.rings_w - 1) * fm.spacing_L_m;
    if (reach >= radius) outside("layer '" + s.layers[k].name + "''s force mesh, laid where the path meets it,", reach);
  }
}

void validate_insertion(const Scene& s, const std::string& file) {
  const Insertion& in = s.insertion;
  require(in.start_height_m >= 0, file, "/insertion/start_height_mm", ">= 0", in.start_height_m / kMm);
  require(in.speed_m_per_s > 0, file, "/insertion/speed_mm_per_s", "> 0 (the scripted insertion must reach the target)",
          in.speed_m_per_s / kMm);
  require(in.speed_m_per_s <= 10.0, file, "/insertion/speed_mm_per_s", "<= 10000 (10 m/s)", in.speed_m_per_s / kMm);
  require(in.target_depth_m > 0, file, "/insertion/target_depth_mm", "> 0", in.target_depth_m / kMm);
  require(in.target_depth_m < s.total_thickness_m(), file, "/insertion/target_depth_mm",
          "less than the total tissue thickness (" + std::to_string(s.total_thickness_m() / kMm) + " mm)",
          in.target_depth_m / kMm);
  require(in.dwell_s >= 0, file, "/insertion/dwell_s", ">= 0", in.dwell_s);
  require(in.withdrawal_speed_m_per_s > 0, file, "/insertion/withdrawal_speed_mm_per_s", "> 0",
          in.withdrawal_speed_m_per_s / kMm);
  require(in.angle_deg >= 0.0 && in.angle_deg <= kMaxInsertionAngleDeg, file, "/insertion/angle_deg",
          "in [0, " + std::to_string(static_cast<int>(kMaxInsertionAngleDeg)) +
              "] deg (the angle between the needle and the surface normal)",
          in.angle_deg);
  require(in.azimuth_deg >= 0.0 && in.azimuth_deg < 360.0, file, "/insertion/azimuth_deg",
          "in [0, 360) deg (the direction the needle tilts towards, from +x towards +y)", in.azimuth_deg);
  if (in.angle_deg > 0.0) validate_inclined_path(s, file);
}

void validate_realtime(const RealtimeSettings& rt, const std::string& file) {
  require(rt.sh_degree >= 2 && rt.sh_degree <= 64, file, "/realtime/sh_degree", "in [2, 64]", rt.sh_degree);
  require(rt.haptic_rate_Hz > 0, file, "/realtime/haptic_rate_Hz", "> 0", rt.haptic_rate_Hz);
  if (rt.integrator != "explicit" && rt.integrator != "implicit" && rt.integrator != "quasi_static")
    throw SceneError(file, "/realtime/integrator",
                     "unknown integrator '" + rt.integrator + "' (known: explicit, implicit, quasi_static)");
  require(rt.frame_rate_Hz > 0 && rt.frame_rate_Hz <= rt.haptic_rate_Hz, file, "/realtime/frame_rate_Hz",
          "> 0 and <= haptic_rate_Hz", rt.frame_rate_Hz);
}

/// The FEM settings, and which puncture criteria the chosen geometry and tip can model.
void validate_fem(const Scene& s, const std::string& file) {
  const FemSettings& f = s.fem;
  if (f.geometry != "auto" && f.geometry != "axisymmetric" && f.geometry != "3d")
    throw SceneError(file, "/fem/geometry", "unknown geometry '" + f.geometry + "' (known: auto, axisymmetric, 3d)");
  const bool cutting_tip = s.needle.tip == "bevel" || s.needle.tip == "hollow";
  for (std::size_t i = 0; i < s.layers.size(); ++i) {
    if (s.layers[i].puncture.kind != PunctureCriterion::Kind::FractureEnergy) continue;
    if (!cutting_tip)
      throw SceneError(file, "/layers/" + std::to_string(i) + "/puncture/criterion",
                       "fracture_energy needs a needle that cuts (needle tip bevel or hollow; got '" + s.needle.tip +
                           "')");
    if (f.geometry == "3d")
      throw SceneError(file, "/fem/geometry",
                       "the 3d reference models a flat punch with the critical_force and critical_stretch criteria "
                       "only; fracture_energy needs geometry axisymmetric (or auto)");
  }
  require(f.refinement >= 0 && f.refinement <= 4, file, "/fem/refinement", "in [0, 4]", f.refinement);
  require(f.element_degree == 1 || f.element_degree == 2, file, "/fem/element_degree", "1 or 2", f.element_degree);
  require(f.load_step_m > 0, file, "/fem/load_step_mm", "> 0", f.load_step_m / kMm);
  require(f.max_newton_iterations >= 1, file, "/fem/max_newton_iterations", ">= 1", f.max_newton_iterations);
  require(f.newton_tolerance > 0 && f.newton_tolerance < 1, file, "/fem/newton_tolerance", "in (0, 1)",
          f.newton_tolerance);
  require(f.cohesive_viscosity_s >= 0 && f.cohesive_viscosity_s <= 1, file, "/fem/cohesive_viscosity_s",
          "in [0, 1] s", f.cohesive_viscosity_s);
  require(f.stabilization_time_s >= 0 && f.stabilization_time_s <= 1, file, "/fem/stabilization_time_s",
          "in [0, 1] s", f.stabilization_time_s);
  require(f.mesh.elements_per_needle_radius >= 2 && f.mesh.elements_per_needle_radius <= 64, file,
          "/fem/mesh/elements_per_needle_radius", "in [2, 64]", f.mesh.elements_per_needle_radius);
  require(f.mesh.min_elements_per_layer >= 1 && f.mesh.min_elements_per_layer <= 200, file,
          "/fem/mesh/min_elements_per_layer", "in [1, 200]", f.mesh.min_elements_per_layer);
  require(f.mesh.radial_growth >= 1.0 && f.mesh.radial_growth <= 2.0, file, "/fem/mesh/radial_growth", "in [1, 2]",
          f.mesh.radial_growth);
  require(f.mesh.path_element_size_mm > 0 && f.mesh.path_element_size_mm <= 10, file,
          "/fem/mesh/path_element_size_mm", "in (0, 10] mm", f.mesh.path_element_size_mm);
}

/// Effects that need particular layers, or exclude each other.
void validate_effects(const Scene& s, const std::string& file) {
  if (!s.effects.layer_interaction) return;
  // A layer pressed by the one above is deflected before the needle meets
  // it: the ring rule would break it at first touch.
  for (std::size_t i = 1; i < s.layers.size(); ++i)
    if (s.layers[i].force_law.breakthrough.kind == BreakthroughCriterion::Kind::Rings)
      throw SceneError(file, "/layers/" + std::to_string(i) + "/force_law/breakthrough/criterion",
                       "with the layer_interaction effect every layer below the first needs critical_force or "
                       "critical_energy (the ring rule counts the deflection carried from the layer above)");
  if (s.layers.size() > 16) throw SceneError(file, "/layers", "layer_interaction supports at most 16 layers");
  if (s.effects.coupled_surfaces)
    throw SceneError(file, "/effects",
                     "coupled_surfaces and layer_interaction both move the layers below the needle layer; list "
                     "one of them");
}

void validate_haptics(const Haptics& h, const std::string& file) {
  require(h.max_force_N > 0, file, "/haptics/max_force_N", "> 0", h.max_force_N);
  require(h.max_force_rate_N_per_s > 0, file, "/haptics/max_force_rate_N_per_s", "> 0", h.max_force_rate_N_per_s);
  require(h.device_damping_N_s_per_m >= 0, file, "/haptics/device_damping_N_s_per_m", ">= 0",
          h.device_damping_N_s_per_m);
  require(h.device_max_stiffness_N_per_m > 0, file, "/haptics/device_max_stiffness_N_per_mm", "> 0",
          h.device_max_stiffness_N_per_m * kMm);
}

/// The comparison models' mesh, integrator and identified stiffness scales.
void validate_comparison(const Scene& s, const std::string& file) {
  const ComparisonSettings& c = s.comparison;
  if (c.mesh.kind != "extruded" && c.mesh.kind != "delaunay")
    throw SceneError(file, "/comparison/mesh/kind", "unknown mesh kind '" + c.mesh.kind + "' (known: extruded, delaunay)");
  require(c.mesh.size_at_axis_m > 0, file, "/comparison/mesh/size_at_axis_mm", "> 0", c.mesh.size_at_axis_m / kMm);
  require(c.mesh.size_far_m >= c.mesh.size_at_axis_m, file, "/comparison/mesh/size_far_mm", ">= size_at_axis_mm",
          c.mesh.size_far_m / kMm);
  require(c.mesh.grading >= 0, file, "/comparison/mesh/grading", ">= 0", c.mesh.grading);
  if (c.integrator != "implicit" && c.integrator != "explicit")
    throw SceneError(file, "/comparison/integrator",
                     "unknown integrator '" + c.integrator + "' (known: implicit, explicit)");
  if (c.mass_spring_springs != "linear" && c.mass_spring_springs != "nonlinear")
    throw SceneError(file, "/comparison/mass_spring_springs",
                     "unknown spring kind '" + c.mass_spring_springs + "' (known: linear, nonlinear)");
  require(c.relative_tolerance > 0 && c.relative_tolerance < 1, file, "/comparison/relative_tolerance", "in (0, 1)",
          c.relative_tolerance);
  require(c.absolute_tolerance_m > 0, file, "/comparison/absolute_tolerance_mm", "> 0", c.absolute_tolerance_m / kMm);
  require(c.mass_damping_per_s >= 0, file, "/comparison/mass_damping_per_s", ">= 0", c.mass_damping_per_s);
  require(c.stiffness_damping_s >= 0, file, "/comparison/stiffness_damping_s", ">= 0", c.stiffness_damping_s);
  if (c.prony_g.size() != c.prony_tau_s.size())
    throw SceneError(file, "/comparison/viscoelastic/prony_tau_s",
                     "must have as many entries as prony_g (" + std::to_string(c.prony_g.size()) + ")");
  for (std::size_t i = 0; i < c.prony_g.size(); ++i) {
    require(c.prony_g[i] >= 0, file, "/comparison/viscoelastic/prony_g/" + std::to_string(i), ">= 0", c.prony_g[i]);
    require(c.prony_tau_s[i] > 0, file, "/comparison/viscoelastic/prony_tau_s/" + std::to_string(i), "> 0",
            c.prony_tau_s[i]);
  }
  if (!c.stiffness_scale.empty() && c.stiffness_scale.size() != s.layers.size())
    throw SceneError(file, "/comparison/stiffness_scale",
                     "must have one entry per layer (" + std::to_string(s.layers.size()) + ")");
  for (std::size_t i = 0; i < c.stiffness_scale.size(); ++i)
    require(c.stiffness_scale[i] > 0 && std::isfinite(c.stiffness_scale[i]), file,
            "/comparison/stiffness_scale/" + std::to_string(i), "> 0", c.stiffness_scale[i]);
  if (c.prescribed_puncture_depths_m.size() > s.layers.size())
    throw SceneError(file, "/comparison/prescribed_puncture_depths_mm",
                     "must have at most one entry per layer (" + std::to_string(s.layers.size()) + ")");
  for (std::size_t i = 0; i < c.prescribed_puncture_depths_m.size(); ++i)
    require(c.prescribed_puncture_depths_m[i] > 0 && std::isfinite(c.prescribed_puncture_depths_m[i]) &&
                (i == 0 || c.prescribed_puncture_depths_m[i] >= c.prescribed_puncture_depths_m[i - 1]),
            file, "/comparison/prescribed_puncture_depths_mm/" + std::to_string(i), "> 0 and not decreasing",
            c.prescribed_puncture_depths_m[i] / kMm);
  if (!c.mass_spring_stiffness_scale.empty() && c.mass_spring_stiffness_scale.size() != s.layers.size())
    throw SceneError(file, "/comparison/mass_spring_stiffness_scale",
                     "must have one entry per layer (" + std::to_string(s.layers.size()) + ")");
  for (std::size_t i = 0; i < c.mass_spring_stiffness_scale.size(); ++i)
    require(c.mass_spring_stiffness_scale[i] > 0, file,
            "/comparison/mass_spring_stiffness_scale/" + std::to_string(i), "> 0", c.mass_spring_stiffness_scale[i]);
}

}  // namespace

void validate_scene(const Scene& s, const std::string& file) {
  validate_needle(s, file);
  validate_layers(s, file);
  validate_insertion(s, file);
  validate_realtime(s.realtime, file);
  validate_fem(s, file);
  scene_limits::check_scene_limits(s, file);
  validate_effects(s, file);
  validate_haptics(s.haptics, file);
  validate_comparison(s, file);
}

}  // namespace puncture
