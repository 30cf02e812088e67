// scene_reader.cpp: strict JSON reader for scene files. Each object is read
// through an ObjectReader that records which keys were consumed, so unknown
// keys (typos) are reported instead of silently ignored. The values are
// checked afterwards by validate_scene (scene_validation.cpp).
#include "puncture/scene_io.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "json_reader.hpp"
#include "puncture/scene_limits.hpp"
#include "scene_fields.hpp"

namespace puncture {

namespace detail {

const std::set<std::string>& effect_names() {
  static const std::set<std::string> names{"surface_force", "damping",  "resumption", "surface_output",
                                           "cutting",       "friction", "stiffening", "layer_interaction",
                                           "coupled_surfaces"};
  return names;
}

}  // namespace detail

namespace {

using json = nlohmann::json;
using detail::kMm;
using detail::kSchemaVersion;

std::string describe(const json& v) {
  std::string s = v.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

/// Reads the fields of one JSON object; remembers the keys it consumed.
class ObjectReader {
 public:
  ObjectReader(const json& object, std::string path, const std::string& file)
      : object_(object), path_(std::move(path)), file_(file) {
    if (!object_.is_object()) fail(path_, "must be a JSON object (got " + describe(object_) + ")");
  }

  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw SceneError(file_, path, what);
  }
  std::string child(const std::string& key) const { return path_ + "/" + detail::json_pointer_token(key); }
  bool has(const std::string& key) const { return object_.contains(key); }

  const json& raw(const std::string& key) {
    used_.insert(key);
    if (!object_.contains(key)) fail(child(key), "missing required field");
    return object_.at(key);
  }

  double number(const std::string& key) {
    const json& v = raw(key);
    if (!v.is_number()) fail(child(key), "must be a number (got " + describe(v) + ")");
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(child(key), "must be finite (got " + describe(v) + ")");
    return x;
  }
  double number(const std::string& key, double fallback) { return has(key) ? number(key) : fallback; }

  int integer(const std::string& key) {
    const json& v = raw(key);
    if (!v.is_number_integer()) fail(child(key), "must be an integer (got " + describe(v) + ")");
    if (v.is_number_unsigned() ? v.get<std::uint64_t>() > 1000000000ULL
                               : (v.get<std::int64_t>() > 1000000000LL || v.get<std::int64_t>() < -1000000000LL))
      fail(child(key), "integer out of range (got " + describe(v) + ")");
    return v.get<int>();
  }
  int integer(const std::string& key, int fallback) { return has(key) ? integer(key) : fallback; }

  std::string string(const std::string& key) {
    const json& v = raw(key);
    if (!v.is_string()) fail(child(key), "must be a string (got " + describe(v) + ")");
    return v.get<std::string>();
  }
  std::string string(const std::string& key, const std::string& fallback) {
    return has(key) ? string(key) : fallback;
  }

  std::vector<std::string> string_list(const std::string& key, const std::set<std::string>& allowed,
                                       const std::string& what) {
    const json& v = raw(key);
    if (!v.is_array()) fail(child(key), "must be an array of strings (got " + describe(v) + ")");
    std::vector<std::string> out;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const std::string p = child(key) + "/" + std::to_string(i);
      if (!v[i].is_string()) fail(p, "must be a string (got " + describe(v[i]) + ")");
      const std::string s = v[i].get<std::string>();
      if (!allowed.count(s)) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        fail(p, "unknown " + what + " '" + s + "' (known: " + list + ")");
      }
      for (const auto& prev : out)
        if (prev == s) fail(p, what + " '" + s + "' listed twice");
      out.push_back(s);
    }
    return out;
  }

  /// Call after reading: every key of the object must have been consumed.
  void reject_unknown_keys() const {
    for (auto it = object_.begin(); it != object_.end(); ++it)
      if (!used_.count(it.key())) fail(child(it.key()), "unknown key");
  }

 private:
  const json& object_;
  std::string path_;
  const std::string& file_;
  std::set<std::string> used_;
};


ForceMeshParams read_force_mesh(ObjectReader r) {
  ForceMeshParams p;
  p.virtual_stiffness_N_per_m = r.number("K_N_per_mm") / kMm;
  p.rings_w = r.integer("w");
  p.spacing_L_m = r.number("L_mm") * kMm;
  p.surface_stiffness_N_per_m = r.number("surface_stiffness_N_per_mm", p.surface_stiffness_N_per_m * kMm) / kMm;
  p.deformed_threshold_m = r.number("deformed_threshold_mm", p.deformed_threshold_m / kMm) * kMm;
  p.node_damping_N_s_per_m = r.number("node_damping_N_s_per_m", p.node_damping_N_s_per_m);
  p.surface_axial_stiffness_N_per_m =
      r.number("surface_axial_stiffness_N_per_mm", p.surface_axial_stiffness_N_per_m * kMm) / kMm;
  p.virtual_stiffening_m = r.number("virtual_stiffening_mm", p.virtual_stiffening_m / kMm) * kMm;
  r.reject_unknown_keys();
  return p;
}

/// material.viscoelastic: {"prony": [{"g", "tau_s"}, ...], "modulus": "instantaneous" | "long_term", "source"}.
Viscoelasticity read_viscoelastic(ObjectReader r, const std::string& file) {
  Viscoelasticity v;
  const json& terms = r.raw("prony");
  if (!terms.is_array() || terms.empty())
    r.fail(r.child("prony"), "must be a non-empty array of {g, tau_s} objects");
  for (std::size_t i = 0; i < terms.size(); ++i) {
    ObjectReader t(terms[i], r.child("prony") + "/" + std::to_string(i), file);
    v.terms.push_back(PronyRelaxationTerm{t.number("g"), t.number("tau_s")});
    t.reject_unknown_keys();
  }
  const std::string basis = r.string("modulus");
  if (basis == "instantaneous")
    v.modulus_basis = Viscoelasticity::ModulusBasis::Instantaneous;
  else if (basis == "long_term")
    v.modulus_basis = Viscoelasticity::ModulusBasis::LongTerm;
  else
    r.fail(r.child("modulus"), "unknown modulus basis '" + basis + "' (known: instantaneous, long_term)");
  v.source = r.string("source", "");
  r.reject_unknown_keys();
  return v;
}

ContinuumMaterial read_material(ObjectReader r, const std::string& file) {
  ContinuumMaterial m;
  m.model = r.string("model", m.model);
  m.youngs_modulus_Pa = r.number("youngs_modulus_kPa") * 1e3;
  m.poisson_ratio = r.number("poisson_ratio");
  m.mooney_rivlin_c01_fraction = r.number("mooney_rivlin_c01_fraction", m.mooney_rivlin_c01_fraction);
  if (r.has("ogden_alpha") && r.has("ogden_terms"))
    r.fail(r.child("ogden_terms"), "give either ogden_alpha (one term) or ogden_terms, not both");
  if (r.has("ogden_alpha")) m.ogden_terms = {OgdenTerm{1.0, r.number("ogden_alpha")}};
  if (r.has("ogden_terms")) {
    const json& terms = r.raw("ogden_terms");
    if (!terms.is_array() || terms.empty())
      r.fail(r.child("ogden_terms"), "must be a non-empty array of {mu_fraction, alpha} objects");
    for (std::size_t i = 0; i < terms.size(); ++i) {
      ObjectReader t(terms[i], r.child("ogden_terms") + "/" + std::to_string(i), file);
      m.ogden_terms.push_back(OgdenTerm{t.number("mu_fraction"), t.number("alpha")});
      t.reject_unknown_keys();
    }
  }
  m.veronda_westmann_gamma = r.number("veronda_westmann_gamma", m.veronda_westmann_gamma);
  if (r.has("viscoelastic"))
    m.viscoelastic = read_viscoelastic(ObjectReader(r.raw("viscoelastic"), r.child("viscoelastic"), file), file);
  m.source = r.string("source", "");
  r.reject_unknown_keys();
  return m;
}

PunctureCriterion read_puncture(ObjectReader r) {
  PunctureCriterion c;
  const std::string kind = r.string("criterion");
  if (kind == "critical_force") {
    c.kind = PunctureCriterion::Kind::CriticalForce;
    c.critical_force_N = r.number("critical_force_N");
  } else if (kind == "critical_stretch") {
    c.kind = PunctureCriterion::Kind::CriticalStretch;
    c.critical_stretch = r.number("critical_stretch");
  } else if (kind == "fracture_energy") {
    c.kind = PunctureCriterion::Kind::FractureEnergy;
    c.toughness_J_per_m2 = r.number("toughness_J_per_m2");
    c.cohesive_strength_Pa = r.number("cohesive_strength_kPa") * 1e3;
  } else {
    r.fail(r.child("criterion"),
           "unknown criterion '" + kind + "' (known: fracture_energy, critical_force, critical_stretch)");
  }
  c.source = r.string("source", "");
  r.reject_unknown_keys();
  return c;
}

ShaftFriction read_shaft_friction(ObjectReader r) {
  ShaftFriction f;
  f.dynamic_coefficient = r.number("coefficient");
  f.static_coefficient = r.number("static_coefficient", f.dynamic_coefficient);
  f.source = r.string("source", "");
  r.reject_unknown_keys();
  return f;
}

BreakthroughCriterion read_breakthrough(ObjectReader r) {
  BreakthroughCriterion c;
  const std::string kind = r.string("criterion");
  if (kind == "rings") {
    c.kind = BreakthroughCriterion::Kind::Rings;
  } else if (kind == "critical_force") {
    c.kind = BreakthroughCriterion::Kind::CriticalForce;
    c.critical_force_N = r.number("critical_force_N");
  } else if (kind == "critical_energy") {
    c.kind = BreakthroughCriterion::Kind::CriticalEnergy;
    c.critical_energy_J = r.number("critical_energy_mJ") * 1e-3;
  } else {
    r.fail(r.child("criterion"), "unknown criterion '" + kind + "' (known: rings, critical_force, critical_energy)");
  }
  if (c.kind != BreakthroughCriterion::Kind::Rings) {  // the threshold's rate law (breakthrough_rate.hpp)
    c.rate_exponent = r.number("rate_exponent", c.rate_exponent);
    c.reference_speed_m_per_s = r.number("reference_speed_mm_per_s", c.reference_speed_m_per_s / kMm) * kMm;
  }
  r.reject_unknown_keys();
  return c;
}

StiffeningLaw read_stiffening(ObjectReader r) {
  StiffeningLaw st;
  const std::string law = r.string("law");
  if (law == "polynomial") {
    st.kind = StiffeningLaw::Kind::Polynomial;
    // One operation with an exact constant each way (1e6, 1e9), so a value
    // written and read back stays the same text (kMm * kMm rounds twice).
    st.quadratic_N_per_m2 = r.number("quadratic_N_per_mm2", 0.0) * 1e6;
    st.cubic_N_per_m3 = r.number("cubic_N_per_mm3", 0.0) * 1e9;
  } else if (law == "exponential") {
    st.kind = StiffeningLaw::Kind::Exponential;
    st.exponential_stiffness_N_per_m = r.number("stiffness_N_per_mm") / kMm;
    st.strain_scale_m = r.number("strain_scale_mm") * kMm;
  } else {
    r.fail(r.child("law"), "unknown stiffening law '" + law + "' (known: polynomial, exponential)");
  }
  r.reject_unknown_keys();
  return st;
}

ShaftFrictionLaw read_friction(ObjectReader r) {
  ShaftFrictionLaw f;
  f.dynamic_N_per_m = r.number("dynamic_N_per_mm") / kMm;
  f.static_N_per_m = r.number("static_N_per_mm", f.dynamic_N_per_m * kMm) / kMm;
  f.velocity_band_m_per_s = r.number("velocity_band_mm_per_s", f.velocity_band_m_per_s / kMm) * kMm;
  f.presliding_m = r.number("presliding_mm", 0.0) * kMm;
  const std::string relaxation = r.string("pressure_relaxation", "none");
  if (relaxation == "layer_material")
    f.pressure_relaxes_with_material = true;
  else if (relaxation != "none")
    r.fail(r.child("pressure_relaxation"),
           "unknown pressure relaxation '" + relaxation + "' (known: none, layer_material)");
  r.reject_unknown_keys();
  return f;
}

/// A rate law of the force law, `key: {coefficient_key: c, "reference_speed_mm_per_s": v_ref}`
/// (cutting_rate, rupture_release_rate), read into c and v_ref (m/s) when present.
void read_rate_law(ObjectReader& r, const std::string& key, const std::string& coefficient_key, const std::string& file,
                   double& coefficient, double& reference_speed_m_per_s) {
  if (!r.has(key)) return;
  ObjectReader c(r.raw(key), r.child(key), file);
  coefficient = c.number(coefficient_key, coefficient);
  reference_speed_m_per_s = c.number("reference_speed_mm_per_s", reference_speed_m_per_s / kMm) * kMm;
  c.reject_unknown_keys();
}

ForceLaw read_force_law(ObjectReader r, const std::string& file) {
  ForceLaw law;
  if (r.has("breakthrough"))
    law.breakthrough = read_breakthrough(ObjectReader(r.raw("breakthrough"), r.child("breakthrough"), file));
  if (r.has("stiffening"))
    law.stiffening = read_stiffening(ObjectReader(r.raw("stiffening"), r.child("stiffening"), file));
  law.cutting_force_N = r.number("cutting_force_N", law.cutting_force_N);
  read_rate_law(r, "cutting_rate", "viscous_fraction", file, law.cutting_rate.viscous_fraction,
                law.cutting_rate.reference_speed_m_per_s);
  law.cutting_release_m = r.number("cutting_release_mm", law.cutting_release_m / kMm) * kMm;
  law.rupture_release_m = r.number("rupture_release_mm", law.rupture_release_m / kMm) * kMm;
  read_rate_law(r, "rupture_release_rate", "exponent", file, law.rupture_release_rate.exponent,
                law.rupture_release_rate.reference_speed_m_per_s);
  if (r.has("friction")) law.friction = read_friction(ObjectReader(r.raw("friction"), r.child("friction"), file));
  r.reject_unknown_keys();
  return law;
}

std::vector<double> number_list(ObjectReader& r, const std::string& key) {
  const json& v = r.raw(key);
  if (!v.is_array()) r.fail(r.child(key), "must be an array of numbers (got " + describe(v) + ")");
  std::vector<double> out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string p = r.child(key) + "/" + std::to_string(i);
    if (!v[i].is_number()) r.fail(p, "must be a number (got " + describe(v[i]) + ")");
    const double x = v[i].get<double>();
    if (!std::isfinite(x)) r.fail(p, "must be finite (got " + describe(v[i]) + ")");
    out.push_back(x);
  }
  return out;
}

ComparisonSettings read_comparison(ObjectReader r, const std::string& file) {
  ComparisonSettings c;
  if (r.has("mesh")) {
    ObjectReader m(r.raw("mesh"), r.child("mesh"), file);
    c.mesh.kind = m.string("kind", c.mesh.kind);
    c.mesh.size_at_axis_m = m.number("size_at_axis_mm", c.mesh.size_at_axis_m / kMm) * kMm;
    c.mesh.size_far_m = m.number("size_far_mm", c.mesh.size_far_m / kMm) * kMm;
    c.mesh.grading = m.number("grading", c.mesh.grading);
    m.reject_unknown_keys();
  }
  c.integrator = r.string("integrator", c.integrator);
  c.mass_spring_springs = r.string("mass_spring_springs", c.mass_spring_springs);
  c.relative_tolerance = r.number("relative_tolerance", c.relative_tolerance);
  c.absolute_tolerance_m = r.number("absolute_tolerance_mm", c.absolute_tolerance_m / kMm) * kMm;
  c.mass_damping_per_s = r.number("mass_damping_per_s", c.mass_damping_per_s);
  c.stiffness_damping_s = r.number("stiffness_damping_s", c.stiffness_damping_s);
  if (r.has("viscoelastic")) {
    ObjectReader v(r.raw("viscoelastic"), r.child("viscoelastic"), file);
    c.prony_g = number_list(v, "prony_g");
    c.prony_tau_s = number_list(v, "prony_tau_s");
    v.reject_unknown_keys();
  }
  if (r.has("stiffness_scale")) c.stiffness_scale = number_list(r, "stiffness_scale");
  if (r.has("prescribed_puncture_depths_mm")) {
    c.prescribed_puncture_depths_m = number_list(r, "prescribed_puncture_depths_mm");
    for (double& d : c.prescribed_puncture_depths_m) d *= kMm;
  }
  if (r.has("mass_spring_stiffness_scale")) c.mass_spring_stiffness_scale = number_list(r, "mass_spring_stiffness_scale");
  r.reject_unknown_keys();
  return c;
}

/// resumption_rate: the paper's eta_r per haptic step if the layer gives one
/// (0 if not), converted to resumption_time_s by the scene reader.
Layer read_layer(ObjectReader r, const std::string& file, bool& has_resumption_time, double& resumption_rate) {
  Layer l;
  l.name = r.string("name");
  l.thickness_m = r.number("thickness_mm") * kMm;
  l.density_kg_per_m3 = r.number("density_kg_per_m3", l.density_kg_per_m3);
  l.force_mesh = read_force_mesh(ObjectReader(r.raw("force_mesh"), r.child("force_mesh"), file));
  l.damping_N_s_per_m2 = r.number("damping_d_N_s_per_m2");
  resumption_rate = 0.0;
  if (r.has("resumption_rate")) {
    resumption_rate = r.number("resumption_rate");
    if (!(resumption_rate > 0 && resumption_rate <= 1))
      r.fail(r.child("resumption_rate"), "in (0, 1] (got " + describe(resumption_rate) + ")");
  }
  has_resumption_time = r.has("resumption_time_s");
  l.resumption_time_s = r.number("resumption_time_s", l.resumption_time_s);
  if (r.has("force_law")) l.force_law = read_force_law(ObjectReader(r.raw("force_law"), r.child("force_law"), file), file);
  if (r.has("material"))
    l.material = read_material(ObjectReader(r.raw("material"), r.child("material"), file), file);
  if (r.has("puncture")) l.puncture = read_puncture(ObjectReader(r.raw("puncture"), r.child("puncture"), file));
  if (r.has("shaft_friction"))
    l.shaft_friction = read_shaft_friction(ObjectReader(r.raw("shaft_friction"), r.child("shaft_friction"), file));
  r.reject_unknown_keys();
  return l;
}

Sample read_sample(ObjectReader o) {
  Sample sample;
  sample.diameter_m = o.number("diameter_mm") * kMm;
  o.reject_unknown_keys();
  return sample;
}

Needle read_needle(ObjectReader o) {
  Needle n;
  n.radius_m = o.number("radius_mm") * kMm;
  n.tip = o.string("tip", n.tip);
  n.inner_radius_m = o.number("inner_radius_mm", n.inner_radius_m / kMm) * kMm;
  n.tip_angle_deg = o.number("tip_angle_deg", n.tip_angle_deg);
  o.reject_unknown_keys();
  return n;
}

Insertion read_insertion(ObjectReader o) {
  Insertion in;
  in.start_height_m = o.number("start_height_mm", in.start_height_m / kMm) * kMm;
  in.speed_m_per_s = o.number("speed_mm_per_s") * kMm;
  in.target_depth_m = o.number("target_depth_mm") * kMm;
  in.dwell_s = o.number("dwell_s", in.dwell_s);
  in.withdrawal_speed_m_per_s = o.number("withdrawal_speed_mm_per_s", in.speed_m_per_s / kMm) * kMm;
  in.angle_deg = o.number("angle_deg", in.angle_deg);
  in.azimuth_deg = o.number("azimuth_deg", in.azimuth_deg);
  o.reject_unknown_keys();
  return in;
}

RealtimeSettings read_realtime(ObjectReader o) {
  RealtimeSettings rt;
  rt.sh_degree = o.integer("sh_degree", rt.sh_degree);
  rt.haptic_rate_Hz = o.number("haptic_rate_Hz", rt.haptic_rate_Hz);
  rt.integrator = o.string("integrator", rt.integrator);
  rt.frame_rate_Hz = o.number("frame_rate_Hz", rt.frame_rate_Hz);
  o.reject_unknown_keys();
  return rt;
}

FemSettings read_fem(ObjectReader o, const std::string& file) {
  FemSettings f;
  f.geometry = o.string("geometry", f.geometry);
  f.refinement = o.integer("refinement", f.refinement);
  f.element_degree = o.integer("element_degree", f.element_degree);
  f.load_step_m = o.number("load_step_mm", f.load_step_m / kMm) * kMm;
  f.max_newton_iterations = o.integer("max_newton_iterations", f.max_newton_iterations);
  f.newton_tolerance = o.number("newton_tolerance", f.newton_tolerance);
  f.cohesive_viscosity_s = o.number("cohesive_viscosity_s", f.cohesive_viscosity_s);
  f.stabilization_time_s = o.number("stabilization_time_s", f.stabilization_time_s);
  if (o.has("mesh")) {
    ObjectReader m(o.raw("mesh"), "/fem/mesh", file);
    FemMeshSettings& ms = f.mesh;
    ms.elements_per_needle_radius = m.integer("elements_per_needle_radius", ms.elements_per_needle_radius);
    ms.min_elements_per_layer = m.integer("min_elements_per_layer", ms.min_elements_per_layer);
    ms.radial_growth = m.number("radial_growth", ms.radial_growth);
    ms.path_element_size_mm = m.number("path_element_size_mm", ms.path_element_size_mm);
    m.reject_unknown_keys();
  }
  o.reject_unknown_keys();
  return f;
}

Effects read_effects(ObjectReader& r) {
  const auto list = r.string_list("effects", detail::effect_names(), "effect");
  auto on = [&](const char* e) { return std::find(list.begin(), list.end(), e) != list.end(); };
  Effects e;
  e.surface_force = on("surface_force");
  e.damping = on("damping");
  e.resumption = on("resumption");
  e.surface_output = on("surface_output");
  e.cutting = on("cutting");
  e.friction = on("friction");
  e.stiffening = on("stiffening");
  e.layer_interaction = on("layer_interaction");
  e.coupled_surfaces = on("coupled_surfaces");
  return e;
}

Haptics read_haptics(ObjectReader o) {
  Haptics h;
  h.max_force_N = o.number("max_force_N", h.max_force_N);
  h.max_force_rate_N_per_s = o.number("max_force_rate_N_per_s", h.max_force_rate_N_per_s);
  h.device_damping_N_s_per_m = o.number("device_damping_N_s_per_m", h.device_damping_N_s_per_m);
  h.device_max_stiffness_N_per_m =
      o.number("device_max_stiffness_N_per_mm", h.device_max_stiffness_N_per_m * kMm) / kMm;
  o.reject_unknown_keys();
  return h;
}

/// How each layer gave its recovery time (read_layer), resolved once the
/// haptic rate is known.
struct ResumptionGiven {
  bool time_given = false;
  double rate_per_step = 0.0;  ///< the paper's eta_r per haptic step (0: not given)
};

/// Recovery time in seconds: given, or the paper's eta_r per haptic step at
/// this file's haptic rate (so that it no longer changes with the rate).
void resolve_resumption_times(Scene& s, const std::vector<ResumptionGiven>& given, const ObjectReader& r) {
  for (std::size_t i = 0; i < s.layers.size(); ++i) {
    Layer& l = s.layers[i];
    const std::string p = "/layers/" + std::to_string(i);
    if (given[i].time_given) {
      if (!(l.resumption_time_s > 0)) r.fail(p + "/resumption_time_s", "must be > 0 (got " + describe(l.resumption_time_s) + ")");
    } else if (given[i].rate_per_step > 0 && s.realtime.haptic_rate_Hz > 0) {
      l.resumption_time_s = 1.0 / (given[i].rate_per_step * s.realtime.haptic_rate_Hz);
    }
  }
}

Scene read_scene(const json& root, const std::string& file) {
  ObjectReader r(root, "", file);
  Scene s;
  const int version = r.integer("schema_version");
  if (version != kSchemaVersion)
    r.fail("/schema_version", "unsupported schema version " + std::to_string(version) + " (this program reads " +
                                  std::to_string(kSchemaVersion) + ")");
  s.name = r.string("name");
  s.description = r.string("description", "");
  s.source_path = file;
  s.sample = read_sample(ObjectReader(r.raw("sample"), "/sample", file));
  s.needle = read_needle(ObjectReader(r.raw("needle"), "/needle", file));
  std::vector<ResumptionGiven> resumption;
  const json& layers = r.raw("layers");
  if (!layers.is_array()) r.fail("/layers", "must be an array of layer objects");
  for (std::size_t i = 0; i < layers.size(); ++i) {
    ResumptionGiven given;
    s.layers.push_back(read_layer(ObjectReader(layers[i], "/layers/" + std::to_string(i), file), file,
                                  given.time_given, given.rate_per_step));
    resumption.push_back(given);
  }
  s.insertion = read_insertion(ObjectReader(r.raw("insertion"), "/insertion", file));
  if (r.has("realtime")) s.realtime = read_realtime(ObjectReader(r.raw("realtime"), "/realtime", file));
  if (r.has("fem")) s.fem = read_fem(ObjectReader(r.raw("fem"), "/fem", file), file);
  if (r.has("comparison")) s.comparison = read_comparison(ObjectReader(r.raw("comparison"), "/comparison", file), file);
  if (r.has("models"))  // read and written by earlier versions, used by no command
    r.fail(r.child("models"), "is no longer a scene field (no command used it): remove it");
  if (r.has("effects")) s.effects = read_effects(r);
  if (r.has("haptics")) s.haptics = read_haptics(ObjectReader(r.raw("haptics"), "/haptics", file));
  r.reject_unknown_keys();
  resolve_resumption_times(s, resumption, r);
  validate_scene(s, file);
  return s;
}

}  // namespace

const std::vector<std::string>& known_effects() {
  static const std::vector<std::string> names(detail::effect_names().begin(), detail::effect_names().end());
  return names;
}

Scene parse_scene(const std::string& text, const std::string& source_name) {
  if (text.size() > scene_limits::kMaxSceneFileBytes)
    throw SceneError(source_name, "", "scene text of " + std::to_string(text.size()) + " bytes; the limit is " +
                                          std::to_string(scene_limits::kMaxSceneFileBytes) + " bytes");
  return read_scene(detail::parse_json_with_paths(text, source_name), source_name);
}

Scene load_scene(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status))
    throw SceneError(path.string(), "", "cannot open scene file: " +
                                            (ec ? ec.message() : std::string("No such file or directory")));
  if (std::filesystem::is_directory(status))
    throw SceneError(path.string(), "", "is a directory, not a scene file");
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > scene_limits::kMaxSceneFileBytes)
    throw SceneError(path.string(), "", "file of " + std::to_string(size) + " bytes; a scene file is at most " +
                                            std::to_string(scene_limits::kMaxSceneFileBytes) + " bytes");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path.string(), "", std::string("cannot open scene file: ") + std::strerror(errno ? errno : EACCES));
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_scene(buffer.str(), path.string());
}

}  // namespace puncture
