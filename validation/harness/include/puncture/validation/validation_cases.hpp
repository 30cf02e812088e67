// validation_cases.hpp: a set of validation cases (other speeds, depths and
// holds, other slabs) on which one model scene is validated without retuning
// (`puncture validate MODEL --cases FILE`), and the held-out summary.
//
// Cases file (JSON; validation/cases/default_heldout.json):
//   {"description": "...",
//    "cases": [{"name": "speed_3_mm_per_s",                  (required; [A-Za-z0-9_.-]+, unique)
//               "overrides": {"insertion": {"speed_mm_per_s": 3, ...},   (fields of the scene's /insertion)
//                             "layer_thickness_mm": [1.2, 5, 30]},       (one per layer, > 0)
//               "held_out": true,                        (optional; default: overrides not empty)
//               "rule": "...", "note": "..."}]}          (optional text for the page)
// A case without overrides is the model's own trajectory (in sample when the
// model was calibrated on it). read_validation_cases throws
// std::invalid_argument naming the file and the JSON path of what is wrong.
//
// case_scene(model_json_text, model_file, case, slab_rule): the model scene's
// JSON with the case's overrides, parsed (and so checked) as a scene; its text
// is returned too, to be written beside the case's report. A slab rule
// (slab_rule.hpp: the model's parameters as functions of each layer's
// thickness, fitted on a family of slabs) belongs to the model, not to the
// cases: given one, a case that changes the thicknesses takes the ruled
// parameters from it.
//
// Held-out summary (heldout_summary.json, the schema of the real-time
// physics issue plus "misses", "rule", "note"):
//   {"model", "model_note", "cases_file", "cases": [{"name", "held_out",
//    "scene", "rule", "slab_rule" (file or null), "note", "layers": [{"layer", "force_rmse_relative",
//    "deflection_relative_rmse", "deflection_after_break_relative_rmse",
//    "puncture_depth_error_mm", "puncture_force_error_relative",
//    "accepted", "misses": [text]}]}], "provenance"}
// Values that could not be computed are null and named in "misses".
//
// Why a model misses (`puncture validate --why-misses FILE`; JSON,
// validation/cases/default_tuned_why_misses.json): the model's reasons, by
// case and layer, written after reading its held-out results:
//   {"description": "...", "model": "results/tuned_preset/default_tuned.json",
//    "reasons": [{"case": "speed_3_mm_per_s", "layer": "fat", "why": "..."}]}
// read_miss_reasons checks each case against the cases file and each layer
// against the model's layers (one reason per case and layer; errors name the
// file and the JSON path). In the summary a layer-case that misses carries
// its reason as "why" (null when none was given); a reason given for a
// layer-case that is accepted is listed under "stale_reasons" (the results
// moved; the reason must go), and the page has a section "Why each miss".
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "puncture/scene.hpp"
#include "puncture/validation/acceptance.hpp"
#include "puncture/validation/slab_rule.hpp"

namespace puncture::validation {

struct ValidationCase {
  std::string name;
  bool held_out = false;
  nlohmann::json insertion_overrides = nlohmann::json::object();  ///< keys of the scene's /insertion
  std::vector<double> layer_thickness_mm;                          ///< empty: the model's thicknesses
  std::string rule, note;
};

struct ValidationCases {
  std::string description;
  std::vector<ValidationCase> cases;
};

ValidationCases read_validation_cases(const std::filesystem::path& file);

struct CaseScene {
  Scene scene;
  std::string json_text;  ///< the scene as validated (model JSON with the overrides)
  bool slab_rule_applied = false;
  std::vector<std::string> rule_notes;  ///< from the slab rule (a thickness outside its family)
};
/// Throws SceneError (file = "<model_file> (case <name>)") when an override
/// makes the scene invalid, std::invalid_argument for an override the model
/// scene does not have (an /insertion key it lacks, a thickness count that
/// differs from its layers).
CaseScene case_scene(const std::string& model_json_text, const std::string& model_file, const ValidationCase& c,
                     const SlabRule* slab_rule = nullptr);

/// The page's text for a case whose slab came from `rule` (read from
/// rule_file): the rule, its family and the notes of case_scene.
std::string slab_rule_case_text(const SlabRule& rule, const std::string& rule_file,
                                const std::vector<std::string>& notes);

/// One reason of a --why-misses file.
struct MissReason {
  std::string case_name, layer, why;
};
std::vector<MissReason> read_miss_reasons(const std::filesystem::path& file, const ValidationCases& cases,
                                          const std::vector<std::string>& layer_names);

/// One case's outcome: the acceptance per layer, the layer metrics JSON of
/// `puncture validate` (layer_metrics_json, for the puncture depth error) and
/// its whole-trajectory terms (validation_metrics.json "trajectory_terms":
/// {"term", "layer", "available", "value", ...}; those without a layer are
/// summarised: the insertion, the force's parts, the dwell, the withdrawal).
struct CaseOutcome {
  ValidationCase validation_case;
  std::string scene_file;  ///< where the case's scene was written
  std::string slab_rule_file;  ///< the slab rule its scene took parameters from (empty: none)
  std::vector<LayerAcceptance> acceptance;
  nlohmann::json layers = nlohmann::json::array();
  nlohmann::json trajectory_terms = nlohmann::json::array();
};

/// The "layers" rows of one case (see above; "why" from `reasons` where the layer misses).
nlohmann::json case_layer_rows(const CaseOutcome& outcome, const std::vector<MissReason>& reasons = {});
/// heldout_summary.json (provenance given as JSON); `reasons` (may be empty)
/// from read_miss_reasons of `reasons_file`.
nlohmann::json heldout_summary_json(const std::vector<CaseOutcome>& outcomes, const std::string& model_file,
                                    const std::string& model_note, const std::string& cases_file,
                                    const nlohmann::json& provenance, const std::vector<MissReason>& reasons = {},
                                    const std::string& reasons_file = {});
/// heldout_summary.md from the summary JSON: one row per case and layer, the
/// count of held-out layer-cases accepted, one row per case of its
/// whole-trajectory force errors, each case's rule and note; with a reasons
/// file, "Why each miss" (and the stale reasons).
std::string heldout_summary_markdown(const nlohmann::json& summary, const std::string& command,
                                     const std::string& provenance_line);

}  // namespace puncture::validation
