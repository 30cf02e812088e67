#include "puncture/validation/slab_rule.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

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

std::optional<double> optional_number(const json& j, const char* key) {
  if (!j.contains(key) || !j[key].is_number()) return std::nullopt;
  return j[key].get<double>();
}

}  // namespace

double slab_rule_value(const SlabRuleParameter& parameter, double reference_thickness_mm, double thickness_mm) {
  const double p = parameter.value_at_reference * std::pow(thickness_mm / reference_thickness_mm, parameter.exponent);
  return parameter.integer ? std::max(1.0, std::round(p)) : p;
}

SlabRule fit_slab_rule(const std::vector<json>& presets, const std::vector<std::string>& names) {
  if (presets.size() != names.size()) throw std::invalid_argument("fit_slab_rule: one name per preset");
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
    std::vector<double> x;
    for (const SlabRulePreset& p : rule.presets) x.push_back(std::log(p.thickness_mm[k] / rule.presets.front().thickness_mm[k]));
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
      std::vector<double> y;
      bool integer = true;
      for (std::size_t i = 0; i < presets.size(); ++i) {
        const json& v = leaves[i].at(pointer);
        integer = integer && v.is_number_integer();
        if (!(v.get<double>() > 0.0) || !std::isfinite(v.get<double>()))
          fail(names[i], layer_pointer + pointer,
               "differs between the presets but is not positive (" + significant_digits(v.get<double>(), 4) +
                   "): a power law in the thickness needs positive values");
        y.push_back(std::log(v.get<double>()));
      }
      double spread = 0.0;
      for (double xi : x) spread = std::max(spread, std::abs(xi - x.front()));
      if (spread < 1e-9)
        fail(names.back(), layer_pointer + pointer,
             "differs between the presets, but layer " + layer.layer +
                 " has the same thickness in all of them: the rule needs the layer at two thicknesses or more");
      const LineFit f = fit_line(x, y);
      SlabRuleParameter p;
      p.pointer = pointer;
      p.value_at_reference = std::exp(f.intercept);
      p.exponent = f.slope;
      p.exponent_standard_error = f.slope_standard_error;
      p.log_residual_rms = f.residual_rms;
      p.integer = integer;
      for (std::size_t i = 0; i < presets.size(); ++i) {
        SlabRuleSample s;
        s.thickness_mm = rule.presets[i].thickness_mm[k];
        s.value = std::exp(y[i]);
        s.fitted = std::exp(f.intercept + f.slope * x[i]);
        if (presets.size() >= 3) {
          std::vector<double> xo, yo;
          for (std::size_t j = 0; j < presets.size(); ++j)
            if (j != i) xo.push_back(x[j]), yo.push_back(y[j]);
          double spread_o = 0.0;
          for (double xj : xo) spread_o = std::max(spread_o, std::abs(xj - xo.front()));
          if (spread_o > 1e-9) {
            const LineFit g = fit_line(xo, yo);
            s.leave_one_out_relative_error = std::exp(g.intercept + g.slope * x[i]) / s.value - 1.0;
          }
        }
        p.samples.push_back(s);
      }
      layer.parameters.push_back(p);
    }
    if (!layer.parameters.empty()) rule.layers.push_back(layer);
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
    const double tolerance = 1e-9 * r->max_thickness_mm;
    if (h < r->min_thickness_mm - tolerance || h > r->max_thickness_mm + tolerance)
      notes.push_back("layer " + name + ": " + significant_digits(h, 4) + " mm lies outside the family's " +
                      significant_digits(r->min_thickness_mm, 4) + " - " + significant_digits(r->max_thickness_mm, 4) +
                      " mm (extrapolated)");
    for (const SlabRuleParameter& p : r->parameters) {
      const json::json_pointer ptr(layer_pointer + p.pointer);
      if (!scene.contains(ptr) || !scene[ptr].is_number())
        fail(where, layer_pointer + p.pointer, "the slab rule sets it, but the scene has no such number");
      const double value = slab_rule_value(p, r->reference_thickness_mm, h);
      scene[ptr] = p.integer ? json(static_cast<long long>(value)) : json(value);
    }
  }
  return notes;
}

json slab_rule_json(const SlabRule& rule, const json& provenance) {
  json presets = json::array();
  for (const SlabRulePreset& p : rule.presets) presets.push_back({{"file", p.file}, {"thickness_mm", p.thickness_mm}});
  json layers = json::array();
  for (const SlabRuleLayer& l : rule.layers) {
    json parameters = json::array();
    for (const SlabRuleParameter& p : l.parameters) {
      json samples = json::array();
      for (const SlabRuleSample& s : p.samples)
        samples.push_back({{"thickness_mm", s.thickness_mm},
                           {"value", s.value},
                           {"fitted", s.fitted},
                           {"leave_one_out_relative_error", or_null(s.leave_one_out_relative_error)}});
      parameters.push_back({{"pointer", p.pointer},
                            {"value_at_reference", p.value_at_reference},
                            {"exponent", p.exponent},
                            {"exponent_standard_error", or_null(p.exponent_standard_error)},
                            {"log_residual_rms", or_null(p.log_residual_rms)},
                            {"integer", p.integer},
                            {"samples", samples}});
    }
    layers.push_back({{"layer", l.layer},
                      {"reference_thickness_mm", l.reference_thickness_mm},
                      {"thickness_range_mm", {l.min_thickness_mm, l.max_thickness_mm}},
                      {"parameters", parameters}});
  }
  return {{"description",
           "Real-time parameters of a slab from each layer's thickness h: p(h) = value_at_reference * "
           "(h / reference_thickness_mm)^exponent, least squares in ln p over presets calibrated on a family of "
           "slabs (validation/harness/include/puncture/validation/slab_rule.hpp). Parameters not listed are the "
           "scene's own."},
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
  for (std::size_t k = 0; k < root["layers"].size(); ++k) {
    const json& l = root["layers"][k];
    const std::string lp = "/layers/" + std::to_string(k);
    if (!l.is_object() || !l.contains("layer") || !l["layer"].is_string()) fail(where, lp + "/layer", "missing or not a string");
    SlabRuleLayer layer;
    layer.layer = l["layer"].get<std::string>();
    layer.reference_thickness_mm = positive(l, "reference_thickness_mm", lp);
    if (!l.contains("thickness_range_mm") || !l["thickness_range_mm"].is_array() || l["thickness_range_mm"].size() != 2 ||
        !l["thickness_range_mm"][0].is_number() || !l["thickness_range_mm"][1].is_number() ||
        !(l["thickness_range_mm"][0].get<double>() <= l["thickness_range_mm"][1].get<double>()))
      fail(where, lp + "/thickness_range_mm", "must be [min, max] in mm");
    layer.min_thickness_mm = l["thickness_range_mm"][0].get<double>();
    layer.max_thickness_mm = l["thickness_range_mm"][1].get<double>();
    if (!l.contains("parameters") || !l["parameters"].is_array()) fail(where, lp + "/parameters", "missing or not an array");
    for (std::size_t j = 0; j < l["parameters"].size(); ++j) {
      const json& p = l["parameters"][j];
      const std::string pp = lp + "/parameters/" + std::to_string(j);
      if (!p.is_object() || !p.contains("pointer") || !p["pointer"].is_string() ||
          p["pointer"].get<std::string>().rfind("/force_", 0) != 0)
        fail(where, pp + "/pointer", "missing or not a pointer into /force_mesh or /force_law");
      SlabRuleParameter parameter;
      parameter.pointer = p["pointer"].get<std::string>();
      parameter.value_at_reference = positive(p, "value_at_reference", pp);
      if (!p.contains("exponent") || !p["exponent"].is_number() || !std::isfinite(p["exponent"].get<double>()))
        fail(where, pp + "/exponent", "missing or not a finite number");
      parameter.exponent = p["exponent"].get<double>();
      parameter.exponent_standard_error = optional_number(p, "exponent_standard_error");
      parameter.log_residual_rms = optional_number(p, "log_residual_rms");
      parameter.integer = p.contains("integer") && p["integer"].is_boolean() && p["integer"].get<bool>();
      if (p.contains("samples") && p["samples"].is_array())
        for (const json& s : p["samples"]) {
          SlabRuleSample sample;
          sample.thickness_mm = s.value("thickness_mm", 0.0);
          sample.value = s.value("value", 0.0);
          sample.fitted = s.value("fitted", 0.0);
          sample.leave_one_out_relative_error = optional_number(s, "leave_one_out_relative_error");
          parameter.samples.push_back(sample);
        }
      layer.parameters.push_back(parameter);
    }
    rule.layers.push_back(layer);
  }
  return rule;
}

std::string slab_rule_markdown(const SlabRule& rule, const std::string& command, const std::string& provenance_line) {
  std::ostringstream md;
  md << "# Slab rule: real-time parameters from each layer's thickness\n\n"
     << "Command: `" << command << "`, " << provenance_line << ".\n\n"
     << "Each preset below is the same model calibrated on its own slab. For every parameter whose calibrated "
        "value differs between them, p(h) = p_ref (h / h_ref)^alpha in the layer's own thickness h, least squares "
        "in ln p (h_ref: the first preset's thickness). Parameters not listed keep the scene's value. A slab the "
        "family never saw takes its parameters from this rule (`puncture validate MODEL --cases FILE --slab-rule slab_rule.json`), never from a "
        "calibration on that slab.\n\n## The family\n\n| preset | thickness (mm) |\n|---|---|\n";
  for (const SlabRulePreset& p : rule.presets) {
    md << "| " << p.file << " | ";
    for (std::size_t k = 0; k < p.thickness_mm.size(); ++k) md << (k ? " / " : "") << significant_digits(p.thickness_mm[k], 4);
    md << " |\n";
  }
  md << "\n## The rule\n\nValues calibrated on each slab (in the family's order) -> the rule's; alpha +- its standard "
        "error; the leave-one-out error is the rule fitted without that slab, at its thickness, relative to its "
        "calibrated value (how well the rule predicts a slab it did not see).\n\n"
     << "| layer | parameter | h_ref (mm) | p_ref | alpha | calibrated -> rule | leave-one-out error |\n"
     << "|---|---|---|---|---|---|---|\n";
  for (const SlabRuleLayer& l : rule.layers)
    for (const SlabRuleParameter& p : l.parameters) {
      md << "| " << l.layer << " | `" << p.pointer << "`" << (p.integer ? " (a count: rounded)" : "") << " | " << significant_digits(l.reference_thickness_mm, 4) << " | "
         << significant_digits(p.value_at_reference, 4) << " | " << significant_digits(p.exponent, 3);
      if (p.exponent_standard_error) md << " +- " << significant_digits(*p.exponent_standard_error, 2);
      md << " | ";
      for (std::size_t i = 0; i < p.samples.size(); ++i)
        md << (i ? "; " : "") << significant_digits(p.samples[i].value, 4) << " -> " << significant_digits(p.samples[i].fitted, 4);
      md << " | ";
      bool any = false;
      for (std::size_t i = 0; i < p.samples.size(); ++i) {
        md << (i ? "; " : "");
        if (p.samples[i].leave_one_out_relative_error) {
          md << (*p.samples[i].leave_one_out_relative_error >= 0 ? "+" : "")
             << significant_digits(100.0 * *p.samples[i].leave_one_out_relative_error, 3) << " %";
          any = true;
        } else {
          md << "n/a";
        }
      }
      if (!any) md << " (needs 3 slabs)";
      md << " |\n";
    }
  if (rule.layers.empty()) md << "| - | no parameter differs between the presets | | | | | |\n";
  return md.str();
}

}  // namespace puncture::validation
