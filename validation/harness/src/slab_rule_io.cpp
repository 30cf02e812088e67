// slab_rule_io.cpp: the slab rule file (slab_rule.json: written and read back)
// and its page (slab_rule.md); see slab_rule.hpp. The fit is in slab_rule.cpp.
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "puncture/validation/number_format.hpp"
#include "puncture/validation/slab_rule.hpp"

namespace puncture::validation {

namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& where, const std::string& pointer, const std::string& what) {
  throw std::invalid_argument(where + ": " + pointer + ": " + what);
}

json or_null(const std::optional<double>& x) { return x ? json(*x) : json(nullptr); }

std::optional<double> optional_number(const json& j, const char* key) {
  if (!j.contains(key) || !j[key].is_number()) return std::nullopt;
  return j[key].get<double>();
}

// The pieces of read_slab_rule: errors name the file (`where`) and the JSON pointer.
double positive_number(const std::string& where, const json& j, const char* key, const std::string& pointer) {
  if (!j.contains(key) || !j[key].is_number() || !std::isfinite(j[key].get<double>()) || !(j[key].get<double>() > 0.0))
    fail(where, pointer + "/" + key, "missing or not a positive number");
  return j[key].get<double>();
}

std::pair<double, double> range_mm(const std::string& where, const json& j, const char* key, const std::string& pointer) {
  if (!j.contains(key) || !j[key].is_array() || j[key].size() != 2 || !j[key][0].is_number() ||
      !j[key][1].is_number() || !(j[key][0].get<double>() <= j[key][1].get<double>()))
    fail(where, pointer + "/" + key, "must be [min, max] in mm");
  return {j[key][0].get<double>(), j[key][1].get<double>()};
}

std::vector<SlabRulePreset> read_rule_presets(const json& root) {
  std::vector<SlabRulePreset> out;
  if (root.contains("presets") && root["presets"].is_array())
    for (const json& p : root["presets"]) {
      SlabRulePreset preset;
      preset.file = p.value("file", std::string());
      preset.calibration_record = p.value("calibration_record", false);
      if (p.contains("thickness_mm") && p["thickness_mm"].is_array())
        for (const json& t : p["thickness_mm"])
          if (t.is_number()) preset.thickness_mm.push_back(t.get<double>());
      out.push_back(preset);
    }
  return out;
}

/// One entry of a layer's "parameters" (pointer pp): the law, and what the
/// fit reported (samples, leave-one-out errors, slabs excluded).
SlabRuleParameter read_rule_parameter(const std::string& where, const json& p, const std::string& pp) {
  if (!p.is_object() || !p.contains("pointer") || !p["pointer"].is_string() ||
      p["pointer"].get<std::string>().rfind("/force_", 0) != 0)
    fail(where, pp + "/pointer", "missing or not a pointer into /force_mesh or /force_law");
  SlabRuleParameter parameter;
  parameter.pointer = p["pointer"].get<std::string>();
  if (!p.contains("variable") || !p["variable"].is_string() || (p["variable"] != "thickness" && p["variable"] != "depth"))
    fail(where, pp + "/variable", "missing or not \"thickness\" or \"depth\"");
  parameter.variable = p["variable"] == "depth" ? SlabRuleVariable::depth : SlabRuleVariable::thickness;
  parameter.reference_mm = positive_number(where, p, "reference_mm", pp);
  std::tie(parameter.min_mm, parameter.max_mm) = range_mm(where, p, "range_mm", pp);
  parameter.value_at_reference = positive_number(where, p, "value_at_reference", pp);
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
  return parameter;
}

}  // namespace

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
  rule.presets = read_rule_presets(root);
  for (std::size_t k = 0; k < root["layers"].size(); ++k) {
    const json& l = root["layers"][k];
    const std::string lp = "/layers/" + std::to_string(k);
    if (!l.is_object() || !l.contains("layer") || !l["layer"].is_string()) fail(where, lp + "/layer", "missing or not a string");
    SlabRuleLayer layer;
    layer.layer = l["layer"].get<std::string>();
    layer.reference_thickness_mm = positive_number(where, l, "reference_thickness_mm", lp);
    std::tie(layer.min_thickness_mm, layer.max_thickness_mm) = range_mm(where, l, "thickness_range_mm", lp);
    if (!l.contains("parameters") || !l["parameters"].is_array()) fail(where, lp + "/parameters", "missing or not an array");
    for (std::size_t j = 0; j < l["parameters"].size(); ++j)
      layer.parameters.push_back(read_rule_parameter(where, l["parameters"][j], lp + "/parameters/" + std::to_string(j)));
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
