// slab_rule.hpp: the real-time parameters of a slab the model was never
// calibrated on, from a rule fitted on a family of calibration slabs (the
// "automatic mass-spring parameters from a FEM" of seed 001, per layer).
//
// Rule. Every preset of the family is the same model calibrated on its own
// slab (other layer thicknesses). For each layer (by name) and each force-mesh
// or force-law parameter whose calibrated value differs between the presets, a
// power law in one geometric variable x of the layer:
//     p(x) = p_ref * (x / x_ref)^alpha,
// fitted by least squares in ln p over the presets; x_ref is the first
// preset's value. x is the layer's own thickness h, or the depth of its top
// surface (the thickness of the layers above it; not for the top layer):
// with three presets or more, the one whose leave-one-out error (the rule
// fitted without one slab, predicting it; RMS in ln p over the slabs) is the
// smaller, else h. Both leave-one-out errors are kept, so a reader sees how
// well either predicts a slab it did not see. Parameters equal in every preset
// (what the calibrations kept: the material's rate and friction parameters;
// within 0.01 %) are not part of the rule: a scene keeps its own. A count (the
// ring count w, which the surface fit may choose per slab) is fitted the same
// way and applied rounded to the nearest integer, at least 1.
//
// In:  presets: scene JSON objects (the schema of scenes/) with the same
//      layer names in the same order, "thickness_mm" > 0 per layer; a ruled
//      parameter positive in every preset, and its variable at two or more
//      values. Names (files) for the messages.
// Out: SlabRule (exponents with their standard error and each preset's
//      leave-one-out error when there are three presets or more).
//      apply_slab_rule sets every ruled parameter of a scene JSON from the
//      scene's own geometry (notes when a value lies outside the family's
//      range: extrapolated).
// Errors: std::invalid_argument naming the preset (or rule file) and the
//      JSON pointer of what is wrong.
//
// slab_rule.json:
//   {"description", "presets": [{"file", "thickness_mm": [...]}],
//    "layers": [{"layer", "reference_thickness_mm", "thickness_range_mm": [min, max],
//                "parameters": [{"pointer" (e.g. "/force_mesh/K_N_per_mm"),
//                                "variable" ("thickness" | "depth"), "reference_mm",
//                                "range_mm": [min, max] (of the variable in the family),
//                                "value_at_reference", "exponent",
//                                "exponent_standard_error" (null below 3 presets),
//                                "log_residual_rms" (null below 3 presets), "integer",
//                                "leave_one_out_log_rms": {"thickness", "depth"} (null
//                                where not computable),
//                                "samples": [{"x_mm", "value", "fitted",
//                                             "leave_one_out_relative_error" (null below 3)}]}]}],
//    "provenance"}
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace puncture::validation {

struct SlabRuleSample {
  double x_mm = 0.0;    ///< the rule's variable on that slab
  double value = 0.0;   ///< calibrated on that slab
  double fitted = 0.0;  ///< the rule's value at that thickness
  std::optional<double> leave_one_out_relative_error;  ///< rule fitted without this slab, (p_loo - value) / value
};

/// The geometric variable of a rule: the layer's own thickness, or the depth
/// of its top surface (the thickness of the layers above it).
enum class SlabRuleVariable { thickness, depth };

struct SlabRuleParameter {
  std::string pointer;  ///< JSON pointer inside the layer, e.g. "/force_law/breakthrough/critical_force_N"
  SlabRuleVariable variable = SlabRuleVariable::thickness;
  double reference_mm = 0.0;           ///< x_ref (the first preset's)
  double min_mm = 0.0, max_mm = 0.0;   ///< the variable's range in the family
  double value_at_reference = 0.0;  ///< p_ref, the rule's value at x_ref
  double exponent = 0.0;            ///< alpha
  std::optional<double> exponent_standard_error;
  std::optional<double> log_residual_rms;  ///< RMS of ln(p_fitted / p) over the presets
  bool integer = false;  ///< a count: applied rounded to the nearest integer >= 1
  /// RMS over the slabs of ln(p_leave_one_out / p) with either variable (how
  /// the choice was made); empty where not computable.
  std::optional<double> leave_one_out_log_rms_thickness, leave_one_out_log_rms_depth;
  std::vector<SlabRuleSample> samples;
};

struct SlabRuleLayer {
  std::string layer;
  double reference_thickness_mm = 0.0;                     ///< the first preset's (for the page)
  double min_thickness_mm = 0.0, max_thickness_mm = 0.0;  ///< the family's range (for the page)
  std::vector<SlabRuleParameter> parameters;
};

struct SlabRulePreset {
  std::string file;
  std::vector<double> thickness_mm;
};

struct SlabRule {
  std::vector<SlabRulePreset> presets;
  std::vector<SlabRuleLayer> layers;
};

/// Fits the rule on a family of calibrated presets (names[i] names presets[i]
/// in messages and in the rule). Needs two presets or more.
SlabRule fit_slab_rule(const std::vector<nlohmann::json>& presets, const std::vector<std::string>& names);

/// p_ref * (x / x_ref)^alpha (rounded to the nearest integer >= 1 for a count).
double slab_rule_value(const SlabRuleParameter& parameter, double x_mm);
/// "thickness" or "depth".
const char* slab_rule_variable_name(SlabRuleVariable variable);

/// Sets each ruled parameter of `scene` (a scene JSON) from its layer's
/// thickness or depth; layers the rule does not name keep their values. Returns notes
/// (a thickness outside the family's range). Throws std::invalid_argument
/// (`where` and the pointer) when the scene lacks a ruled parameter.
std::vector<std::string> apply_slab_rule(nlohmann::json& scene, const SlabRule& rule, const std::string& where);

nlohmann::json slab_rule_json(const SlabRule& rule, const nlohmann::json& provenance);
/// Reads slab_rule.json back (only what apply_slab_rule needs is required:
/// layers, their reference thickness and range, the parameters' pointer,
/// value_at_reference and exponent).
SlabRule read_slab_rule(const std::filesystem::path& file);
/// slab_rule.md: the family, then one row per layer and parameter.
std::string slab_rule_markdown(const SlabRule& rule, const std::string& command, const std::string& provenance_line);

}  // namespace puncture::validation
