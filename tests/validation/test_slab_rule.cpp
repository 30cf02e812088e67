// Slab rule (slab_rule.hpp): power laws in each layer's thickness fitted on
// presets of a family of slabs, checked against closed forms (exact power
// laws, the least-squares slope and its standard error by hand), applied to a
// scene and through a validation case, and its errors.
#include <gtest/gtest.h>

#include <unistd.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "puncture/io/atomic_file.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/slab_rule.hpp"
#include "puncture/validation/validation_cases.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace puncture::validation {
namespace {

json default_scene() {
  return json::parse(io::read_text_file(fs::path(PUNCTURE_SOURCE_DIR) / "scenes" / "default.json"));
}

/// The default scene on slab (skin, fat, muscle) with K and the skin's
/// cutting force set by exact power laws of each layer's thickness.
json family_member(double skin_mm, double fat_mm, double muscle_mm) {
  json s = default_scene();
  const double h[3] = {skin_mm, fat_mm, muscle_mm};
  for (int k = 0; k < 3; ++k) {
    s["layers"][k]["thickness_mm"] = h[k];
    s["layers"][k]["force_mesh"]["K_N_per_mm"] = 0.05 * std::pow(h[k], 1.5 - 0.5 * k);  // alpha 1.5, 1, 0.5
  }
  s["layers"][0]["force_law"]["cutting_force_N"] = 2.0 * std::pow(skin_mm / 0.8, 2.0);
  return s;
}

const SlabRuleParameter* find(const SlabRule& rule, const std::string& layer, const std::string& pointer) {
  for (const SlabRuleLayer& l : rule.layers)
    if (l.layer == layer)
      for (const SlabRuleParameter& p : l.parameters)
        if (p.pointer == pointer) return &p;
  return nullptr;
}

TEST(SlabRule, RecoversExactPowerLawsAndOnlyTheParametersThatDiffer) {
  json round_off = family_member(1.0, 6.5, 28);
  const double L = round_off["layers"][1]["force_mesh"]["L_mm"].get<double>();
  round_off["layers"][1]["force_mesh"]["L_mm"] = L * (1.0 + 2e-5);  // a kept value moved by round-off
  const SlabRule rule = fit_slab_rule({family_member(0.8, 8.4, 39), family_member(1.6, 4, 33), round_off},
                                      {"a.json", "b.json", "c.json"});
  ASSERT_EQ(rule.layers.size(), 3u);
  EXPECT_EQ(rule.presets[1].thickness_mm, (std::vector<double>{1.6, 4, 33}));
  const SlabRuleParameter* k_skin = find(rule, "skin", "/force_mesh/K_N_per_mm");
  const SlabRuleParameter* k_muscle = find(rule, "muscle", "/force_mesh/K_N_per_mm");
  const SlabRuleParameter* cut = find(rule, "skin", "/force_law/cutting_force_N");
  ASSERT_TRUE(k_skin && k_muscle && cut);
  EXPECT_NEAR(k_skin->exponent, 1.5, 1e-10);
  EXPECT_NEAR(k_skin->value_at_reference, 0.05 * std::pow(0.8, 1.5), 1e-12);
  EXPECT_NEAR(k_muscle->exponent, 0.5, 1e-10);
  EXPECT_NEAR(cut->exponent, 2.0, 1e-10);
  EXPECT_NEAR(cut->value_at_reference, 2.0, 1e-10);
  ASSERT_TRUE(cut->exponent_standard_error && cut->log_residual_rms);
  EXPECT_NEAR(*cut->exponent_standard_error, 0.0, 1e-8);
  for (const SlabRuleSample& s : cut->samples) {
    ASSERT_TRUE(s.leave_one_out_relative_error);
    EXPECT_NEAR(*s.leave_one_out_relative_error, 0.0, 1e-9);  // an exact law predicts the slab it did not see
  }
  // Only K and the skin's cutting force differ: the rest of each layer is not
  // ruled, nor a value that differs by round-off only.
  EXPECT_EQ(rule.layers[0].parameters.size(), 2u);
  EXPECT_EQ(rule.layers[1].parameters.size(), 1u);
  EXPECT_DOUBLE_EQ(rule.layers[2].min_thickness_mm, 28.0);
  EXPECT_DOUBLE_EQ(rule.layers[2].max_thickness_mm, 39.0);
  EXPECT_NEAR(slab_rule_value(*k_muscle, 30.0), 0.05 * std::sqrt(30.0), 1e-12);
  // Exact in the own thickness: chosen over the depth of the layer's top.
  EXPECT_EQ(k_muscle->variable, SlabRuleVariable::thickness);
  ASSERT_TRUE(k_muscle->leave_one_out_log_rms_thickness && k_muscle->leave_one_out_log_rms_depth);
  EXPECT_NEAR(*k_muscle->leave_one_out_log_rms_thickness, 0.0, 1e-9);
  EXPECT_GT(*k_muscle->leave_one_out_log_rms_depth, 0.01);
  EXPECT_EQ(k_skin->variable, SlabRuleVariable::thickness);  // the top layer has no depth
  EXPECT_FALSE(k_skin->leave_one_out_log_rms_depth.has_value());
}

TEST(SlabRule, AParameterThatFollowsTheDepthOfItsLayerIsRuledByTheDepth) {
  // The muscle's critical force = 0.9 N (d / 9.2 mm)^4, d the depth of its top
  // (skin + fat): the rule picks the depth, predicts each slab left out exactly,
  // and sets a new slab's value from its depth.
  const double slabs[3][3] = {{0.8, 8.4, 39}, {1.6, 4.5, 36}, {1.0, 6.5, 28}};
  std::vector<json> presets;
  for (const auto& h : slabs) {
    json s = family_member(h[0], h[1], h[2]);
    s["layers"][2]["force_law"]["cutting_force_N"] = 0.9 * std::pow((h[0] + h[1]) / 9.2, 4.0);
    presets.push_back(s);
  }
  const SlabRule rule = fit_slab_rule(presets, {"a", "b", "c"});
  const SlabRuleParameter* c = find(rule, "muscle", "/force_law/cutting_force_N");
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->variable, SlabRuleVariable::depth);
  EXPECT_NEAR(c->exponent, 4.0, 1e-10);
  EXPECT_NEAR(c->reference_mm, 9.2, 1e-12);
  EXPECT_DOUBLE_EQ(c->min_mm, 6.1);
  EXPECT_NEAR(*c->leave_one_out_log_rms_depth, 0.0, 1e-9);
  EXPECT_GT(*c->leave_one_out_log_rms_thickness, 0.1);
  json scene = default_scene();
  scene["layers"][0]["thickness_mm"] = 1.2;
  scene["layers"][1]["thickness_mm"] = 5.0;
  scene["layers"][2]["thickness_mm"] = 30.0;
  const std::vector<std::string> notes = apply_slab_rule(scene, rule, "scene.json");
  EXPECT_NEAR(scene["layers"][2]["force_law"]["cutting_force_N"].get<double>(), 0.9 * std::pow(6.2 / 9.2, 4.0), 1e-10);
  // Its depth, 6.2 mm, lies inside the family's 6.1-9.2 mm: no extrapolation note for it.
  for (const std::string& n : notes) EXPECT_EQ(n.find("muscle: its depth"), std::string::npos) << n;
  // Read back from the file: the same value.
  const fs::path f = fs::temp_directory_path() / ("puncture_rule_depth_" + std::to_string(::getpid()) + ".json");
  std::ofstream(f) << slab_rule_json(rule, json::object()).dump();
  const SlabRule read = read_slab_rule(f);
  fs::remove(f);
  ASSERT_NE(find(read, "muscle", "/force_law/cutting_force_N"), nullptr);
  EXPECT_EQ(find(read, "muscle", "/force_law/cutting_force_N")->variable, SlabRuleVariable::depth);
  json again = default_scene();
  again["layers"][0]["thickness_mm"] = 1.2;
  again["layers"][1]["thickness_mm"] = 5.0;
  apply_slab_rule(again, read, "scene.json");
  EXPECT_NEAR(again["layers"][2]["force_law"]["cutting_force_N"].get<double>(), 0.9 * std::pow(6.2 / 9.2, 4.0), 1e-10);
}

TEST(SlabRule, NoisyValuesGiveTheLeastSquaresSlopeAndItsStandardError) {
  // ln p = y at x = ln(h / h_ref): slope, standard error and leave-one-out by hand.
  const double h[3] = {1.0, 2.0, 4.0};
  const double p[3] = {1.0, 2.2, 3.8};
  std::vector<json> presets;
  for (int i = 0; i < 3; ++i) {
    json s = default_scene();
    s["layers"][0]["thickness_mm"] = h[i];
    s["layers"][0]["force_law"]["cutting_force_N"] = p[i];
    presets.push_back(s);
  }
  const SlabRule rule = fit_slab_rule(presets, {"a", "b", "c"});
  const SlabRuleParameter* cut = find(rule, "skin", "/force_law/cutting_force_N");
  ASSERT_NE(cut, nullptr);
  const double x[3] = {0.0, std::log(2.0), std::log(4.0)};
  const double y[3] = {0.0, std::log(2.2), std::log(3.8)};
  const double mx = (x[0] + x[1] + x[2]) / 3, my = (y[0] + y[1] + y[2]) / 3;
  double sxx = 0, sxy = 0;
  for (int i = 0; i < 3; ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
  const double slope = sxy / sxx, intercept = my - slope * mx;
  double rss = 0;
  for (int i = 0; i < 3; ++i) rss += std::pow(y[i] - intercept - slope * x[i], 2);
  EXPECT_NEAR(cut->exponent, slope, 1e-12);
  EXPECT_NEAR(cut->value_at_reference, std::exp(intercept), 1e-12);
  EXPECT_NEAR(*cut->exponent_standard_error, std::sqrt(rss / 1.0 / sxx), 1e-12);
  EXPECT_NEAR(*cut->log_residual_rms, std::sqrt(rss / 3.0), 1e-12);
  // Without the middle slab the rule is the line through the outer two: p = 3.8^(x / ln 4).
  const double loo_middle = std::exp(std::log(3.8) * 0.5) / 2.2 - 1.0;
  EXPECT_NEAR(*cut->samples[1].leave_one_out_relative_error, loo_middle, 1e-12);
}

TEST(SlabRule, AppliedToASceneAndToTheCasesThatChangeTheSlab) {
  const SlabRule rule = fit_slab_rule({family_member(0.8, 8.4, 39), family_member(1.6, 4, 33)}, {"a.json", "b.json"});
  json scene = default_scene();
  scene["layers"][0]["thickness_mm"] = 1.2;
  scene["layers"][1]["thickness_mm"] = 5.0;
  scene["layers"][2]["thickness_mm"] = 30.0;
  const double fat_before = scene["layers"][1]["force_law"]["cutting_force_N"].get<double>();
  const std::vector<std::string> notes = apply_slab_rule(scene, rule, "scene.json");
  EXPECT_NEAR(scene["layers"][0]["force_mesh"]["K_N_per_mm"].get<double>(), 0.05 * std::pow(1.2, 1.5), 1e-12);
  EXPECT_NEAR(scene["layers"][0]["force_law"]["cutting_force_N"].get<double>(), 2.0 * std::pow(1.5, 2.0), 1e-10);
  EXPECT_EQ(scene["layers"][1]["force_law"]["cutting_force_N"].get<double>(), fat_before);  // not ruled
  ASSERT_EQ(notes.size(), 1u);  // the muscle's 30 mm lies outside the family's 33-39 mm
  EXPECT_NE(notes[0].find("muscle"), std::string::npos);
  EXPECT_NE(notes[0].find("extrapolated"), std::string::npos);

  // Written, read back, and given with a validation case that changes the
  // slab: the case's scene has the rule's values; a case on the model's own
  // slab (no thickness override) is left alone.
  const fs::path dir = fs::temp_directory_path() / ("puncture_slab_rule_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "slab_rule.json") << slab_rule_json(rule, json::object()).dump(2);
  const SlabRule read = read_slab_rule(dir / "slab_rule.json");
  ValidationCase slab;
  slab.name = "slab";
  slab.layer_thickness_mm = {1.2, 5, 30};
  const CaseScene cs = case_scene(default_scene().dump(), "default.json", slab, &read);
  EXPECT_TRUE(cs.slab_rule_applied);
  EXPECT_NEAR(cs.scene.layers[0].force_mesh.virtual_stiffness_N_per_m, 1e3 * 0.05 * std::pow(1.2, 1.5), 1e-6);
  EXPECT_NEAR(cs.scene.layers[2].force_mesh.virtual_stiffness_N_per_m, 1e3 * 0.05 * std::sqrt(30.0), 1e-6);
  EXPECT_EQ(cs.rule_notes.size(), 1u);
  const std::string text = slab_rule_case_text(read, "rule.json", cs.rule_notes);
  EXPECT_NE(text.find("rule.json"), std::string::npos);
  EXPECT_NE(text.find("0.8/8.4/39, 1.6/4/33"), std::string::npos) << text;
  EXPECT_NE(text.find("extrapolated"), std::string::npos) << text;
  ValidationCase speed;
  speed.name = "fast";
  speed.insertion_overrides = {{"speed_mm_per_s", 20.0}};
  const CaseScene unchanged = case_scene(default_scene().dump(), "default.json", speed, &read);
  EXPECT_FALSE(unchanged.slab_rule_applied);
  EXPECT_EQ(unchanged.scene.layers[0].force_mesh.virtual_stiffness_N_per_m,
            load_scene(fs::path(PUNCTURE_SOURCE_DIR) / "scenes" / "default.json").layers[0].force_mesh.virtual_stiffness_N_per_m);
  fs::remove_all(dir);
}

std::string fit_error(std::vector<json> presets) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < presets.size(); ++i) names.push_back("p" + std::to_string(i) + ".json");
  try {
    fit_slab_rule(presets, names);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

TEST(SlabRule, ACountSuchAsTheRingNumberIsRuledAndRounded) {
  // w = 8 on 0.8 mm, 12 on 1.6 mm: alpha = ln 1.5 / ln 2; at 1.2 mm 8 (1.5)^0.585 = 10.1 -> 10.
  json thick = family_member(1.6, 4, 33);
  thick["layers"][0]["force_mesh"]["w"] = 12;
  json thin = family_member(0.8, 8.4, 39);
  thin["layers"][0]["force_mesh"]["w"] = 8;
  const SlabRule rule = fit_slab_rule({thin, thick}, {"a", "b"});
  const SlabRuleParameter* w = find(rule, "skin", "/force_mesh/w");
  ASSERT_NE(w, nullptr);
  EXPECT_TRUE(w->integer);
  EXPECT_NEAR(w->exponent, std::log(1.5) / std::log(2.0), 1e-12);
  json scene = default_scene();
  scene["layers"][0]["thickness_mm"] = 1.2;
  apply_slab_rule(scene, rule, "scene.json");
  ASSERT_TRUE(scene["layers"][0]["force_mesh"]["w"].is_number_integer());
  EXPECT_EQ(scene["layers"][0]["force_mesh"]["w"].get<int>(), 10);
  scene["layers"][0]["thickness_mm"] = 0.01;  // far below: at least one ring
  apply_slab_rule(scene, rule, "scene.json");
  EXPECT_EQ(scene["layers"][0]["force_mesh"]["w"].get<int>(), 1);
  // The flag survives the file.
  const fs::path f = fs::temp_directory_path() / ("puncture_rule_w_" + std::to_string(::getpid()) + ".json");
  std::ofstream(f) << slab_rule_json(rule, json::object()).dump();
  const SlabRule read = read_slab_rule(f);
  fs::remove(f);
  ASSERT_NE(find(read, "skin", "/force_mesh/w"), nullptr);
  EXPECT_TRUE(find(read, "skin", "/force_mesh/w")->integer);
  EXPECT_FALSE(find(read, "skin", "/force_mesh/K_N_per_mm")->integer);
}

/// A calibration record (a provenance's "calibrated_values") with each
/// (layer, pointer, status) given.
PresetCalibration record(const std::vector<std::array<std::string, 3>>& entries) {
  json values = json::array();
  for (const auto& e : entries) values.push_back({{"layer", e[0]}, {"pointer", e[1]}, {"status", e[2]}, {"reason", ""}});
  return read_preset_calibration(json{{"calibrated_values", values}}, "p.provenance.json");
}

TEST(SlabRule, OnlyValuesTheCalibrationIdentifiedEnterTheFit) {
  // The muscle's K is an exact power law (alpha 0.5) on three slabs; on the
  // fourth its calibration ended at a bound with a wild value, which must not
  // move the rule. The skin's cutting force is identified on one slab only:
  // not ruled. The fat's K was not set by the fourth slab's calibration (kept):
  // left out, and a non-positive value there is no error.
  std::vector<json> family = {family_member(0.8, 8.4, 39), family_member(1.6, 4, 33), family_member(1.0, 6.5, 28),
                              family_member(1.3, 7.5, 32)};
  family[3]["layers"][2]["force_mesh"]["K_N_per_mm"] = 1e3;
  family[3]["layers"][1]["force_mesh"]["K_N_per_mm"] = 0.0;
  const std::vector<std::string> names = {"a.json", "b.json", "c.json", "d.json"};
  std::vector<PresetCalibration> records;
  for (int i = 0; i < 4; ++i) {
    std::vector<std::array<std::string, 3>> e = {
        {"skin", "/force_mesh/K_N_per_mm", "identified"},
        {"muscle", "/force_mesh/K_N_per_mm", i == 3 ? "at a bound" : "identified"},
        {"skin", "/force_law/cutting_force_N", i == 1 ? "identified" : "not identifiable"}};
    if (i < 3) e.push_back({"fat", "/force_mesh/K_N_per_mm", "identified"});
    records.push_back(record(e));
  }
  const SlabRule rule = fit_slab_rule(family, names, records);
  const SlabRuleParameter* k_muscle = find(rule, "muscle", "/force_mesh/K_N_per_mm");
  ASSERT_NE(k_muscle, nullptr);
  EXPECT_NEAR(k_muscle->exponent, 0.5, 1e-10);  // exact: the wild value is out
  ASSERT_EQ(k_muscle->samples.size(), 3u);
  EXPECT_EQ(k_muscle->samples[2].file, "c.json");
  ASSERT_EQ(k_muscle->excluded.size(), 1u);
  EXPECT_EQ(k_muscle->excluded[0], (std::pair<std::string, std::string>{"d.json", "at a bound"}));
  const SlabRuleParameter* k_fat = find(rule, "fat", "/force_mesh/K_N_per_mm");
  ASSERT_NE(k_fat, nullptr);
  EXPECT_NEAR(k_fat->exponent, 1.0, 1e-10);
  ASSERT_EQ(k_fat->excluded.size(), 1u);
  EXPECT_EQ(k_fat->excluded[0].second, "not calibrated (kept)");
  EXPECT_NEAR(find(rule, "skin", "/force_mesh/K_N_per_mm")->exponent, 1.5, 1e-10);  // identified everywhere
  EXPECT_EQ(find(rule, "skin", "/force_law/cutting_force_N"), nullptr);
  ASSERT_EQ(rule.layers[0].not_ruled.size(), 1u);
  EXPECT_EQ(rule.layers[0].not_ruled[0].pointer, "/force_law/cutting_force_N");
  EXPECT_NE(rule.layers[0].not_ruled[0].reason.find("identified on 1 of 4 slabs"), std::string::npos)
      << rule.layers[0].not_ruled[0].reason;
  EXPECT_NE(rule.layers[0].not_ruled[0].reason.find("a.json: not identifiable"), std::string::npos);
  // Two identified slabs of four: no leave-one-out check, not ruled either.
  records[2].status[{"muscle", "/force_mesh/K_N_per_mm"}] = "not identifiable";
  const SlabRule two = fit_slab_rule(family, names, records);
  EXPECT_EQ(find(two, "muscle", "/force_mesh/K_N_per_mm"), nullptr);
  ASSERT_EQ(two.layers[2].not_ruled.size(), 1u);
  EXPECT_NE(two.layers[2].not_ruled[0].reason.find("identified on 2 of 4 slabs (a rule needs 3"), std::string::npos)
      << two.layers[2].not_ruled[0].reason;
  records[2].status[{"muscle", "/force_mesh/K_N_per_mm"}] = "identified";
  EXPECT_TRUE(rule.presets[0].calibration_record);

  // A scene keeps its own value of what is not ruled.
  json scene = default_scene();
  const double cut = scene["layers"][0]["force_law"]["cutting_force_N"].get<double>();
  scene["layers"][2]["thickness_mm"] = 30.0;
  apply_slab_rule(scene, rule, "scene.json");
  EXPECT_DOUBLE_EQ(scene["layers"][0]["force_law"]["cutting_force_N"].get<double>(), cut);
  EXPECT_NEAR(scene["layers"][2]["force_mesh"]["K_N_per_mm"].get<double>(), 0.05 * std::sqrt(30.0), 1e-12);

  // The file keeps the excluded slabs and what is not ruled; the page shows both.
  const fs::path f = fs::temp_directory_path() / ("puncture_rule_excl_" + std::to_string(::getpid()) + ".json");
  std::ofstream(f) << slab_rule_json(rule, json::object()).dump();
  const SlabRule read = read_slab_rule(f);
  fs::remove(f);
  ASSERT_NE(find(read, "muscle", "/force_mesh/K_N_per_mm"), nullptr);
  EXPECT_EQ(find(read, "muscle", "/force_mesh/K_N_per_mm")->excluded, k_muscle->excluded);
  ASSERT_EQ(read.layers[0].not_ruled.size(), 1u);
  EXPECT_EQ(read.layers[0].not_ruled[0].reason, rule.layers[0].not_ruled[0].reason);
  const std::string md = slab_rule_markdown(rule, "cmd", "here");
  EXPECT_NE(md.find("(at a bound)"), std::string::npos) << md;
  EXPECT_NE(md.find("## Not ruled"), std::string::npos);

  // Without records every value counts: the wild value moves the rule.
  family[3]["layers"][1]["force_mesh"]["K_N_per_mm"] = 0.05 * 7.5;
  const SlabRule blind = fit_slab_rule(family, names);
  EXPECT_GT(std::abs(find(blind, "muscle", "/force_mesh/K_N_per_mm")->exponent - 0.5), 1.0);
  EXPECT_FALSE(blind.presets[0].calibration_record);
}

TEST(SlabRule, ACalibrationRecordIsReadFromTheProvenance) {
  EXPECT_FALSE(read_preset_calibration(json{{"preset", "p"}}, "p.provenance.json").known);
  const PresetCalibration c = record({{"skin", "/force_mesh/w", "not identifiable"}});
  EXPECT_TRUE(c.known);
  EXPECT_EQ(c.status.at({"skin", "/force_mesh/w"}), "not identifiable");
  try {
    read_preset_calibration(json{{"calibrated_values", json::array({json{{"layer", "skin"}, {"status", "identified"}}})}},
                            "p.provenance.json");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("p.provenance.json: /calibrated_values/0/pointer"), std::string::npos) << e.what();
  }
}

TEST(SlabRule, ErrorsNameThePresetAndTheField) {
  EXPECT_NE(fit_error({family_member(0.8, 8.4, 39)}).find("two slabs"), std::string::npos);
  json zero = family_member(1.6, 4, 33);
  zero["layers"][0]["force_law"]["cutting_force_N"] = 0.0;
  const std::string e1 = fit_error({family_member(0.8, 8.4, 39), zero});
  EXPECT_NE(e1.find("p1.json: /layers/0/force_law/cutting_force_N"), std::string::npos) << e1;
  EXPECT_NE(e1.find("positive"), std::string::npos) << e1;
  json same = family_member(0.8, 8.4, 39);
  same["layers"][0]["force_law"]["cutting_force_N"] = 3.0;  // differs, but the skin's thickness does not
  same["layers"][1]["thickness_mm"] = 4.0;
  same["layers"][2]["thickness_mm"] = 33.0;
  const std::string e2 = fit_error({family_member(0.8, 8.4, 39), same});
  EXPECT_NE(e2.find("same thickness"), std::string::npos) << e2;
  json renamed = family_member(1.6, 4, 33);
  renamed["layers"][1]["name"] = "adipose";
  EXPECT_NE(fit_error({family_member(0.8, 8.4, 39), renamed}).find("/layers/1/name"), std::string::npos);

  // A rule naming a parameter the scene lacks; a malformed rule file.
  SlabRule rule = fit_slab_rule({family_member(0.8, 8.4, 39), family_member(1.6, 4, 33)}, {"a", "b"});
  rule.layers[0].parameters[0].pointer = "/force_mesh/no_such_field";
  json scene = default_scene();
  try {
    apply_slab_rule(scene, rule, "scene.json");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("scene.json: /layers/0/force_mesh/no_such_field"), std::string::npos) << e.what();
  }
  const fs::path bad = fs::temp_directory_path() / ("puncture_bad_rule_" + std::to_string(::getpid()) + ".json");
  std::ofstream(bad) << R"({"layers": [{"layer": "skin", "reference_thickness_mm": 1,
      "thickness_range_mm": [1, 2], "parameters": [{"pointer": "/force_mesh/K_N_per_mm", "variable": "age",
      "reference_mm": 1, "range_mm": [1, 2], "value_at_reference": 1, "exponent": 1}]}]})";
  try {
    read_slab_rule(bad);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/layers/0/parameters/0/variable"), std::string::npos) << e.what();
  }
  fs::remove(bad);
}

}  // namespace
}  // namespace puncture::validation
