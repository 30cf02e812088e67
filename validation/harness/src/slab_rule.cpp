#include "puncture/validation/slab_rule.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "puncture/validation/number_format.hpp"

namespace puncture::validation {

namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& where, const std::string& pointer, const std::string& what) {
  throw std::invalid_argument(where + ": " + pointer + ": " + what);
}

/// Values within this relative difference are the same value: a calibration
/// that ended where it started moves a kept parameter by round-off only.
constexpr double kSameValue = 1e-4;

/// The parameter blocks of a layer the rule may set.
constexpr const char* kBlocks[] = {"force_mesh", "force_law"};

/// Every numeric leaf under `node`, by JSON pointer relative to the layer.
void numeric_leaves(const json& node, const std::string& pointer, std::map<std::string, json>& out) {
  if (node.is_object()) {
    for (auto it = node.begin(); it != node.end(); ++it) numeric_leaves(*it, pointer + "/" + it.key(), out);
  } else if (node.is_number()) {
    out[pointer] = node;
  }
}

const json& layers_of(const json& preset, const std::string& where) {
  if (!preset.is_object() || !preset.contains("layers") || !preset["layers"].is_array() || preset["layers"].empty())
    fail(where, "/layers", "missing or not a non-empty array");
  return preset["layers"];
}

double thickness_of(const json& layer, const std::string& where, const std::string& pointer) {
  if (!layer.contains("thickness_mm") || !layer["thickness_mm"].is_number() ||
      !std::isfinite(layer["thickness_mm"].get<double>()) || !(layer["thickness_mm"].get<double>() > 0.0))
    fail(where, pointer + "/thickness_mm", "missing or not a positive number (mm)");
  return layer["thickness_mm"].get<double>();
}

/// Least squares y = a + alpha x; out: a, alpha, standard error of alpha
/// (n >= 3), RMS residual (n >= 3).
struct LineFit {
  double intercept = 0.0, slope = 0.0;
  std::optional<double> slope_standard_error, residual_rms;
};

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i] / n, my += y[i] / n;
  double sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
  LineFit f;
  f.slope = sxy / sxx;
  f.intercept = my - f.slope * mx;
  if (x.size() >= 3) {
    double rss = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double r = y[i] - (f.intercept + f.slope * x[i]);
      rss += r * r;
    }
    f.residual_rms = std::sqrt(rss / n);
    f.slope_standard_error = std::sqrt(rss / (n - 2.0) / sxx);
  }
  return f;
}

json or_null(const std::optional<double>& x) { return x ? json(*x) : json(nullptr); }

bool varies(const std::vector<double>& x) {
  for (double xi : x)
    if (std::abs(xi - x.front()) > 1e-9) return true;
  return false;
}

/// The rule of one parameter in one variable: x_mm[i] > 0 and y[i] = ln p on
/// preset i; the fit, its samples and the RMS leave-one-out error in ln p.
SlabRuleParameter fit_in(SlabRuleVariable variable, const std::vector<double>& x_mm, const std::vector<double>& y,
                         const std::vector<std::string>& files, std::optional<double>& leave_one_out_log_rms) {
  std::vector<double> x;
  for (double v : x_mm) x.push_back(std::log(v / x_mm.front()));
  const LineFit f = fit_line(x, y);
  SlabRuleParameter p;
  p.variable = variable;
  p.reference_mm = x_mm.front();
  p.min_mm = *std::min_element(x_mm.begin(), x_mm.end());
  p.max_mm = *std::max_element(x_mm.begin(), x_mm.end());
  p.value_at_reference = std::exp(f.intercept);
  p.exponent = f.slope;
  p.exponent_standard_error = f.slope_standard_error;
  p.log_residual_rms = f.residual_rms;
  double sum_sq = 0.0;
  bool every_slab = x.size() >= 3;
  for (std::size_t i = 0; i < x.size(); ++i) {
    SlabRuleSample s;
    s.file = files[i];
    s.x_mm = x_mm[i];
    s.value = std::exp(y[i]);
    s.fitted = std::exp(f.intercept + f.slope * x[i]);
    if (x.size() >= 3) {
      std::vector<double> xo, yo;
      for (std::size_t j = 0; j < x.size(); ++j)
        if (j != i) xo.push_back(x[j]), yo.push_back(y[j]);
      if (varies(xo)) {
        const LineFit g = fit_line(xo, yo);
        const double predicted = g.intercept + g.slope * x[i];
        s.leave_one_out_relative_error = std::exp(predicted - y[i]) - 1.0;
        sum_sq += (predicted - y[i]) * (predicted - y[i]);
      } else {
        every_slab = false;
      }
    }
    p.samples.push_back(s);
  }
  if (every_slab) leave_one_out_log_rms = std::sqrt(sum_sq / static_cast<double>(x.size()));
  return p;
}

std::optional<double> optional_number(const json& j, const char* key) {
  if (!j.contains(key) || !j[key].is_number()) return std::nullopt;
  return j[key].get<double>();
}

/// The presets whose calibration identified (layer, pointer), every preset
/// without a record among them; the others go to `excluded` as (name, status).
std::vector<std::size_t> identified_slabs(const std::vector<PresetCalibration>& calibrations,
                                          const std::vector<std::string>& names, const std::string& layer,
                                          const std::string& pointer,
                                          std::vector<std::pair<std::string, std::string>>& excluded) {
  std::vector<std::size_t> used;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (calibrations.empty() || !calibrations[i].known) {
      used.push_back(i);
      continue;
    }
    const auto st = calibrations[i].status.find({layer, pointer});
    const std::string status = st == calibrations[i].status.end() ? "not calibrated (kept)" : st->second;
    if (status == "identified") used.push_back(i);
    else excluded.emplace_back(names[i], status);
  }
  return used;
}

}  // namespace

const char* slab_rule_variable_name(SlabRuleVariable variable) {
  return variable == SlabRuleVariable::depth ? "depth" : "thickness";
}

double slab_rule_value(const SlabRuleParameter& parameter, double x_mm) {
  const double p = parameter.value_at_reference * std::pow(x_mm / parameter.reference_mm, parameter.exponent);
  return parameter.integer ? std::max(1.0, std::round(p)) : p;
}

PresetCalibration read_preset_calibration(const json& provenance, const std::string& where) {
  PresetCalibration c;
  if (!provenance.is_object() || !provenance.contains("calibrated_values")) return c;
  const json& values = provenance["calibrated_values"];
  if (!values.is_array()) fail(where, "/calibrated_values", "not an array");
  c.known = true;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const json& v = values[i];
    const std::string pointer = "/calibrated_values/" + std::to_string(i);
    for (const char* key : {"layer", "pointer", "status"})
      if (!v.is_object() || !v.contains(key) || !v[key].is_string()) fail(where, pointer + "/" + key, "missing or not a string");
    c.status[{v["layer"].get<std::string>(), v["pointer"].get<std::string>()}] = v["status"].get<std::string>();
  }
  return c;
}

SlabRule fit_slab_rule(const std::vector<json>& presets, const std::vector<std::string>& names,
                       const std::vector<PresetCalibration>& calibrations) {
  if (presets.size() != names.size()) throw std::invalid_argument("fit_slab_rule: one name per preset");
  if (!calibrations.empty() && calibrations.size() != presets.size())
    throw std::invalid_argument("fit_slab_rule: one calibration record per preset, or none");
  if (presets.size() < 2) throw std::invalid_argument("a slab rule needs presets calibrated on two slabs or more");
  SlabRule rule;
  const json& first_layers = layers_of(presets.front(), names.front());
  for (std::size_t i = 0; i < presets.size(); ++i) {
    const json& layers = layers_of(presets[i], names[i]);
    if (layers.size() != first_layers.size())
      fail(names[i], "/layers", "has " + std::to_string(layers.size()) + " layers, " + names.front() + " has " +
                                    std::to_string(first_layers.size()));
    SlabRulePreset p;
    p.file = names[i];
    p.calibration_record = !calibrations.empty() && calibrations[i].known;
    for (std::size_t k = 0; k < layers.size(); ++k) {
      const std::string pointer = "/layers/" + std::to_string(k);
      const std::string name = layers[k].value("name", std::string());
      if (name != first_layers[k].value("name", std::string()))
        fail(names[i], pointer + "/name", "\"" + name + "\" where " + names.front() + " has \"" +
                                              first_layers[k].value("name", std::string()) + "\"");
      p.thickness_mm.push_back(thickness_of(layers[k], names[i], pointer));
    }
    rule.presets.push_back(p);
  }

  for (std::size_t k = 0; k < first_layers.size(); ++k) {
    const std::string layer_pointer = "/layers/" + std::to_string(k);
    // Each preset's numeric parameters of this layer.
    std::vector<std::map<std::string, json>> leaves(presets.size());
    for (std::size_t i = 0; i < presets.size(); ++i)
      for (const char* block : kBlocks)
        if (presets[i]["layers"][k].contains(block))
          numeric_leaves(presets[i]["layers"][k][block], std::string("/") + block, leaves[i]);
    // The two variables on each preset: the layer's thickness and the depth of its top.
    std::vector<double> thickness, depth;
    for (const SlabRulePreset& p : rule.presets) {
      thickness.push_back(p.thickness_mm[k]);
      double above = 0.0;
      for (std::size_t j = 0; j < k; ++j) above += p.thickness_mm[j];
      depth.push_back(above);
    }
    const bool by_thickness = varies(thickness), by_depth = k > 0 && varies(depth);
    SlabRuleLayer layer;
    layer.layer = first_layers[k].value("name", std::string());
    layer.reference_thickness_mm = rule.presets.front().thickness_mm[k];
    layer.min_thickness_mm = layer.max_thickness_mm = layer.reference_thickness_mm;
    for (const SlabRulePreset& p : rule.presets) {
      layer.min_thickness_mm = std::min(layer.min_thickness_mm, p.thickness_mm[k]);
      layer.max_thickness_mm = std::max(layer.max_thickness_mm, p.thickness_mm[k]);
    }
    for (const auto& [pointer, first_value] : leaves.front()) {
      bool differs = false;
      for (std::size_t i = 1; i < presets.size(); ++i) {
        const auto it = leaves[i].find(pointer);
        if (it == leaves[i].end())
          fail(names[i], layer_pointer + pointer, "missing (" + names.front() + " has it)");
        const double a = first_value.get<double>(), b = it->second.get<double>();
        if (std::abs(a - b) > kSameValue * std::max(std::abs(a), std::abs(b))) differs = true;
      }
      if (!differs) continue;
      if (!by_thickness && !by_depth)
        fail(names.back(), layer_pointer + pointer,
             "differs between the presets, but layer " + layer.layer +
                 " has the same thickness and depth in all of them: the rule needs the layer at two thicknesses "
                 "or depths or more");
      // Only the slabs whose calibration identified the value enter the fit.
      std::vector<std::pair<std::string, std::string>> excluded;
      const std::vector<std::size_t> used = identified_slabs(calibrations, names, layer.layer, pointer, excluded);
      std::vector<double> y, x_thickness, x_depth;
      std::vector<std::string> files;
      bool integer = true;
      for (std::size_t i : used) {
        const json& v = leaves[i].at(pointer);
        integer = integer && v.is_number_integer();
        if (!(v.get<double>() > 0.0) || !std::isfinite(v.get<double>()))
          fail(names[i], layer_pointer + pointer,
               "differs between the presets but is not positive (" + significant_digits(v.get<double>(), 4) +
                   "): a power law needs positive values");
        y.push_back(std::log(v.get<double>()));
        x_thickness.push_back(thickness[i]);
        x_depth.push_back(depth[i]);
        files.push_back(names[i]);
      }
      // Enough slabs for a leave-one-out check where the family has them (3),
      // else every slab of a family of two.
      const std::size_t needed = std::min<std::size_t>(3, presets.size());
      const bool used_thickness = used.size() >= needed && varies(x_thickness);
      const bool used_depth = used.size() >= needed && k > 0 && varies(x_depth);
      if (!used_thickness && !used_depth) {
        std::string why = used.size() < needed
                              ? "identified on " + std::to_string(used.size()) + " of " + std::to_string(presets.size()) +
                                    " slabs (a rule needs " + std::to_string(needed) +
                                    (needed == 3 ? ", so that each slab can be predicted by the others" : "") + ")"
                              : "identified only on slabs where the layer has the same thickness and depth";
        for (const auto& [file, status] : excluded) why += "; " + file + ": " + status;
        layer.not_ruled.push_back({pointer, why});
        continue;
      }
      std::optional<double> loo_thickness, loo_depth;
      std::optional<SlabRuleParameter> in_thickness, in_depth;
      if (used_thickness) in_thickness = fit_in(SlabRuleVariable::thickness, x_thickness, y, files, loo_thickness);
      if (used_depth) in_depth = fit_in(SlabRuleVariable::depth, x_depth, y, files, loo_depth);
      // The depth where it predicts the slabs left out better, or where the thickness does not vary.
      const bool use_depth = in_depth && (!in_thickness || (loo_depth && loo_thickness && *loo_depth < *loo_thickness));
      SlabRuleParameter p = use_depth ? *in_depth : *in_thickness;
      p.pointer = pointer;
      p.integer = integer;
      p.excluded = excluded;
      p.leave_one_out_log_rms_thickness = loo_thickness;
      p.leave_one_out_log_rms_depth = loo_depth;
      layer.parameters.push_back(p);
    }
    if (!layer.parameters.empty() || !layer.not_ruled.empty()) rule.layers.push_back(layer);
  }
  return rule;
}

std::vector<std::string> apply_slab_rule(json& scene, const SlabRule& rule, const std::string& where) {
  std::vector<std::string> notes;
  const json& layers = layers_of(scene, where);
  for (std::size_t k = 0; k < layers.size(); ++k) {
    const std::string name = layers[k].value("name", std::string());
    const auto r = std::find_if(rule.layers.begin(), rule.layers.end(),
                                [&](const SlabRuleLayer& l) { return l.layer == name; });
    if (r == rule.layers.end()) continue;
    const std::string layer_pointer = "/layers/" + std::to_string(k);
    const double h = thickness_of(layers[k], where, layer_pointer);
    double depth = 0.0;
    for (std::size_t j = 0; j < k; ++j) depth += thickness_of(layers[j], where, "/layers/" + std::to_string(j));
    bool noted[2] = {false, false};
    for (const SlabRuleParameter& p : r->parameters) {
      const json::json_pointer ptr(layer_pointer + p.pointer);
      if (!scene.contains(ptr) || !scene[ptr].is_number())
        fail(where, layer_pointer + p.pointer, "the slab rule sets it, but the scene has no such number");
      const bool by_depth = p.variable == SlabRuleVariable::depth;
      const double x = by_depth ? depth : h;
      if (!(x > 0.0)) fail(where, layer_pointer, std::string("the slab rule needs the layer's ") +
                                                     slab_rule_variable_name(p.variable) + " > 0");
      const double tolerance = 1e-9 * p.max_mm;
      if ((x < p.min_mm - tolerance || x > p.max_mm + tolerance) && !noted[by_depth]) {
        noted[by_depth] = true;
        notes.push_back("layer " + name + ": its " + slab_rule_variable_name(p.variable) + " " +
                        significant_digits(x, 4) + " mm lies outside the family's " + significant_digits(p.min_mm, 4) +
                        " - " + significant_digits(p.max_mm, 4) + " mm (extrapolated)");
      }
      const double value = slab_rule_value(p, x);
      scene[ptr] = p.integer ? json(static_cast<long long>(value)) : json(value);
    }
  }
  return notes;
}

namespace {

json excluded_json(const std::vector<std::pair<std::string, std::string>>& excluded) {
  json a = json::array();
  for (const auto& [file, status] : excluded) a.push_back({{"file", file}, {"status", status}});
  return a;
}

}  // namespace

json slab_rule_json(const SlabRule& rule, const json& provenance) {
  json presets = json::array();
  for (const SlabRulePreset& p : rule.presets)
    presets.push_back({{"file", p.file}, {"thickness_mm", p.thickness_mm}, {"calibration_record", p.calibration_record}});
  json layers = json::array();
  for (const SlabRuleLayer& l : rule.layers) {
    json parameters = json::array();
    for (const SlabRuleParameter& p : l.parameters) {
      json samples = json::array();
      for (const SlabRuleSample& s : p.samples)
        samples.push_back({{"file", s.file},
                           {"x_mm", s.x_mm},
                           {"value", s.value},
                           {"fitted", s.fitted},
                           {"leave_one_out_relative_error", or_null(s.leave_one_out_relative_error)}});
      parameters.push_back({{"pointer", p.pointer},
                            {"variable", slab_rule_variable_name(p.variable)},
                            {"reference_mm", p.reference_mm},
                            {"range_mm", {p.min_mm, p.max_mm}},
                            {"value_at_reference", p.value_at_reference},
                            {"exponent", p.exponent},
                            {"exponent_standard_error", or_null(p.exponent_standard_error)},
                            {"log_residual_rms", or_null(p.log_residual_rms)},
                            {"integer", p.integer},
                            {"leave_one_out_log_rms",
                             {{"thickness", or_null(p.leave_one_out_log_rms_thickness)},
                              {"depth", or_null(p.leave_one_out_log_rms_depth)}}},
                            {"samples", samples},
                            {"excluded", excluded_json(p.excluded)}});
    }
    json not_ruled = json::array();
    for (const SlabRuleNotRuled& n : l.not_ruled) not_ruled.push_back({{"pointer", n.pointer}, {"reason", n.reason}});
    layers.push_back({{"layer", l.layer},
                      {"reference_thickness_mm", l.reference_thickness_mm},
                      {"thickness_range_mm", {l.min_thickness_mm, l.max_thickness_mm}},
                      {"parameters", parameters},
                      {"not_ruled", not_ruled}});
  }
  return {{"description",
           "Real-time parameters of a slab from each layer's geometry: p(x) = value_at_reference * "
           "(x / reference_mm)^exponent, x the layer's thickness or the depth of its top (\"variable\", the one "
           "with the smaller leave-one-out error), least squares in ln p over presets calibrated on a family of "
           "slabs (validation/harness/include/puncture/validation/slab_rule.hpp), each slab's value only where its "
           "calibration identified it (\"excluded\": the others, with their status). Parameters not listed, and "
           "those \"not_ruled\", are the scene's own."},
          {"presets", presets},
          {"layers", layers},
          {"provenance", provenance}};
}

SlabRule read_slab_rule(const std::filesystem::path& file) {
  const std::string where = file.string();
  std::ifstream in(file);
  if (!in) throw std::invalid_argument(where + ": cannot open the slab rule file");
  json root;
  try {
    root = json::parse(in);
  } catch (const json::parse_error& e) {
    throw std::invalid_argument(where + ": not valid JSON: " + e.what());
  }
  if (!root.is_object() || !root.contains("layers") || !root["layers"].is_array())
    fail(where, "/layers", "missing or not an array");
  SlabRule rule;
  if (root.contains("presets") && root["presets"].is_array())
    for (const json& p : root["presets"]) {
      SlabRulePreset preset;
      preset.file = p.value("file", std::string());
      preset.calibration_record = p.value("calibration_record", false);
      if (p.contains("thickness_mm") && p["thickness_mm"].is_array())
        for (const json& t : p["thickness_mm"])
          if (t.is_number()) preset.thickness_mm.push_back(t.get<double>());
      rule.presets.push_back(preset);
    }
  const auto positive = [&](const json& j, const char* key, const std::string& pointer) {
    if (!j.contains(key) || !j[key].is_number() || !std::isfinite(j[key].get<double>()) || !(j[key].get<double>() > 0.0))
      fail(where, pointer + "/" + key, "missing or not a positive number");
    return j[key].get<double>();
  };
  const auto range = [&](const json& j, const char* key, const std::string& pointer) {
    if (!j.contains(key) || !j[key].is_array() || j[key].size() != 2 || !j[key][0].is_number() ||
        !j[key][1].is_number() || !(j[key][0].get<double>() <= j[key][1].get<double>()))
      fail(where, pointer + "/" + key, "must be [min, max] in mm");
    return std::pair<double, double>(j[key][0].get<double>(), j[key][1].get<double>());
  };
  for (std::size_t k = 0; k < root["layers"].size(); ++k) {
    const json& l = root["layers"][k];
    const std::string lp = "/layers/" + std::to_string(k);
    if (!l.is_object() || !l.contains("layer") || !l["layer"].is_string()) fail(where, lp + "/layer", "missing or not a string");
    SlabRuleLayer layer;
    layer.layer = l["layer"].get<std::string>();
    layer.reference_thickness_mm = positive(l, "reference_thickness_mm", lp);
    std::tie(layer.min_thickness_mm, layer.max_thickness_mm) = range(l, "thickness_range_mm", lp);
    if (!l.contains("parameters") || !l["parameters"].is_array()) fail(where, lp + "/parameters", "missing or not an array");
    for (std::size_t j = 0; j < l["parameters"].size(); ++j) {
      const json& p = l["parameters"][j];
      const std::string pp = lp + "/parameters/" + std::to_string(j);
      if (!p.is_object() || !p.contains("pointer") || !p["pointer"].is_string() ||
          p["pointer"].get<std::string>().rfind("/force_", 0) != 0)
        fail(where, pp + "/pointer", "missing or not a pointer into /force_mesh or /force_law");
      SlabRuleParameter parameter;
      parameter.pointer = p["pointer"].get<std::string>();
      if (!p.contains("variable") || !p["variable"].is_string() ||
          (p["variable"] != "thickness" && p["variable"] != "depth"))
        fail(where, pp + "/variable", "missing or not \"thickness\" or \"depth\"");
      parameter.variable = p["variable"] == "depth" ? SlabRuleVariable::depth : SlabRuleVariable::thickness;
      parameter.reference_mm = positive(p, "reference_mm", pp);
      std::tie(parameter.min_mm, parameter.max_mm) = range(p, "range_mm", pp);
      parameter.value_at_reference = positive(p, "value_at_reference", pp);
      if (!p.contains("exponent") || !p["exponent"].is_number() || !std::isfinite(p["exponent"].get<double>()))
        fail(where, pp + "/exponent", "missing or not a finite number");
      parameter.exponent = p["exponent"].get<double>();
      parameter.exponent_standard_error = optional_number(p, "exponent_standard_error");
      parameter.log_residual_rms = optional_number(p, "log_residual_rms");
      parameter.integer = p.contains("integer") && p["integer"].is_boolean() && p["integer"].get<bool>();
      if (p.contains("leave_one_out_log_rms") && p["leave_one_out_log_rms"].is_object()) {
        parameter.leave_one_out_log_rms_thickness = optional_number(p["leave_one_out_log_rms"], "thickness");
        parameter.leave_one_out_log_rms_depth = optional_number(p["leave_one_out_log_rms"], "depth");
      }
      if (p.contains("samples") && p["samples"].is_array())
        for (const json& s : p["samples"]) {
          SlabRuleSample sample;
          sample.file = s.value("file", std::string());
          sample.x_mm = s.value("x_mm", 0.0);
          sample.value = s.value("value", 0.0);
          sample.fitted = s.value("fitted", 0.0);
          sample.leave_one_out_relative_error = optional_number(s, "leave_one_out_relative_error");
          parameter.samples.push_back(sample);
        }
      if (p.contains("excluded") && p["excluded"].is_array())
        for (const json& e : p["excluded"])
          parameter.excluded.emplace_back(e.value("file", std::string()), e.value("status", std::string()));
      layer.parameters.push_back(parameter);
    }
    if (l.contains("not_ruled") && l["not_ruled"].is_array())
      for (const json& n : l["not_ruled"])
        layer.not_ruled.push_back({n.value("pointer", std::string()), n.value("reason", std::string())});
    rule.layers.push_back(layer);
  }
  return rule;
}

namespace {

std::string percent(const std::optional<double>& x) {
  if (!x) return "n/a";
  return (*x >= 0 ? "+" : "") + significant_digits(100.0 * *x, 3) + " %";
}

/// A leave-one-out RMS in ln p as the relative error it stands for.
std::string log_rms_percent(const std::optional<double>& x) {
  return x ? significant_digits(100.0 * (std::exp(*x) - 1.0), 3) + " %" : "n/a";
}

}  // namespace

std::string slab_rule_markdown(const SlabRule& rule, const std::string& command, const std::string& provenance_line) {
  std::ostringstream md;
  md << "# Slab rule: real-time parameters from each layer's geometry\n\n"
     << "Command: `" << command << "`, " << provenance_line << ".\n\n"
     << "Each preset below is the same model calibrated on its own slab. For every parameter whose calibrated "
        "value differs between them, p(x) = p_ref (x / x_ref)^alpha, least squares in ln p (x_ref: the first "
        "fitted slab's), where x is the layer's own thickness or the depth of its top (the thickness of the layers "
        "above it), whichever predicts the slabs left out better: the leave-one-out error of either is the rule "
        "fitted without one slab, predicting it, RMS over the slabs (the own thickness when it cannot be told). "
        "A slab's value enters the fit only where its calibration identified it (its provenance's "
        "`calibrated_values`); values at a bound, not identifiable or not set by that calibration are left out "
        "(shown as such), and a parameter identified on fewer than three slabs (two in a family of two: a power "
        "law through two points has no leave-one-out check) is not ruled (listed below with why). Parameters not listed, and those not ruled, keep the scene's value. A slab the family never saw "
        "takes its parameters from this rule (`puncture validate MODEL --cases FILE --slab-rule slab_rule.json`), "
        "never from a calibration on that slab.\n\n## The family\n\n| preset | thickness (mm) | which values "
        "its calibration identified |\n|---|---|---|\n";
  for (const SlabRulePreset& p : rule.presets) {
    md << "| " << p.file << " | ";
    for (std::size_t k = 0; k < p.thickness_mm.size(); ++k) md << (k ? " / " : "") << significant_digits(p.thickness_mm[k], 4);
    md << " | " << (p.calibration_record ? "from its provenance" : "no record: every value taken as identified") << " |\n";
  }
  md << "\n## The rule\n\nValues calibrated on each slab (in the family's order; in brackets, a slab left out and its "
        "calibration's status of the value) -> the rule's; alpha +- its standard "
        "error; per slab, the rule fitted without it, at its x, relative to its calibrated value; the leave-one-out "
        "RMS of either variable (the chosen one in bold).\n\n"
     << "| layer | parameter | x | x_ref (mm) | p_ref | alpha | calibrated -> rule | leave-one-out error per slab | "
        "leave-one-out RMS: thickness / depth |\n"
     << "|---|---|---|---|---|---|---|---|---|\n";
  for (const SlabRuleLayer& l : rule.layers)
    for (const SlabRuleParameter& p : l.parameters) {
      const bool by_depth = p.variable == SlabRuleVariable::depth;
      md << "| " << l.layer << " | `" << p.pointer << "`" << (p.integer ? " (a count: rounded)" : "") << " | "
         << (by_depth ? "depth of its top" : "own thickness") << " | " << significant_digits(p.reference_mm, 4)
         << " | " << significant_digits(p.value_at_reference, 4) << " | " << significant_digits(p.exponent, 3);
      if (p.exponent_standard_error) md << " +- " << significant_digits(*p.exponent_standard_error, 2);
      // One entry per slab of the family: its sample, or why it was left out.
      std::vector<std::string> fitted, left_out;
      for (const SlabRulePreset& preset : rule.presets) {
        const auto sample = std::find_if(p.samples.begin(), p.samples.end(),
                                         [&](const SlabRuleSample& x) { return x.file == preset.file; });
        if (sample != p.samples.end()) {
          fitted.push_back(significant_digits(sample->value, 4) + " -> " + significant_digits(sample->fitted, 4));
          left_out.push_back(percent(sample->leave_one_out_relative_error));
          continue;
        }
        const auto why = std::find_if(p.excluded.begin(), p.excluded.end(),
                                      [&](const auto& e) { return e.first == preset.file; });
        fitted.push_back("(" + (why != p.excluded.end() ? why->second : std::string("not in the fit")) + ")");
        left_out.push_back("-");
      }
      md << " | ";
      for (std::size_t i = 0; i < fitted.size(); ++i) md << (i ? "; " : "") << fitted[i];
      md << " | ";
      for (std::size_t i = 0; i < left_out.size(); ++i) md << (i ? "; " : "") << left_out[i];
      const std::string t = log_rms_percent(p.leave_one_out_log_rms_thickness);
      const std::string d = log_rms_percent(p.leave_one_out_log_rms_depth);
      md << " | " << (by_depth ? t : "**" + t + "**") << " / " << (by_depth ? "**" + d + "**" : d) << " |\n";
    }
  if (rule.layers.empty()) md << "| - | no parameter differs between the presets | | | | | | | |\n";
  bool any_not_ruled = false;
  for (const SlabRuleLayer& l : rule.layers) any_not_ruled = any_not_ruled || !l.not_ruled.empty();
  if (any_not_ruled) {
    md << "\n## Not ruled\n\nThese differ between the presets, but too few slabs identified them: a scene keeps its "
          "own value.\n\n| layer | parameter | why |\n|---|---|---|\n";
    for (const SlabRuleLayer& l : rule.layers)
      for (const SlabRuleNotRuled& n : l.not_ruled) md << "| " << l.layer << " | `" << n.pointer << "` | " << n.reason << " |\n";
  }
  return md.str();
}

}  // namespace puncture::validation
