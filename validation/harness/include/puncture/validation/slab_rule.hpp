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
// fitted preset's value. x is the layer's own thickness h, or the depth of its top
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
// Only calibrated values count. A preset written by `puncture calibrate`
// has, in its provenance ("calibrated_values"), the status of every value
// its calibration set: a slab's value enters the rule only when its
// calibration identified it; a value at a bound, not identifiable, or not
// set by that calibration (kept from the start preset) is left out of the
// fit (listed as excluded, with its status). A parameter identified on fewer
// than three slabs (two in a family of two), or only on slabs where its
// variables do not vary, is not ruled (listed, with why): a scene keeps its
// own value. Three, so that every rule of a family of three or more has been
// checked by predicting each of its slabs from the others (a power law
// through two points has no such check). A preset without
// such a record has every value taken as calibrated (the page says so).
//
// In:  presets: scene JSON objects (the schema of scenes/) with the same
//      layer names in the same order, "thickness_mm" > 0 per layer; a ruled
//      parameter positive in every preset that identified it. Names (files)
//      for the messages. Optionally, per preset, what its calibration
//      determined (read_preset_calibration of its provenance).
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
//                                "samples": [{"file", "x_mm", "value", "fitted",
//                                             "leave_one_out_relative_error" (null below 3)}],
//                                "excluded": [{"file", "status"}]}],
//                "not_ruled": [{"pointer", "reason"}]}],
//    "provenance"}
// (each preset: "calibration_record": whether its provenance said which
// values its calibration identified).
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace puncture::validation {

struct SlabRuleSample {
  std::string file;     ///< the preset calibrated on that slab
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
  double reference_mm = 0.0;           ///< x_ref (the first fitted preset's)
  double min_mm = 0.0, max_mm = 0.0;   ///< the variable's range in the family
  double value_at_reference = 0.0;  ///< p_ref, the rule's value at x_ref
  double exponent = 0.0;            ///< alpha
  std::optional<double> exponent_standard_error;
  std::optional<double> log_residual_rms;  ///< RMS of ln(p_fitted / p) over the presets
  bool integer = false;  ///< a count: applied rounded to the nearest integer >= 1
  /// RMS over the slabs of ln(p_leave_one_out / p) with either variable (how
  /// the choice was made); empty where not computable.
  std::optional<double> leave_one_out_log_rms_thickness, leave_one_out_log_rms_depth;
  std::vector<SlabRuleSample> samples;  ///< the slabs whose calibration identified it
  /// The slabs left out of the fit: (preset, its calibration's status of the value).
  std::vector<std::pair<std::string, std::string>> excluded;
};

/// A parameter that differs between the presets but is not ruled, and why
/// (e.g. identified on one slab only).
struct SlabRuleNotRuled {
  std::string pointer, reason;
};

struct SlabRuleLayer {
  std::string layer;
  double reference_thickness_mm = 0.0;                     ///< the first preset's (for the page)
  double min_thickness_mm = 0.0, max_thickness_mm = 0.0;  ///< the family's range (for the page)
  std::vector<SlabRuleParameter> parameters;
  std::vector<SlabRuleNotRuled> not_ruled;
};

struct SlabRulePreset {
  std::string file;
  std::vector<double> thickness_mm;
  bool calibration_record = false;  ///< whether its calibration said which values it identified
};

/// What the calibration of one preset determined of its values.
struct PresetCalibration {
  bool known = false;  ///< false: no record, every value is taken as calibrated
  /// (layer name, JSON pointer relative to the layer) -> "identified", "at a
  /// bound" or "not identifiable"; a value not listed was not set by the calibration.
  std::map<std::pair<std::string, std::string>, std::string> status;
};

/// From a preset's provenance JSON (<name>.provenance.json of `puncture
/// calibrate`): its "calibrated_values"; known = false when there is none.
/// Throws std::invalid_argument (`where` and the pointer) for a malformed entry.
PresetCalibration read_preset_calibration(const nlohmann::json& provenance, const std::string& where);

struct SlabRule {
  std::vector<SlabRulePreset> presets;
  std::vector<SlabRuleLayer> layers;
};

/// Fits the rule on a family of calibrated presets (names[i] names presets[i]
/// in messages and in the rule; calibrations[i], when given (one per preset),
/// what its calibration determined). Needs two presets or more.
SlabRule fit_slab_rule(const std::vector<nlohmann::json>& presets, const std::vector<std::string>& names,
                       const std::vector<PresetCalibration>& calibrations = {});

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
