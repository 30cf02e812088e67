// scene_io.cpp: strict JSON reader for scene files. Each object is read
// through an ObjectReader that records which keys were consumed, so unknown
// keys (typos) are reported instead of silently ignored.
#include "puncture/scene_io.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "json_reader.hpp"
#include "puncture/scene_limits.hpp"

namespace puncture {
namespace {

using json = nlohmann::json;

constexpr double kMm = 1e-3;
constexpr int kSchemaVersion = 1;

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

const std::set<std::string> kEffects{"surface_force", "damping",  "resumption", "surface_output",
                                     "cutting",       "friction", "stiffening", "layer_interaction",
                                     "coupled_surfaces"};
const std::set<std::string> kModels{"realtime", "fem"};

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
  r.reject_unknown_keys();
  return f;
}

ForceLaw read_force_law(ObjectReader r, const std::string& file) {
  ForceLaw law;
  if (r.has("breakthrough"))
    law.breakthrough = read_breakthrough(ObjectReader(r.raw("breakthrough"), r.child("breakthrough"), file));
  if (r.has("stiffening"))
    law.stiffening = read_stiffening(ObjectReader(r.raw("stiffening"), r.child("stiffening"), file));
  law.cutting_force_N = r.number("cutting_force_N", law.cutting_force_N);
  law.cutting_release_m = r.number("cutting_release_mm", law.cutting_release_m / kMm) * kMm;
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
    c.mesh.size_at_axis_m = m.number("size_at_axis_mm", c.mesh.size_at_axis_m / kMm) * kMm;
    c.mesh.size_far_m = m.number("size_far_mm", c.mesh.size_far_m / kMm) * kMm;
    c.mesh.grading = m.number("grading", c.mesh.grading);
    m.reject_unknown_keys();
  }
  c.integrator = r.string("integrator", c.integrator);
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
  std::vector<bool> resumption_time_given;
  std::vector<double> resumption_rate;  // eta_r per haptic step as given (0: not given)

  {
    ObjectReader o(r.raw("sample"), "/sample", file);
    s.sample.diameter_m = o.number("diameter_mm") * kMm;
    o.reject_unknown_keys();
  }
  {
    ObjectReader o(r.raw("needle"), "/needle", file);
    s.needle.radius_m = o.number("radius_mm") * kMm;
    s.needle.tip = o.string("tip", s.needle.tip);
    s.needle.inner_radius_m = o.number("inner_radius_mm", s.needle.inner_radius_m / kMm) * kMm;
    s.needle.tip_angle_deg = o.number("tip_angle_deg", s.needle.tip_angle_deg);
    o.reject_unknown_keys();
  }
  {
    const json& layers = r.raw("layers");
    if (!layers.is_array()) r.fail("/layers", "must be an array of layer objects");
    for (std::size_t i = 0; i < layers.size(); ++i) {
      bool has_time = false;
      double rate = 0.0;
      s.layers.push_back(
          read_layer(ObjectReader(layers[i], "/layers/" + std::to_string(i), file), file, has_time, rate));
      resumption_time_given.push_back(has_time);
      resumption_rate.push_back(rate);
    }
  }
  {
    ObjectReader o(r.raw("insertion"), "/insertion", file);
    Insertion& in = s.insertion;
    in.start_height_m = o.number("start_height_mm", in.start_height_m / kMm) * kMm;
    in.speed_m_per_s = o.number("speed_mm_per_s") * kMm;
    in.target_depth_m = o.number("target_depth_mm") * kMm;
    in.dwell_s = o.number("dwell_s", in.dwell_s);
    in.withdrawal_speed_m_per_s = o.number("withdrawal_speed_mm_per_s", in.speed_m_per_s / kMm) * kMm;
    in.angle_deg = o.number("angle_deg", in.angle_deg);
    o.reject_unknown_keys();
  }
  if (r.has("realtime")) {
    ObjectReader o(r.raw("realtime"), "/realtime", file);
    RealtimeSettings& rt = s.realtime;
    rt.sh_degree = o.integer("sh_degree", rt.sh_degree);
    rt.haptic_rate_Hz = o.number("haptic_rate_Hz", rt.haptic_rate_Hz);
    rt.integrator = o.string("integrator", rt.integrator);
    rt.frame_rate_Hz = o.number("frame_rate_Hz", rt.frame_rate_Hz);
    o.reject_unknown_keys();
  }
  if (r.has("fem")) {
    ObjectReader o(r.raw("fem"), "/fem", file);
    FemSettings& f = s.fem;
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
  }
  if (r.has("comparison")) s.comparison = read_comparison(ObjectReader(r.raw("comparison"), "/comparison", file), file);
  if (r.has("models")) s.models = r.string_list("models", kModels, "model");
  if (r.has("effects")) {
    const auto list = r.string_list("effects", kEffects, "effect");
    auto on = [&](const char* e) { return std::find(list.begin(), list.end(), e) != list.end(); };
    s.effects.surface_force = on("surface_force");
    s.effects.damping = on("damping");
    s.effects.resumption = on("resumption");
    s.effects.surface_output = on("surface_output");
    s.effects.cutting = on("cutting");
    s.effects.friction = on("friction");
    s.effects.stiffening = on("stiffening");
    s.effects.layer_interaction = on("layer_interaction");
    s.effects.coupled_surfaces = on("coupled_surfaces");
  }
  if (r.has("haptics")) {
    ObjectReader o(r.raw("haptics"), "/haptics", file);
    Haptics& h = s.haptics;
    h.max_force_N = o.number("max_force_N", h.max_force_N);
    h.max_force_rate_N_per_s = o.number("max_force_rate_N_per_s", h.max_force_rate_N_per_s);
    h.device_damping_N_s_per_m = o.number("device_damping_N_s_per_m", h.device_damping_N_s_per_m);
    h.device_max_stiffness_N_per_m =
        o.number("device_max_stiffness_N_per_mm", h.device_max_stiffness_N_per_m * kMm) / kMm;
    o.reject_unknown_keys();
  }
  r.reject_unknown_keys();
  // Recovery time in seconds: given, or the paper's eta_r per haptic step at
  // this file's haptic rate (so that it no longer changes with the rate).
  for (std::size_t i = 0; i < s.layers.size(); ++i) {
    Layer& l = s.layers[i];
    const std::string p = "/layers/" + std::to_string(i);
    if (resumption_time_given[i]) {
      if (!(l.resumption_time_s > 0)) r.fail(p + "/resumption_time_s", "must be > 0 (got " + describe(l.resumption_time_s) + ")");
    } else if (resumption_rate[i] > 0 && s.realtime.haptic_rate_Hz > 0) {
      l.resumption_time_s = 1.0 / (resumption_rate[i] * s.realtime.haptic_rate_Hz);
    }
  }
  validate_scene(s, file);
  return s;
}

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
  const StiffeningLaw& st = law.stiffening;
  require(st.quadratic_N_per_m2 >= 0, file, p + "/stiffening/quadratic_N_per_mm2", ">= 0", st.quadratic_N_per_m2 * kMm * kMm);
  require(st.cubic_N_per_m3 >= 0, file, p + "/stiffening/cubic_N_per_mm3", ">= 0", st.cubic_N_per_m3 * kMm * kMm * kMm);
  require(st.exponential_stiffness_N_per_m >= 0, file, p + "/stiffening/stiffness_N_per_mm", ">= 0",
          st.exponential_stiffness_N_per_m * kMm);
  require(st.strain_scale_m > 0, file, p + "/stiffening/strain_scale_mm", "> 0", st.strain_scale_m / kMm);
  require(law.cutting_force_N >= 0 && law.cutting_force_N <= 1e3, file, p + "/cutting_force_N", "in [0, 1000]",
          law.cutting_force_N);
  require(law.cutting_release_m > 0 && law.cutting_release_m <= thickness_m + 1e-3, file, p + "/cutting_release_mm",
          "> 0 and at most the layer thickness + 1 mm", law.cutting_release_m / kMm);
  const ShaftFrictionLaw& f = law.friction;
  require(f.dynamic_N_per_m >= 0, file, p + "/friction/dynamic_N_per_mm", ">= 0", f.dynamic_N_per_m * kMm);
  require(f.static_N_per_m >= f.dynamic_N_per_m, file, p + "/friction/static_N_per_mm",
          ">= dynamic_N_per_mm (the shaft cannot stick with less force than it slides with)", f.static_N_per_m * kMm);
  require(f.velocity_band_m_per_s > 0, file, p + "/friction/velocity_band_mm_per_s", "> 0",
          f.velocity_band_m_per_s / kMm);
  require(f.presliding_m >= 0, file, p + "/friction/presliding_mm", ">= 0", f.presliding_m / kMm);
}

}  // namespace

const std::vector<std::string>& known_effects() {
  static const std::vector<std::string> names(kEffects.begin(), kEffects.end());
  return names;
}

void validate_scene(const Scene& s, const std::string& file) {
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
    const ForceMeshParams& fm = l.force_mesh;
    require(fm.virtual_stiffness_N_per_m > 0, file, p + "/force_mesh/K_N_per_mm", "> 0",
            fm.virtual_stiffness_N_per_m * kMm);
    require(fm.rings_w >= 1, file, p + "/force_mesh/w", ">= 1", fm.rings_w);
    require(fm.rings_w <= 64, file, p + "/force_mesh/w", "<= 64", fm.rings_w);
    require(fm.spacing_L_m > 0, file, p + "/force_mesh/L_mm", "> 0", fm.spacing_L_m / kMm);
    require((fm.rings_w - 1) * fm.spacing_L_m < sample_radius, file, p + "/force_mesh/L_mm",
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
    require(l.damping_N_s_per_m2 >= 0, file, p + "/damping_d_N_s_per_m2", ">= 0", l.damping_N_s_per_m2);
    require(l.resumption_time_s > 0 && std::isfinite(l.resumption_time_s), file, p + "/resumption_time_s", "> 0",
            l.resumption_time_s);
    validate_force_law(l.force_law, file, p + "/force_law", l.thickness_m);
    const ContinuumMaterial& m = l.material;
    if (m.model != "neo_hookean" && m.model != "mooney_rivlin" && m.model != "ogden" && m.model != "veronda_westmann")
      throw SceneError(file, p + "/material/model",
                       "unknown material model '" + m.model +
                           "' (known: neo_hookean, mooney_rivlin, ogden, veronda_westmann)");
    require(m.youngs_modulus_Pa > 0, file, p + "/material/youngs_modulus_kPa", "> 0", m.youngs_modulus_Pa / 1e3);
    require(m.poisson_ratio > -1 && m.poisson_ratio < 0.5, file, p + "/material/poisson_ratio", "in (-1, 0.5)",
            m.poisson_ratio);
    require(m.mooney_rivlin_c01_fraction >= 0 && m.mooney_rivlin_c01_fraction < 1, file,
            p + "/material/mooney_rivlin_c01_fraction", "in [0, 1)", m.mooney_rivlin_c01_fraction);
    if (m.model == "ogden") {
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
        require(t.mu_fraction * t.alpha > 0, file,
                p + "/material/ogden_terms/" + std::to_string(k) + "/mu_fraction",
                "of the same sign as alpha (each term must be stable: mu_p alpha_p > 0)", t.mu_fraction);
        share += t.mu_fraction;
      }
      require(std::abs(share - 1.0) < 1e-9, file, p + "/material/ogden_terms",
              "shares of the initial shear modulus summing to 1", share);
    } else if (!m.ogden_terms.empty()) {
      throw SceneError(file, p + "/material/ogden_terms", "only an ogden material takes Ogden terms");
    }
    require(m.veronda_westmann_gamma > 0 && m.veronda_westmann_gamma <= 100, file,
            p + "/material/veronda_westmann_gamma", "in (0, 100]", m.veronda_westmann_gamma);
    validate_viscoelastic(m.viscoelastic, file, p + "/material/viscoelastic");
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
  require(in.angle_deg == 0.0, file, "/insertion/angle_deg",
          "0: only insertion along the surface normal is supported", in.angle_deg);

  const RealtimeSettings& rt = s.realtime;
  require(rt.sh_degree >= 2 && rt.sh_degree <= 64, file, "/realtime/sh_degree", "in [2, 64]", rt.sh_degree);
  require(rt.haptic_rate_Hz > 0, file, "/realtime/haptic_rate_Hz", "> 0", rt.haptic_rate_Hz);
  if (rt.integrator != "explicit" && rt.integrator != "implicit" && rt.integrator != "quasi_static")
    throw SceneError(file, "/realtime/integrator",
                     "unknown integrator '" + rt.integrator + "' (known: explicit, implicit, quasi_static)");
  require(rt.frame_rate_Hz > 0 && rt.frame_rate_Hz <= rt.haptic_rate_Hz, file, "/realtime/frame_rate_Hz",
          "> 0 and <= haptic_rate_Hz", rt.frame_rate_Hz);

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
  if (s.models.empty()) throw SceneError(file, "/models", "must name at least one model (realtime, fem)");
  scene_limits::check_scene_limits(s, file);
  if (s.effects.layer_interaction) {
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

  const Haptics& h = s.haptics;
  require(h.max_force_N > 0, file, "/haptics/max_force_N", "> 0", h.max_force_N);
  require(h.max_force_rate_N_per_s > 0, file, "/haptics/max_force_rate_N_per_s", "> 0", h.max_force_rate_N_per_s);
  require(h.device_damping_N_s_per_m >= 0, file, "/haptics/device_damping_N_s_per_m", ">= 0",
          h.device_damping_N_s_per_m);
  require(h.device_max_stiffness_N_per_m > 0, file, "/haptics/device_max_stiffness_N_per_mm", "> 0",
          h.device_max_stiffness_N_per_m * kMm);

  const ComparisonSettings& c = s.comparison;
  require(c.mesh.size_at_axis_m > 0, file, "/comparison/mesh/size_at_axis_mm", "> 0", c.mesh.size_at_axis_m / kMm);
  require(c.mesh.size_far_m >= c.mesh.size_at_axis_m, file, "/comparison/mesh/size_far_mm", ">= size_at_axis_mm",
          c.mesh.size_far_m / kMm);
  require(c.mesh.grading >= 0, file, "/comparison/mesh/grading", ">= 0", c.mesh.grading);
  if (c.integrator != "implicit" && c.integrator != "explicit")
    throw SceneError(file, "/comparison/integrator",
                     "unknown integrator '" + c.integrator + "' (known: implicit, explicit)");
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
  if (!c.mass_spring_stiffness_scale.empty() && c.mass_spring_stiffness_scale.size() != s.layers.size())
    throw SceneError(file, "/comparison/mass_spring_stiffness_scale",
                     "must have one entry per layer (" + std::to_string(s.layers.size()) + ")");
  for (std::size_t i = 0; i < c.mass_spring_stiffness_scale.size(); ++i)
    require(c.mass_spring_stiffness_scale[i] > 0, file,
            "/comparison/mass_spring_stiffness_scale/" + std::to_string(i), "> 0", c.mass_spring_stiffness_scale[i]);
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

namespace {

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
  j["cutting_release_mm"] = law.cutting_release_m / kMm;
  j["friction"] = {{"static_N_per_mm", law.friction.static_N_per_m * kMm},
                   {"dynamic_N_per_mm", law.friction.dynamic_N_per_m * kMm},
                   {"velocity_band_mm_per_s", law.friction.velocity_band_m_per_s / kMm},
                   {"presliding_mm", law.friction.presliding_m / kMm}};
  return j;
}

}  // namespace

std::string scene_to_json_text(const Scene& s) {
  json root;
  root["schema_version"] = kSchemaVersion;
  root["name"] = s.name;
  root["description"] = s.description;
  root["sample"] = {{"diameter_mm", s.sample.diameter_m / kMm}};
  root["needle"] = {{"radius_mm", s.needle.radius_m / kMm},
                    {"tip", s.needle.tip},
                    {"inner_radius_mm", s.needle.inner_radius_m / kMm},
                    {"tip_angle_deg", s.needle.tip_angle_deg}};
  json layers = json::array();
  for (const Layer& l : s.layers) {
    json j;
    j["name"] = l.name;
    j["thickness_mm"] = l.thickness_m / kMm;
    j["density_kg_per_m3"] = l.density_kg_per_m3;
    j["force_mesh"] = {{"K_N_per_mm", l.force_mesh.virtual_stiffness_N_per_m * kMm},
                       {"w", l.force_mesh.rings_w},
                       {"L_mm", l.force_mesh.spacing_L_m / kMm},
                       {"surface_stiffness_N_per_mm", l.force_mesh.surface_stiffness_N_per_m * kMm},
                       {"deformed_threshold_mm", l.force_mesh.deformed_threshold_m / kMm},
                       {"node_damping_N_s_per_m", l.force_mesh.node_damping_N_s_per_m}};
    // The stiffening of the mesh is written only when on (a linear mesh's file stays as it was).
    if (l.force_mesh.surface_axial_stiffness_N_per_m > 0.0)
      j["force_mesh"]["surface_axial_stiffness_N_per_mm"] = l.force_mesh.surface_axial_stiffness_N_per_m * kMm;
    if (l.force_mesh.virtual_stiffening_m > 0.0)
      j["force_mesh"]["virtual_stiffening_mm"] = l.force_mesh.virtual_stiffening_m / kMm;
    j["damping_d_N_s_per_m2"] = l.damping_N_s_per_m2;
    j["resumption_time_s"] = l.resumption_time_s;
    j["force_law"] = force_law_json(l.force_law);
    j["material"] = {{"model", l.material.model},
                     {"youngs_modulus_kPa", l.material.youngs_modulus_Pa / 1e3},
                     {"poisson_ratio", l.material.poisson_ratio},
                     {"mooney_rivlin_c01_fraction", l.material.mooney_rivlin_c01_fraction},
                     {"veronda_westmann_gamma", l.material.veronda_westmann_gamma},
                     {"source", l.material.source}};
    if (!l.material.ogden_terms.empty()) {
      json terms = json::array();
      for (const OgdenTerm& t : l.material.ogden_terms) terms.push_back({{"mu_fraction", t.mu_fraction}, {"alpha", t.alpha}});
      j["material"]["ogden_terms"] = terms;
    }
    if (l.material.viscoelastic.enabled()) j["material"]["viscoelastic"] = viscoelastic_json(l.material.viscoelastic);
    const PunctureCriterion& c = l.puncture;
    if (c.kind == PunctureCriterion::Kind::CriticalForce)
      j["puncture"] = {{"criterion", "critical_force"}, {"critical_force_N", c.critical_force_N}};
    else if (c.kind == PunctureCriterion::Kind::CriticalStretch)
      j["puncture"] = {{"criterion", "critical_stretch"}, {"critical_stretch", c.critical_stretch}};
    else
      j["puncture"] = {{"criterion", "fracture_energy"},
                       {"toughness_J_per_m2", c.toughness_J_per_m2},
                       {"cohesive_strength_kPa", c.cohesive_strength_Pa / 1e3}};
    j["puncture"]["source"] = c.source;
    j["shaft_friction"] = {{"coefficient", l.shaft_friction.dynamic_coefficient},
                           {"static_coefficient", l.shaft_friction.static_coefficient},
                           {"source", l.shaft_friction.source}};
    layers.push_back(j);
  }
  root["layers"] = layers;
  const Insertion& in = s.insertion;
  root["insertion"] = {{"start_height_mm", in.start_height_m / kMm},
                       {"speed_mm_per_s", in.speed_m_per_s / kMm},
                       {"target_depth_mm", in.target_depth_m / kMm},
                       {"dwell_s", in.dwell_s},
                       {"withdrawal_speed_mm_per_s", in.withdrawal_speed_m_per_s / kMm},
                       {"angle_deg", in.angle_deg}};
  root["realtime"] = {{"sh_degree", s.realtime.sh_degree},
                      {"haptic_rate_Hz", s.realtime.haptic_rate_Hz},
                      {"integrator", s.realtime.integrator},
                      {"frame_rate_Hz", s.realtime.frame_rate_Hz}};
  root["fem"] = {{"geometry", s.fem.geometry},
                 {"refinement", s.fem.refinement},
                 {"element_degree", s.fem.element_degree},
                 {"load_step_mm", s.fem.load_step_m / kMm},
                 {"max_newton_iterations", s.fem.max_newton_iterations},
                 {"newton_tolerance", s.fem.newton_tolerance},
                 {"cohesive_viscosity_s", s.fem.cohesive_viscosity_s},
                 {"stabilization_time_s", s.fem.stabilization_time_s},
                 {"mesh",
                  {{"elements_per_needle_radius", s.fem.mesh.elements_per_needle_radius},
                   {"min_elements_per_layer", s.fem.mesh.min_elements_per_layer},
                   {"radial_growth", s.fem.mesh.radial_growth},
                   {"path_element_size_mm", s.fem.mesh.path_element_size_mm}}}};
  root["models"] = s.models;
  json effects = json::array();
  if (s.effects.surface_force) effects.push_back("surface_force");
  if (s.effects.damping) effects.push_back("damping");
  if (s.effects.resumption) effects.push_back("resumption");
  if (s.effects.surface_output) effects.push_back("surface_output");
  if (s.effects.cutting) effects.push_back("cutting");
  if (s.effects.friction) effects.push_back("friction");
  if (s.effects.stiffening) effects.push_back("stiffening");
  if (s.effects.layer_interaction) effects.push_back("layer_interaction");
  if (s.effects.coupled_surfaces) effects.push_back("coupled_surfaces");
  root["effects"] = effects;
  root["haptics"] = {{"max_force_N", s.haptics.max_force_N},
                     {"max_force_rate_N_per_s", s.haptics.max_force_rate_N_per_s},
                     {"device_damping_N_s_per_m", s.haptics.device_damping_N_s_per_m},
                     {"device_max_stiffness_N_per_mm", s.haptics.device_max_stiffness_N_per_m * kMm}};
  const ComparisonSettings& c = s.comparison;
  json comparison = {{"mesh",
                      {{"size_at_axis_mm", c.mesh.size_at_axis_m / kMm},
                       {"size_far_mm", c.mesh.size_far_m / kMm},
                       {"grading", c.mesh.grading}}},
                     {"integrator", c.integrator},
                     {"relative_tolerance", c.relative_tolerance},
                     {"absolute_tolerance_mm", c.absolute_tolerance_m / kMm},
                     {"mass_damping_per_s", c.mass_damping_per_s},
                     {"stiffness_damping_s", c.stiffness_damping_s},
                     {"viscoelastic", {{"prony_g", c.prony_g}, {"prony_tau_s", c.prony_tau_s}}}};
  if (!c.mass_spring_stiffness_scale.empty()) comparison["mass_spring_stiffness_scale"] = c.mass_spring_stiffness_scale;
  root["comparison"] = comparison;
  return root.dump(2) + "\n";
}

}  // namespace puncture
