// Validation cases (validation_cases.hpp): reading a cases file, the model
// scene with a case's overrides, and the held-out summary rows.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <functional>
#include <fstream>
#include <string>

#include "puncture/io/atomic_file.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/validation_cases.hpp"

namespace fs = std::filesystem;

namespace puncture::validation {
namespace {

fs::path write_temp(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("puncture_cases_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(p) << text;
  return p;
}

std::string model_text() { return io::read_text_file(fs::path(PUNCTURE_SOURCE_DIR) / "scenes" / "default.json"); }

/// The error message of reading `text` (written to a file named after
/// `name`) with `read`; "no error" if it reads.
std::string error_of(const std::string& name, const std::string& text,
                     const std::function<void(const fs::path&)>& read = [](const fs::path& p) {
                       read_validation_cases(p);
                     }) {
  const fs::path p = write_temp(name, text);
  try {
    read(p);
  } catch (const std::invalid_argument& e) {
    fs::remove(p);
    return e.what();
  }
  fs::remove(p);
  return "no error";
}

TEST(ValidationCases, ReadsCasesAndTellsHeldOutFromOverrides) {
  const fs::path p = write_temp("ok.json", R"({"description": "d", "cases": [
      {"name": "own"},
      {"name": "fast", "overrides": {"insertion": {"speed_mm_per_s": 20}}, "note": "n"},
      {"name": "thick", "overrides": {"layer_thickness_mm": [1, 5, 30]}, "rule": "r"},
      {"name": "declared", "overrides": {"insertion": {"dwell_s": 1}}, "held_out": false}]})");
  const ValidationCases c = read_validation_cases(p);
  fs::remove(p);
  ASSERT_EQ(c.cases.size(), 4u);
  EXPECT_EQ(c.description, "d");
  EXPECT_FALSE(c.cases[0].held_out);
  EXPECT_TRUE(c.cases[1].held_out);
  EXPECT_EQ(c.cases[1].insertion_overrides["speed_mm_per_s"].get<double>(), 20.0);
  EXPECT_EQ(c.cases[1].note, "n");
  EXPECT_TRUE(c.cases[2].held_out);
  EXPECT_EQ(c.cases[2].layer_thickness_mm, (std::vector<double>{1, 5, 30}));
  EXPECT_EQ(c.cases[2].rule, "r");
  EXPECT_FALSE(c.cases[3].held_out);  // declared in sample although it overrides
}

TEST(ValidationCases, BadFilesNameTheFileAndTheField) {
  struct Bad {
    const char* text;
    const char* pointer;
  };
  const Bad bad[] = {
      {R"({"cases": []})", "/cases"},
      {R"({"cases": [{"overrides": {}}]})", "/cases/0/name"},
      {R"({"cases": [{"name": "../up"}]})", "/cases/0/name"},
      {R"({"cases": [{"name": "a"}, {"name": "a"}]})", "/cases/1/name"},
      {R"({"cases": [{"name": "a", "overrides": {"speed": 3}}]})", "/cases/0/overrides/speed"},
      {R"({"cases": [{"name": "a", "overrides": {"insertion": {"speed_mm_per_s": "fast"}}}]})",
       "/cases/0/overrides/insertion/speed_mm_per_s"},
      {R"({"cases": [{"name": "a", "overrides": {"layer_thickness_mm": [1, -2, 3]}}]})",
       "/cases/0/overrides/layer_thickness_mm/1"},
      {R"({"cases": [{"name": "a", "colour": "red"}]})", "/cases/0/colour"},
      {R"({"cases": [{"name": "a", "held_out": "yes"}]})", "/cases/0/held_out"},
      {R"({"cases": [{"name": "a"}], "extra": 1})", "/extra"},
  };
  for (const Bad& b : bad) {
    const std::string e = error_of("bad.json", b.text);
    EXPECT_NE(e.find("bad.json"), std::string::npos) << b.text << " -> " << e;
    EXPECT_NE(e.find(b.pointer), std::string::npos) << b.text << " -> " << e;
  }
  EXPECT_NE(error_of("broken.json", "{\"cases\": [").find("not valid JSON"), std::string::npos);
}

TEST(ValidationCases, OverridesChangeOnlyWhatTheyName) {
  const std::string text = model_text();
  const Scene model = parse_scene(text, "default.json");
  ValidationCase c;
  c.name = "slow_thick";
  c.held_out = true;
  c.insertion_overrides = {{"speed_mm_per_s", 3.0}, {"dwell_s", 10.0}};
  c.layer_thickness_mm = {1.2, 5.0, 30.0};
  const CaseScene s = case_scene(text, "default.json", c);
  EXPECT_DOUBLE_EQ(s.scene.insertion.speed_m_per_s, 3e-3);
  EXPECT_DOUBLE_EQ(s.scene.insertion.dwell_s, 10.0);
  EXPECT_DOUBLE_EQ(s.scene.insertion.target_depth_m, model.insertion.target_depth_m);
  ASSERT_EQ(s.scene.layers.size(), 3u);
  EXPECT_DOUBLE_EQ(s.scene.layers[0].thickness_m, 1.2e-3);
  EXPECT_DOUBLE_EQ(s.scene.layers[2].thickness_m, 30e-3);
  EXPECT_EQ(s.scene.layers[1].force_mesh.rings_w, model.layers[1].force_mesh.rings_w);
  EXPECT_EQ(s.scene.name, model.name + "_slow_thick");
  // The written text is the scene validated: it reads back to the same scene.
  EXPECT_EQ(scene_to_json_text(parse_scene(s.json_text, "again")), scene_to_json_text(s.scene));

  // The case without overrides is the model itself (but for its name).
  ValidationCase own;
  own.name = "own";
  Scene same = case_scene(text, "default.json", own).scene;
  same.name = model.name;
  EXPECT_EQ(scene_to_json_text(same), scene_to_json_text(model));
}

TEST(ValidationCases, OverridesTheModelCannotTakeAreErrors) {
  const std::string text = model_text();
  ValidationCase c;
  c.name = "x";
  c.insertion_overrides = {{"speed_mph", 3.0}};
  EXPECT_THROW(case_scene(text, "default.json", c), std::invalid_argument);
  c.insertion_overrides = nlohmann::json::object();
  c.layer_thickness_mm = {1.0, 2.0};
  EXPECT_THROW(case_scene(text, "default.json", c), std::invalid_argument);
  c.layer_thickness_mm.clear();
  c.insertion_overrides = {{"speed_mm_per_s", -1.0}};  // valid JSON, invalid scene
  try {
    case_scene(text, "default.json", c);
    ADD_FAILURE() << "a negative speed was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("default.json (case x)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("/insertion/speed_mm_per_s"), std::string::npos) << e.what();
  }
}

AcceptanceCheck check(bool available, double value, double limit, const std::string& note = "") {
  AcceptanceCheck c;
  c.available = available;
  c.value = value;
  c.limit = limit;
  c.met = available && std::abs(value) <= limit;
  c.note = note;
  return c;
}

TEST(ValidationCases, SummaryRowsNameEveryMissAndCountHeldOutLayers) {
  LayerAcceptance good, bad;
  good.layer = "skin";
  good.force_rmse = check(true, 0.05, 0.1);
  good.puncture_depth = check(true, 0.4e-3, 2e-3);
  good.puncture_force = check(true, -0.02, 0.1);
  good.deflection_judged = true;
  good.deflection = check(true, 0.1, 0.15);
  good.recovery = check(true, 0.2, 0.25);
  bad = good;
  bad.layer = "fat";
  bad.force_rmse = check(true, 0.113, 0.1);
  bad.puncture_depth = check(true, 2.93e-3, 2.5e-3);
  bad.deflection = check(false, 0.0, 0.15, "no FEM profile of this layer's top surface");
  ASSERT_TRUE(good.accepted());
  ASSERT_FALSE(bad.accepted());

  CaseOutcome own, fast;
  own.validation_case.name = "own";
  own.acceptance = {good};
  own.layers = nlohmann::json::array({{{"layer", "skin"}, {"puncture_depth_error_mm", 0.4}}});
  fast.validation_case.name = "fast";
  fast.validation_case.held_out = true;
  fast.validation_case.rule = "keep them";
  fast.acceptance = {good, bad};
  fast.layers = nlohmann::json::array();

  const nlohmann::json rows = case_layer_rows(fast);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_TRUE(rows[0]["accepted"].get<bool>());
  EXPECT_TRUE(rows[0]["misses"].empty());
  EXPECT_TRUE(rows[0]["puncture_depth_error_mm"].is_null());  // fast has no layer metrics
  EXPECT_FALSE(rows[1]["accepted"].get<bool>());
  EXPECT_DOUBLE_EQ(rows[1]["force_rmse_relative"].get<double>(), 0.113);
  EXPECT_TRUE(rows[1]["deflection_relative_rmse"].is_null());
  ASSERT_EQ(rows[1]["misses"].size(), 3u) << rows[1]["misses"].dump();
  EXPECT_EQ(rows[1]["misses"][0], "force RMSE 0.113 beyond 0.1");
  EXPECT_EQ(rows[1]["misses"][1], "puncture depth 2.93 mm beyond 2.5 mm");
  EXPECT_EQ(rows[1]["misses"][2], "deflection RMSE before the break: no FEM profile of this layer's top surface");
  EXPECT_DOUBLE_EQ(case_layer_rows(own)[0]["puncture_depth_error_mm"].get<double>(), 0.4);

  const nlohmann::json summary = heldout_summary_json({own, fast}, "model.json", "note", "cases.json", {});
  EXPECT_EQ(summary["cases"].size(), 2u);
  EXPECT_FALSE(summary["cases"][0]["held_out"].get<bool>());
  EXPECT_EQ(summary["cases"][1]["rule"], "keep them");
  const std::string md = heldout_summary_markdown(summary, "puncture validate model.json --cases cases.json", "git x");
  EXPECT_NE(md.find("Held out: 1 of 2 layer-cases accepted"), std::string::npos) << md;
  EXPECT_NE(md.find("| own | no (in sample) | skin |"), std::string::npos) << md;
  EXPECT_NE(md.find("| fast | yes | fat | 0.113 | n/a |"), std::string::npos) << md;
  EXPECT_NE(md.find("`fast` (rule): keep them."), std::string::npos) << md;
}

TEST(ValidationCases, SummaryListsEachCasesWholeTrajectoryTermsWithoutTheLayerTerms) {
  CaseOutcome hold;
  hold.validation_case.name = "hold";
  hold.validation_case.held_out = true;
  hold.trajectory_terms = nlohmann::json::array(
      {{{"term", "overall"}, {"layer", ""}, {"available", true}, {"value", 0.0486}, {"samples", 127}},
       {{"term", "force_rmse"}, {"layer", "skin"}, {"available", true}, {"value", 0.051}, {"samples", 40}},
       {{"term", "dwell"}, {"layer", ""}, {"available", true}, {"value", 0.0429}, {"samples", 9}},
       {{"term", "withdrawal"}, {"layer", ""}, {"available", false}, {"samples", 0}}});
  CaseOutcome none;  // a case without terms (e.g. an older outcome): n/a in every column
  none.validation_case.name = "none";
  const nlohmann::json summary = heldout_summary_json({hold, none}, "model.json", "", "cases.json", {});
  const nlohmann::json& rows = summary["cases"][0]["whole_trajectory"];
  ASSERT_EQ(rows.size(), 3u) << rows.dump();  // the skin's layer term is left out
  EXPECT_EQ(rows[0]["term"], "overall");
  EXPECT_DOUBLE_EQ(rows[0]["force_rmse_relative"].get<double>(), 0.0486);
  EXPECT_EQ(rows[1]["term"], "dwell");
  EXPECT_EQ(rows[1]["samples"], 9);
  EXPECT_TRUE(rows[2]["force_rmse_relative"].is_null());  // not available
  EXPECT_TRUE(summary["cases"][1]["whole_trajectory"].empty());
  const std::string md = heldout_summary_markdown(summary, "puncture validate model.json --cases cases.json", "git x");
  EXPECT_NE(md.find("| case | held out | overall | dwell | withdrawal |"), std::string::npos) << md;
  EXPECT_NE(md.find("| hold | yes | 0.049 | 0.043 | n/a |"), std::string::npos) << md;
  EXPECT_NE(md.find("| none | no (in sample) | n/a | n/a | n/a |"), std::string::npos) << md;
}

ValidationCases two_cases() {
  ValidationCases cases;
  cases.cases.resize(2);
  cases.cases[0].name = "own";
  cases.cases[1].name = "fast";
  return cases;
}

std::string reasons_error_of(const std::string& name, const std::string& text) {
  return error_of(name, text, [](const fs::path& p) { read_miss_reasons(p, two_cases(), {"skin", "fat", "muscle"}); });
}

TEST(ValidationCases, MissReasonsAreReadAndCheckedAgainstTheCasesAndTheModelsLayers) {
  const fs::path p = write_temp("why.json",
                                R"({"description": "d", "model": "m.json", "reasons": [
      {"case": "fast", "layer": "fat", "why": "rate beyond the fitted speeds"},
      {"case": "own", "layer": "skin", "why": "an old reason"}]})");
  const std::vector<MissReason> reasons = read_miss_reasons(p, two_cases(), {"skin", "fat", "muscle"});
  fs::remove(p);
  ASSERT_EQ(reasons.size(), 2u);
  EXPECT_EQ(reasons[0].case_name, "fast");
  EXPECT_EQ(reasons[0].layer, "fat");
  EXPECT_EQ(reasons[0].why, "rate beyond the fitted speeds");

  struct Bad {
    const char* name;
    const char* text;
    const char* expected;
  };
  const Bad bad[] = {
      {"not_json", "{", "not valid JSON"},
      {"no_reasons", R"({"description": "d"})", "/reasons: missing or not an array"},
      {"unknown_top", R"({"reasons": [], "extra": 1})", "/extra: unknown key"},
      {"unknown_case", R"({"reasons": [{"case": "slow", "layer": "fat", "why": "w"}]})",
       "/reasons/0/case: \"slow\" is not a case of the cases file"},
      {"unknown_layer", R"({"reasons": [{"case": "fast", "layer": "bone", "why": "w"}]})",
       "/reasons/0/layer: \"bone\" is not a layer of the model"},
      {"empty_why", R"({"reasons": [{"case": "fast", "layer": "fat", "why": ""}]})",
       "/reasons/0/why: missing or not a non-empty string"},
      {"unknown_key", R"({"reasons": [{"case": "fast", "layer": "fat", "why": "w", "when": 1}]})",
       "/reasons/0/when: unknown key"},
      {"twice", R"({"reasons": [{"case": "fast", "layer": "fat", "why": "w"}, {"case": "fast", "layer": "fat", "why": "v"}]})",
       "/reasons/1: a second reason for case fast, layer fat"},
  };
  for (const Bad& b : bad) {
    const std::string e = reasons_error_of(b.name, b.text);
    EXPECT_NE(e.find(b.expected), std::string::npos) << b.name << ": " << e;
    EXPECT_NE(e.find(b.name), std::string::npos) << "the error names the file: " << e;
  }
}

TEST(ValidationCases, SummarySaysWhyEachMissAndListsReasonsThatWentStale) {
  LayerAcceptance good, bad;
  good.layer = "skin";
  good.force_rmse = check(true, 0.05, 0.1);
  good.puncture_depth = check(true, 0.4e-3, 2e-3);
  good.puncture_force = check(true, -0.02, 0.1);
  bad = good;
  bad.layer = "fat";
  bad.puncture_force = check(true, 0.25, 0.1);
  LayerAcceptance unexplained = bad;
  unexplained.layer = "muscle";
  CaseOutcome own, fast;
  own.validation_case.name = "own";
  own.acceptance = {good};
  fast.validation_case.name = "fast";
  fast.validation_case.held_out = true;
  fast.acceptance = {good, bad, unexplained};
  const std::vector<MissReason> reasons = {{"fast", "fat", "rate beyond the fitted speeds"},
                                           {"own", "skin", "an old reason"}};
  const nlohmann::json summary =
      heldout_summary_json({own, fast}, "model.json", "", "cases.json", {}, reasons, "why.json");
  EXPECT_EQ(summary["reasons_file"], "why.json");
  EXPECT_TRUE(summary["cases"][0]["layers"][0]["why"].is_null()) << "accepted: no reason shown";
  EXPECT_EQ(summary["cases"][1]["layers"][1]["why"], "rate beyond the fitted speeds");
  EXPECT_TRUE(summary["cases"][1]["layers"][2]["why"].is_null()) << "a miss without a reason";
  ASSERT_EQ(summary["stale_reasons"].size(), 1u);
  EXPECT_EQ(summary["stale_reasons"][0]["case"], "own");
  EXPECT_EQ(summary["stale_reasons"][0]["layer"], "skin");
  const std::string md = heldout_summary_markdown(summary, "puncture validate model.json --cases cases.json", "git x");
  EXPECT_NE(md.find("## Why each miss"), std::string::npos) << md;
  EXPECT_NE(md.find("- **fast, fat** (puncture force 0.25 beyond 0.1): rate beyond the fitted speeds"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("- **fast, muscle** (puncture force 0.25 beyond 0.1): no reason given"), std::string::npos) << md;
  EXPECT_NE(md.find("(stale: the results moved since they were written)"), std::string::npos) << md;
  EXPECT_NE(md.find("- own, skin: an old reason"), std::string::npos) << md;
  EXPECT_EQ(md.find("- **own, skin**"), std::string::npos) << md;

  // Without a reasons file: no section, every "why" null.
  const nlohmann::json plain = heldout_summary_json({own, fast}, "model.json", "", "cases.json", {});
  EXPECT_TRUE(plain["reasons_file"].is_null());
  EXPECT_TRUE(plain["cases"][1]["layers"][1]["why"].is_null());
  EXPECT_EQ(heldout_summary_markdown(plain, "c", "git x").find("Why each miss"), std::string::npos);
}

TEST(ValidationCases, TheCommittedHeldOutSummarySaysWhyEachMissAndHasNoStaleReason) {
  // results/validation_heldout (scripts/results_heldout.sh): the acceptance
  // lets a held-out layer-case miss only when the page says why.
  std::ifstream in(fs::path(PUNCTURE_SOURCE_DIR) / "results" / "validation_heldout" / "heldout_summary.json");
  ASSERT_TRUE(in) << "results/validation_heldout/heldout_summary.json is missing";
  const nlohmann::json summary = nlohmann::json::parse(in);
  ASSERT_TRUE(summary.contains("reasons_file") && summary["reasons_file"].is_string())
      << "made without --why-misses: run bash scripts/results_heldout.sh";
  for (const nlohmann::json& c : summary["cases"])
    for (const nlohmann::json& l : c["layers"])
      if (!l["accepted"].get<bool>()) {
        EXPECT_TRUE(l["why"].is_string() && !l["why"].get<std::string>().empty())
            << c["name"] << ", " << l["layer"] << " misses without a reason";
      }
  EXPECT_TRUE(summary["stale_reasons"].empty()) << summary["stale_reasons"].dump();
}

}  // namespace
}  // namespace puncture::validation
