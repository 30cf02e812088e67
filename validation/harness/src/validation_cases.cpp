#include "puncture/validation/validation_cases.hpp"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>

#include "puncture/scene_io.hpp"
#include "puncture/validation/number_format.hpp"

namespace puncture::validation {

namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& pointer, const std::string& what) {
  throw std::invalid_argument(file.string() + ": " + pointer + ": " + what);
}

/// The JSON object in `file` (`kind` names the file in the errors; `main_key` the key it must have).
json read_json_object(const std::filesystem::path& file, const std::string& kind, const std::string& main_key) {
  std::ifstream in(file);
  if (!in) throw std::invalid_argument(file.string() + ": cannot open the " + kind);
  json root;
  try {
    root = json::parse(in);
  } catch (const json::parse_error& e) {
    throw std::invalid_argument(file.string() + ": not valid JSON: " + e.what());
  }
  if (!root.is_object()) fail(file, "/", "must be an object with \"" + main_key + "\"");
  return root;
}

/// Fails on a key of object `o` (at `pointer`) that is not in `allowed`.
void reject_unknown_keys(const json& o, const std::set<std::string>& allowed, const std::filesystem::path& file,
                         const std::string& pointer) {
  for (auto it = o.begin(); it != o.end(); ++it)
    if (!allowed.count(it.key())) fail(file, pointer + "/" + it.key(), "unknown key");
}

std::string optional_text(const json& c, const char* key, const std::filesystem::path& file,
                          const std::string& pointer) {
  if (!c.contains(key)) return {};
  if (!c[key].is_string()) fail(file, pointer + "/" + key, "must be a string");
  return c[key].get<std::string>();
}

ValidationCase read_case(const json& c, const std::filesystem::path& file, const std::string& pointer) {
  if (!c.is_object()) fail(file, pointer, "a case must be an object");
  reject_unknown_keys(c, {"name", "overrides", "held_out", "rule", "note"}, file, pointer);
  ValidationCase v;
  if (!c.contains("name") || !c["name"].is_string()) fail(file, pointer + "/name", "missing or not a string");
  v.name = c["name"].get<std::string>();
  if (!std::regex_match(v.name, std::regex("[A-Za-z0-9_.-]+")) || v.name == "." || v.name == "..")
    fail(file, pointer + "/name", "\"" + v.name + "\" is not a folder name (letters, digits, _ . -)");
  if (c.contains("overrides")) {
    const json& o = c["overrides"];
    const std::string op = pointer + "/overrides";
    if (!o.is_object()) fail(file, op, "must be an object");
    for (auto it = o.begin(); it != o.end(); ++it) {
      if (it.key() == "insertion") {
        if (!it->is_object()) fail(file, op + "/insertion", "must be an object");
        for (auto f = it->begin(); f != it->end(); ++f)
          if (!f->is_number() || !std::isfinite(f->get<double>()))
            fail(file, op + "/insertion/" + f.key(), "must be a finite number");
        v.insertion_overrides = *it;
      } else if (it.key() == "layer_thickness_mm") {
        if (!it->is_array() || it->empty()) fail(file, op + "/layer_thickness_mm", "must be a non-empty array");
        for (std::size_t i = 0; i < it->size(); ++i) {
          const json& t = (*it)[i];
          if (!t.is_number() || !std::isfinite(t.get<double>()) || !(t.get<double>() > 0.0))
            fail(file, op + "/layer_thickness_mm/" + std::to_string(i), "must be a positive number (mm)");
          v.layer_thickness_mm.push_back(t.get<double>());
        }
      } else {
        fail(file, op + "/" + it.key(), "unknown override (insertion, layer_thickness_mm)");
      }
    }
  }
  const bool overridden = !v.insertion_overrides.empty() || !v.layer_thickness_mm.empty();
  v.held_out = overridden;
  if (c.contains("held_out")) {
    if (!c["held_out"].is_boolean()) fail(file, pointer + "/held_out", "must be true or false");
    v.held_out = c["held_out"].get<bool>();
  }
  v.rule = optional_text(c, "rule", file, pointer);
  v.note = optional_text(c, "note", file, pointer);
  return v;
}

std::optional<double> value_of(const AcceptanceCheck& c) {
  if (!c.available || !std::isfinite(c.value)) return std::nullopt;
  return c.value;
}

json or_null(const std::optional<double>& x) { return x ? json(*x) : json(nullptr); }

std::string miss(const char* label, const AcceptanceCheck& c, double scale, const char* unit) {
  if (!c.available) return std::string(label) + ": " + (c.note.empty() ? "not available" : c.note);
  if (c.met) return {};
  return std::string(label) + " " + significant_digits(c.value * scale, 3) + unit + " beyond " +
         significant_digits(c.limit * scale, 3) + unit;
}

std::string fixed(const json& v, int decimals, bool sign = false) {
  if (!v.is_number()) return "n/a";
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << (sign ? std::showpos : std::noshowpos) << v.get<double>();
  return s.str();
}

}  // namespace

ValidationCases read_validation_cases(const std::filesystem::path& file) {
  const json root = read_json_object(file, "cases file", "cases");
  reject_unknown_keys(root, {"description", "cases"}, file, "");
  ValidationCases out;
  if (root.contains("description")) {
    if (!root["description"].is_string()) fail(file, "/description", "must be a string");
    out.description = root["description"].get<std::string>();
  }
  if (!root.contains("cases") || !root["cases"].is_array() || root["cases"].empty())
    fail(file, "/cases", "missing or not a non-empty array");
  std::set<std::string> names;
  for (std::size_t i = 0; i < root["cases"].size(); ++i) {
    const std::string pointer = "/cases/" + std::to_string(i);
    out.cases.push_back(read_case(root["cases"][i], file, pointer));
    if (!names.insert(out.cases.back().name).second)
      fail(file, pointer + "/name", "\"" + out.cases.back().name + "\" appears twice");
  }
  return out;
}

std::vector<MissReason> read_miss_reasons(const std::filesystem::path& file, const ValidationCases& cases,
                                          const std::vector<std::string>& layer_names) {
  const json root = read_json_object(file, "reasons file", "reasons");
  reject_unknown_keys(root, {"description", "model", "reasons"}, file, "");
  for (const char* key : {"description", "model"})
    if (root.contains(key) && !root[key].is_string()) fail(file, std::string("/") + key, "must be a string");
  if (!root.contains("reasons") || !root["reasons"].is_array()) fail(file, "/reasons", "missing or not an array");
  std::set<std::string> case_names;
  for (const ValidationCase& c : cases.cases) case_names.insert(c.name);
  const std::set<std::string> layers(layer_names.begin(), layer_names.end());
  std::vector<MissReason> out;
  std::set<std::pair<std::string, std::string>> seen;
  for (std::size_t i = 0; i < root["reasons"].size(); ++i) {
    const json& r = root["reasons"][i];
    const std::string pointer = "/reasons/" + std::to_string(i);
    if (!r.is_object()) fail(file, pointer, "a reason must be an object with case, layer and why");
    reject_unknown_keys(r, {"case", "layer", "why"}, file, pointer);
    for (const char* key : {"case", "layer", "why"})
      if (!r.contains(key) || !r[key].is_string() || r[key].get<std::string>().empty())
        fail(file, pointer + "/" + key, "missing or not a non-empty string");
    MissReason m{r["case"].get<std::string>(), r["layer"].get<std::string>(), r["why"].get<std::string>()};
    if (!case_names.count(m.case_name)) fail(file, pointer + "/case", "\"" + m.case_name + "\" is not a case of the cases file");
    if (!layers.count(m.layer)) fail(file, pointer + "/layer", "\"" + m.layer + "\" is not a layer of the model");
    if (!seen.insert({m.case_name, m.layer}).second)
      fail(file, pointer, "a second reason for case " + m.case_name + ", layer " + m.layer);
    out.push_back(m);
  }
  return out;
}

std::string slab_rule_case_text(const SlabRule& rule, const std::string& rule_file,
                                const std::vector<std::string>& notes) {
  std::string family;
  for (const SlabRulePreset& p : rule.presets) {
    family += family.empty() ? "" : ", ";
    for (std::size_t k = 0; k < p.thickness_mm.size(); ++k) family += (k ? "/" : "") + significant_digits(p.thickness_mm[k], 3);
  }
  std::string text = "each layer's real-time parameters from its geometry by the model's slab rule " + rule_file +
                     " (p = p_ref (x / x_ref)^alpha per parameter, x the layer's thickness or the depth of its top, "
                     "fitted on the model calibrated on the slabs " + family +
                     " mm; the parameters it does not name are the model's)";
  for (const std::string& n : notes) text += "; " + n;
  return text;
}

CaseScene case_scene(const std::string& model_json_text, const std::string& model_file, const ValidationCase& c,
                     const SlabRule* slab_rule) {
  json s = json::parse(model_json_text);
  const std::string where = model_file + " (case " + c.name + ")";
  if (!c.insertion_overrides.empty()) {
    if (!s.contains("insertion") || !s["insertion"].is_object())
      throw std::invalid_argument(where + ": the model scene has no /insertion to override");
    for (auto it = c.insertion_overrides.begin(); it != c.insertion_overrides.end(); ++it) {
      if (!s["insertion"].contains(it.key()))
        throw std::invalid_argument(where + ": /insertion/" + it.key() + " is not a field of the model scene");
      s["insertion"][it.key()] = *it;
    }
  }
  if (!c.layer_thickness_mm.empty()) {
    if (!s.contains("layers") || !s["layers"].is_array() || s["layers"].size() != c.layer_thickness_mm.size())
      throw std::invalid_argument(where + ": layer_thickness_mm has " + std::to_string(c.layer_thickness_mm.size()) +
                                  " values for " +
                                  std::to_string(s.contains("layers") ? s["layers"].size() : 0) + " layers");
    for (std::size_t k = 0; k < c.layer_thickness_mm.size(); ++k) s["layers"][k]["thickness_mm"] = c.layer_thickness_mm[k];
  }
  CaseScene out;
  if (slab_rule && !c.layer_thickness_mm.empty()) {
    out.rule_notes = apply_slab_rule(s, *slab_rule, where);
    out.slab_rule_applied = true;
  }
  s["name"] = s.value("name", std::string("scene")) + "_" + c.name;
  out.json_text = s.dump(2) + "\n";
  out.scene = parse_scene(out.json_text, where);
  return out;
}

namespace {

const MissReason* reason_for(const std::vector<MissReason>& reasons, const std::string& case_name,
                             const std::string& layer) {
  for (const MissReason& r : reasons)
    if (r.case_name == case_name && r.layer == layer) return &r;
  return nullptr;
}

}  // namespace

json case_layer_rows(const CaseOutcome& outcome, const std::vector<MissReason>& reasons) {
  json rows = json::array();
  for (const LayerAcceptance& a : outcome.acceptance) {
    json depth_error = nullptr;
    for (const json& l : outcome.layers)
      if (l.value("layer", std::string()) == a.layer && l.contains("puncture_depth_error_mm"))
        depth_error = l["puncture_depth_error_mm"];
    json misses = json::array();
    const std::string checks[] = {
        miss("force RMSE", a.force_rmse, 1.0, ""), miss("puncture depth", a.puncture_depth, 1e3, " mm"),
        miss("puncture force", a.puncture_force, 1.0, ""),
        a.deflection_judged ? miss("deflection RMSE before the break", a.deflection, 1.0, "") : "",
        a.deflection_judged ? miss("deflection RMSE after the break", a.recovery, 1.0, "") : ""};
    for (const std::string& text : checks)
      if (!text.empty()) misses.push_back(text);
    rows.push_back({{"layer", a.layer},
                    {"force_rmse_relative", or_null(value_of(a.force_rmse))},
                    {"deflection_relative_rmse", a.deflection_judged ? or_null(value_of(a.deflection)) : json(nullptr)},
                    {"deflection_after_break_relative_rmse",
                     a.deflection_judged ? or_null(value_of(a.recovery)) : json(nullptr)},
                    {"puncture_depth_error_mm", depth_error},
                    {"puncture_force_error_relative", or_null(value_of(a.puncture_force))},
                    {"accepted", a.accepted()},
                    {"misses", misses}});
    const MissReason* why = reason_for(reasons, outcome.validation_case.name, a.layer);
    rows.back()["why"] = why && !a.accepted() ? json(why->why) : json(nullptr);
  }
  return rows;
}

namespace {

/// The whole-trajectory terms of one case (those without a layer): term ->
/// force RMSE over the FEM's peak (null where the term is not available).
json whole_trajectory_rows(const json& terms) {
  json rows = json::array();
  for (const json& t : terms) {
    if (!t.value("layer", std::string()).empty()) continue;
    const bool available = t.value("available", false) && t.contains("value");
    rows.push_back({{"term", t.value("term", std::string())},
                    {"force_rmse_relative", available ? t["value"] : json(nullptr)},
                    {"samples", t.value("samples", 0)}});
  }
  return rows;
}

}  // namespace

json heldout_summary_json(const std::vector<CaseOutcome>& outcomes, const std::string& model_file,
                          const std::string& model_note, const std::string& cases_file, const json& provenance,
                          const std::vector<MissReason>& reasons, const std::string& reasons_file) {
  json cases = json::array();
  json stale = json::array();
  for (const CaseOutcome& o : outcomes) {
    const ValidationCase& c = o.validation_case;
    cases.push_back({{"name", c.name},
                     {"held_out", c.held_out},
                     {"scene", o.scene_file},
                     {"rule", c.rule.empty() ? json(nullptr) : json(c.rule)},
                     {"slab_rule", o.slab_rule_file.empty() ? json(nullptr) : json(o.slab_rule_file)},
                     {"note", c.note.empty() ? json(nullptr) : json(c.note)},
                     {"layers", case_layer_rows(o, reasons)},
                     {"whole_trajectory", whole_trajectory_rows(o.trajectory_terms)}});
  }
  for (const MissReason& r : reasons)
    for (const CaseOutcome& o : outcomes)
      for (const LayerAcceptance& a : o.acceptance)
        if (o.validation_case.name == r.case_name && a.layer == r.layer && a.accepted())
          stale.push_back({{"case", r.case_name}, {"layer", r.layer}, {"why", r.why}});
  return {{"model", model_file},
          {"model_note", model_note},
          {"cases_file", cases_file},
          {"reasons_file", reasons_file.empty() ? json(nullptr) : json(reasons_file)},
          {"cases", cases},
          {"stale_reasons", stale},
          {"provenance", provenance}};
}

namespace {

/// A layer-case's misses, "; "-separated.
std::string joined_misses(const json& layer) {
  std::string misses;
  for (const json& m : layer["misses"]) misses += (misses.empty() ? "" : "; ") + m.get<std::string>();
  return misses;
}

/// The held-out page's table of the whole trajectory per case (nothing if no case has one).
void write_whole_trajectory_table(std::ostringstream& md, const json& summary) {
  // The whole trajectory per case: the columns are the first case's terms.
  std::vector<std::string> terms;
  for (const json& c : summary["cases"])
    if (terms.empty() && c.contains("whole_trajectory"))
      for (const json& t : c["whole_trajectory"]) terms.push_back(t["term"].get<std::string>());
  if (!terms.empty()) {
    md << "\n## The whole trajectory, per case\n\nForce RMSE over the FEM's peak of each case (the real-time "
          "model's whole force, d h v included; `overall` and the parts over the insertion, `dwell` and "
          "`withdrawal` over those phases; not part of the acceptance above).\n\n| case | held out |";
    for (const std::string& t : terms) md << " " << t << " |";
    md << "\n|---|---|";
    for (std::size_t i = 0; i < terms.size(); ++i) md << "---|";
    md << "\n";
    for (const json& c : summary["cases"]) {
      md << "| " << c["name"].get<std::string>() << " | " << (c["held_out"].get<bool>() ? "yes" : "no (in sample)")
         << " |";
      for (const std::string& name : terms) {
        json value = nullptr;
        if (c.contains("whole_trajectory"))
          for (const json& t : c["whole_trajectory"])
            if (t["term"] == name) value = t["force_rmse_relative"];
        md << " " << fixed(value, 3) << " |";
      }
      md << "\n";
    }
  }
}

/// The held-out page's reasons for each miss (when the summary names a reasons file).
void write_miss_reasons(std::ostringstream& md, const json& summary) {
  if (summary.contains("reasons_file") && summary["reasons_file"].is_string()) {
    md << "\n## Why each miss\n\nThe model's reasons (`" << summary["reasons_file"].get<std::string>()
       << "`, written after reading these results), for every layer-case that misses.\n\n";
    for (const json& c : summary["cases"])
      for (const json& l : c["layers"]) {
        if (l["accepted"].get<bool>()) continue;
        const std::string misses = joined_misses(l);
        md << "- **" << c["name"].get<std::string>() << ", " << l["layer"].get<std::string>() << "** (" << misses
           << "): " << (l.contains("why") && l["why"].is_string() ? l["why"].get<std::string>() : "no reason given")
           << "\n";
      }
    if (summary.contains("stale_reasons") && !summary["stale_reasons"].empty()) {
      md << "\nReasons given for layer-cases that are now accepted (stale: the results moved since they were "
            "written):\n\n";
      for (const json& r : summary["stale_reasons"])
        md << "- " << r["case"].get<std::string>() << ", " << r["layer"].get<std::string>() << ": "
           << r["why"].get<std::string>() << "\n";
    }
  }
}

}  // namespace

std::string heldout_summary_markdown(const json& summary, const std::string& command,
                                     const std::string& provenance_line) {
  std::ostringstream md;
  md << "# Held-out validation of the tuned real-time model\n\n"
     << "Command: `" << command << "`, " << provenance_line << ".\n\n"
     << "Model: `" << summary.value("model", std::string()) << "`";
  const std::string note = summary.value("model_note", std::string());
  if (!note.empty()) md << " (" << note << ")";
  md << ". Cases: `" << summary.value("cases_file", std::string())
     << "`. A case with overrides is held out: the model was not tuned on it. Acceptance per layer: pressing and "
        "cutting force RMSE <= 10 % of the FEM peak, puncture depth within L, puncture force within 10 %, "
        "deflection RMSE of the layer's surface <= 15 % of the FEM's largest deflection before the breakthrough "
        "and <= 25 % after it (the acceptance of `puncture validate`).\n\n"
     << "| case | held out | layer | force RMSE / peak | deflection RMSE / largest, before the break | after the "
        "break | puncture depth error (mm) | puncture force error | accepted | what misses |\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n";
  std::size_t held = 0, accepted = 0;
  for (const json& c : summary["cases"]) {
    const bool held_out = c["held_out"].get<bool>();
    for (const json& l : c["layers"]) {
      const std::string misses = joined_misses(l);
      md << "| " << c["name"].get<std::string>() << " | " << (held_out ? "yes" : "no (in sample)") << " | "
         << l["layer"].get<std::string>() << " | " << fixed(l["force_rmse_relative"], 3) << " | "
         << fixed(l["deflection_relative_rmse"], 2) << " | " << fixed(l["deflection_after_break_relative_rmse"], 2)
         << " | " << fixed(l["puncture_depth_error_mm"], 2, true) << " | "
         << fixed(l["puncture_force_error_relative"], 3, true) << " | " << (l["accepted"].get<bool>() ? "yes" : "no")
         << " | " << (misses.empty() ? "-" : misses) << " |\n";
      if (held_out) {
        ++held;
        if (l["accepted"].get<bool>()) ++accepted;
      }
    }
  }
  md << "\nHeld out: " << accepted << " of " << held
     << " layer-cases accepted. Each case that changes the slab says below where its real-time parameters come from "
        "(the model's slab rule, or the cases file's rule). Each case's report "
        "(validation_summary.md, plots, the case's scene.json) is in its folder.\n";
  write_whole_trajectory_table(md, summary);
  for (const json& c : summary["cases"])
    for (const char* key : {"rule", "note"})
      if (c.contains(key) && c[key].is_string())
        md << "\n`" << c["name"].get<std::string>() << "` (" << key << "): " << c[key].get<std::string>() << ".\n";
  write_miss_reasons(md, summary);
  return md.str();
}

}  // namespace puncture::validation
