// scene_io.cpp: strict JSON reader for scene files. Each object is read
// through an ObjectReader that records which keys were consumed, so unknown
// keys (typos) are reported instead of silently ignored.
#include "puncture/scene_io.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

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
  std::string child(const std::string& key) const { return path_ + "/" + key; }
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

const std::set<std::string> kEffects{"surface_force", "damping", "resumption", "surface_output"};
const std::set<std::string> kModels{"realtime", "fem"};

ForceMeshParams read_force_mesh(ObjectReader r) {
  ForceMeshParams p;
  p.virtual_stiffness_N_per_m = r.number("K_N_per_mm") / kMm;
  p.rings_w = r.integer("w");
  p.spacing_L_m = r.number("L_mm") * kMm;
  p.surface_stiffness_N_per_m = r.number("surface_stiffness_N_per_mm", p.surface_stiffness_N_per_m * kMm) / kMm;
  p.deformed_threshold_m = r.number("deformed_threshold_mm", p.deformed_threshold_m / kMm) * kMm;
  p.node_damping_N_s_per_m = r.number("node_damping_N_s_per_m", p.node_damping_N_s_per_m);
  r.reject_unknown_keys();
  return p;
}

ContinuumMaterial read_material(ObjectReader r) {
  ContinuumMaterial m;
  m.model = r.string("model", m.model);
  m.youngs_modulus_Pa = r.number("youngs_modulus_kPa") * 1e3;
  m.poisson_ratio = r.number("poisson_ratio");
  m.mooney_rivlin_c01_fraction = r.number("mooney_rivlin_c01_fraction", m.mooney_rivlin_c01_fraction);
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
  } else {
    r.fail(r.child("criterion"), "unknown criterion '" + kind + "' (known: critical_force, critical_stretch)");
  }
  r.reject_unknown_keys();
  return c;
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

Layer read_layer(ObjectReader r, const std::string& file) {
  Layer l;
  l.name = r.string("name");
  l.thickness_m = r.number("thickness_mm") * kMm;
  l.density_kg_per_m3 = r.number("density_kg_per_m3", l.density_kg_per_m3);
  l.force_mesh = read_force_mesh(ObjectReader(r.raw("force_mesh"), r.child("force_mesh"), file));
  l.damping_N_s_per_m2 = r.number("damping_d_N_s_per_m2");
  l.resumption_rate = r.number("resumption_rate", l.resumption_rate);
  if (r.has("material")) l.material = read_material(ObjectReader(r.raw("material"), r.child("material"), file));
  if (r.has("puncture")) l.puncture = read_puncture(ObjectReader(r.raw("puncture"), r.child("puncture"), file));
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

  {
    ObjectReader o(r.raw("sample"), "/sample", file);
    s.sample.diameter_m = o.number("diameter_mm") * kMm;
    o.reject_unknown_keys();
  }
  {
    ObjectReader o(r.raw("needle"), "/needle", file);
    s.needle.radius_m = o.number("radius_mm") * kMm;
    s.needle.tip = o.string("tip", s.needle.tip);
    o.reject_unknown_keys();
  }
  {
    const json& layers = r.raw("layers");
    if (!layers.is_array()) r.fail("/layers", "must be an array of layer objects");
    for (std::size_t i = 0; i < layers.size(); ++i)
      s.layers.push_back(read_layer(ObjectReader(layers[i], "/layers/" + std::to_string(i), file), file));
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
    f.refinement = o.integer("refinement", f.refinement);
    f.element_degree = o.integer("element_degree", f.element_degree);
    f.load_step_m = o.number("load_step_mm", f.load_step_m / kMm) * kMm;
    f.max_newton_iterations = o.integer("max_newton_iterations", f.max_newton_iterations);
    f.newton_tolerance = o.number("newton_tolerance", f.newton_tolerance);
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
  }
  r.reject_unknown_keys();
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

}  // namespace

void validate_scene(const Scene& s, const std::string& file) {
  require(s.sample.diameter_m > 0, file, "/sample/diameter_mm", "> 0", s.sample.diameter_m / kMm);
  const double sample_radius = 0.5 * s.sample.diameter_m;
  require(s.needle.radius_m > 0, file, "/needle/radius_mm", "> 0", s.needle.radius_m / kMm);
  require(s.needle.radius_m < 0.25 * sample_radius, file, "/needle/radius_mm",
          "smaller than a quarter of the sample radius", s.needle.radius_m / kMm);
  if (s.needle.tip != "blunt")
    throw SceneError(file, "/needle/tip", "unknown tip shape '" + s.needle.tip + "' (known: blunt)");

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
    require(l.damping_N_s_per_m2 >= 0, file, p + "/damping_d_N_s_per_m2", ">= 0", l.damping_N_s_per_m2);
    require(l.resumption_rate > 0 && l.resumption_rate <= 1, file, p + "/resumption_rate", "in (0, 1]",
            l.resumption_rate);
    const ContinuumMaterial& m = l.material;
    if (m.model != "neo_hookean" && m.model != "mooney_rivlin")
      throw SceneError(file, p + "/material/model",
                       "unknown material model '" + m.model + "' (known: neo_hookean, mooney_rivlin)");
    require(m.youngs_modulus_Pa > 0, file, p + "/material/youngs_modulus_kPa", "> 0", m.youngs_modulus_Pa / 1e3);
    require(m.poisson_ratio > -1 && m.poisson_ratio < 0.5, file, p + "/material/poisson_ratio", "in (-1, 0.5)",
            m.poisson_ratio);
    require(m.mooney_rivlin_c01_fraction >= 0 && m.mooney_rivlin_c01_fraction < 1, file,
            p + "/material/mooney_rivlin_c01_fraction", "in [0, 1)", m.mooney_rivlin_c01_fraction);
    if (l.puncture.kind == PunctureCriterion::Kind::CriticalForce)
      require(l.puncture.critical_force_N > 0, file, p + "/puncture/critical_force_N", "> 0",
              l.puncture.critical_force_N);
    else
      require(l.puncture.critical_stretch > 1, file, p + "/puncture/critical_stretch", "> 1",
              l.puncture.critical_stretch);
  }

  const Insertion& in = s.insertion;
  require(in.start_height_m >= 0, file, "/insertion/start_height_mm", ">= 0", in.start_height_m / kMm);
  require(in.speed_m_per_s >= 0, file, "/insertion/speed_mm_per_s", ">= 0", in.speed_m_per_s / kMm);
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
  require(f.refinement >= 0 && f.refinement <= 4, file, "/fem/refinement", "in [0, 4]", f.refinement);
  require(f.element_degree == 1 || f.element_degree == 2, file, "/fem/element_degree", "1 or 2", f.element_degree);
  require(f.load_step_m > 0, file, "/fem/load_step_mm", "> 0", f.load_step_m / kMm);
  require(f.max_newton_iterations >= 1, file, "/fem/max_newton_iterations", ">= 1", f.max_newton_iterations);
  require(f.newton_tolerance > 0 && f.newton_tolerance < 1, file, "/fem/newton_tolerance", "in (0, 1)",
          f.newton_tolerance);
  if (s.models.empty()) throw SceneError(file, "/models", "must name at least one model (realtime, fem)");

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
  json root;
  try {
    root = json::parse(text);
  } catch (const json::out_of_range& e) {
    throw SceneError(source_name, "", std::string("number out of range: ") + e.what());
  } catch (const json::parse_error& e) {
    // e.what() names the byte position; keep it, drop nlohmann's prefix.
    std::string what = e.what();
    const auto pos = what.find("parse error");
    throw SceneError(source_name, "", "malformed JSON: " + (pos == std::string::npos ? what : what.substr(pos)));
  }
  return read_scene(root, source_name);
}

Scene load_scene(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw SceneError(path.string(), "", "cannot open scene file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_scene(buffer.str(), path.string());
}

std::string scene_to_json_text(const Scene& s) {
  json root;
  root["schema_version"] = kSchemaVersion;
  root["name"] = s.name;
  root["description"] = s.description;
  root["sample"] = {{"diameter_mm", s.sample.diameter_m / kMm}};
  root["needle"] = {{"radius_mm", s.needle.radius_m / kMm}, {"tip", s.needle.tip}};
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
    j["damping_d_N_s_per_m2"] = l.damping_N_s_per_m2;
    j["resumption_rate"] = l.resumption_rate;
    j["material"] = {{"model", l.material.model},
                     {"youngs_modulus_kPa", l.material.youngs_modulus_Pa / 1e3},
                     {"poisson_ratio", l.material.poisson_ratio},
                     {"mooney_rivlin_c01_fraction", l.material.mooney_rivlin_c01_fraction},
                     {"source", l.material.source}};
    if (l.puncture.kind == PunctureCriterion::Kind::CriticalForce)
      j["puncture"] = {{"criterion", "critical_force"}, {"critical_force_N", l.puncture.critical_force_N}};
    else
      j["puncture"] = {{"criterion", "critical_stretch"}, {"critical_stretch", l.puncture.critical_stretch}};
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
  root["fem"] = {{"refinement", s.fem.refinement},
                 {"element_degree", s.fem.element_degree},
                 {"load_step_mm", s.fem.load_step_m / kMm},
                 {"max_newton_iterations", s.fem.max_newton_iterations},
                 {"newton_tolerance", s.fem.newton_tolerance}};
  root["models"] = s.models;
  json effects = json::array();
  if (s.effects.surface_force) effects.push_back("surface_force");
  if (s.effects.damping) effects.push_back("damping");
  if (s.effects.resumption) effects.push_back("resumption");
  if (s.effects.surface_output) effects.push_back("surface_output");
  root["effects"] = effects;
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
