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

/// The presets' files and layer thicknesses, checked to have the same layers
/// (count and names) as the first.
std::vector<SlabRulePreset> rule_presets(const std::vector<json>& presets, const std::vector<std::string>& names,
                                         const std::vector<PresetCalibration>& calibrations) {
  std::vector<SlabRulePreset> out;
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
    out.push_back(p);
  }
  return out;
}

/// Layer k across the presets: its thickness and the depth of its top on each
/// (mm), and each preset's numeric parameters of the layer by JSON pointer.
struct LayerAcrossSlabs {
  std::size_t k = 0;
  std::string pointer;  ///< "/layers/k"
  std::vector<double> thickness, depth;
  std::vector<std::map<std::string, json>> leaves;
  bool by_thickness = false, by_depth = false;  ///< the variable varies between the presets
};

LayerAcrossSlabs layer_across_slabs(const std::vector<json>& presets, const std::vector<SlabRulePreset>& rule_presets,
                                    std::size_t k) {
  LayerAcrossSlabs l;
  l.k = k;
  l.pointer = "/layers/" + std::to_string(k);
  l.leaves.resize(presets.size());
  for (std::size_t i = 0; i < presets.size(); ++i)
    for (const char* block : kBlocks)
      if (presets[i]["layers"][k].contains(block))
        numeric_leaves(presets[i]["layers"][k][block], std::string("/") + block, l.leaves[i]);
  for (const SlabRulePreset& p : rule_presets) {
    l.thickness.push_back(p.thickness_mm[k]);
    double above = 0.0;
    for (std::size_t j = 0; j < k; ++j) above += p.thickness_mm[j];
    l.depth.push_back(above);
  }
  l.by_thickness = varies(l.thickness);
  l.by_depth = k > 0 && varies(l.depth);
  return l;
}

/// Does the parameter at `pointer` (first preset's value `first_value`)
/// differ between the presets? Each preset must have it.
bool differs_between_presets(const std::string& pointer, const json& first_value, const LayerAcrossSlabs& l,
                             const std::vector<std::string>& names) {
  bool differs = false;
  for (std::size_t i = 1; i < l.leaves.size(); ++i) {
    const auto it = l.leaves[i].find(pointer);
    if (it == l.leaves[i].end()) fail(names[i], l.pointer + pointer, "missing (" + names.front() + " has it)");
    const double a = first_value.get<double>(), b = it->second.get<double>();
    if (std::abs(a - b) > kSameValue * std::max(std::abs(a), std::abs(b))) differs = true;
  }
  return differs;
}

/// A parameter that differs between the presets: its power law in the
/// layer's thickness or depth (whichever predicts the slabs left out better),
/// fitted on the slabs whose calibration identified it, into
/// layer.parameters; or, where too few slabs identified it, the reason into
/// layer.not_ruled.
void rule_parameter(const std::string& pointer, const LayerAcrossSlabs& l, const std::vector<std::string>& names,
                    const std::vector<PresetCalibration>& calibrations, SlabRuleLayer& layer) {
  if (!l.by_thickness && !l.by_depth)
    fail(names.back(), l.pointer + pointer,
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
    const json& v = l.leaves[i].at(pointer);
    integer = integer && v.is_number_integer();
    if (!(v.get<double>() > 0.0) || !std::isfinite(v.get<double>()))
      fail(names[i], l.pointer + pointer,
           "differs between the presets but is not positive (" + significant_digits(v.get<double>(), 4) +
               "): a power law needs positive values");
    y.push_back(std::log(v.get<double>()));
    x_thickness.push_back(l.thickness[i]);
    x_depth.push_back(l.depth[i]);
    files.push_back(names[i]);
  }
  // Enough slabs for a leave-one-out check where the family has them (3),
  // else every slab of a family of two.
  const std::size_t needed = std::min<std::size_t>(3, names.size());
  const bool used_thickness = used.size() >= needed && varies(x_thickness);
  const bool used_depth = used.size() >= needed && l.k > 0 && varies(x_depth);
  if (!used_thickness && !used_depth) {
    std::string why = used.size() < needed
                          ? "identified on " + std::to_string(used.size()) + " of " + std::to_string(names.size()) +
                                " slabs (a rule needs " + std::to_string(needed) +
                                (needed == 3 ? ", so that each slab can be predicted by the others" : "") + ")"
                          : "identified only on slabs where the layer has the same thickness and depth";
    for (const auto& [file, status] : excluded) why += "; " + file + ": " + status;
    layer.not_ruled.push_back({pointer, why});
    return;
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
  rule.presets = rule_presets(presets, names, calibrations);
  const std::size_t n_layers = layers_of(presets.front(), names.front()).size();
  for (std::size_t k = 0; k < n_layers; ++k) {
    const LayerAcrossSlabs across = layer_across_slabs(presets, rule.presets, k);
    SlabRuleLayer layer;
    layer.layer = presets.front()["layers"][k].value("name", std::string());
    layer.reference_thickness_mm = rule.presets.front().thickness_mm[k];
    layer.min_thickness_mm = *std::min_element(across.thickness.begin(), across.thickness.end());
    layer.max_thickness_mm = *std::max_element(across.thickness.begin(), across.thickness.end());
    for (const auto& [pointer, first_value] : across.leaves.front())
      if (differs_between_presets(pointer, first_value, across, names)) rule_parameter(pointer, across, names, calibrations, layer);
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

}  // namespace puncture::validation
