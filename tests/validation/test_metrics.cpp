// Insertion curves and metrics against closed forms: linear force ramps whose
// RMSE is known exactly, shifted puncture depths, linear deflection profiles.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "puncture/model/realtime_model.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/metrics.hpp"
#include "puncture/validation/recording.hpp"
#include "puncture/validation/puncture_events.hpp"

namespace pv = puncture::validation;
using puncture::LayerState;

namespace {

/// A hand-built curve: depths d_i = i * step (m), force = f(d), one layer
/// "skin" pressed for d in [0, puncture) and punctured from `puncture` on.
template <class F>
pv::InsertionCurve ramp_curve(int n, double step_m, F force, double puncture_m) {
  pv::InsertionCurve c;
  c.source = "hand-built";
  c.layer_names = {"skin"};
  c.layer_states.resize(1);
  for (int i = 0; i < n; ++i) {
    const double d = i * step_m;
    c.time_s.push_back(0.1 * i);
    c.depth_m.push_back(d);
    c.velocity_m_per_s.push_back(0.01);
    c.force_N.push_back(force(d));
    c.layer_states[0].push_back(d >= puncture_m - 1e-12 ? LayerState::Punctured : LayerState::Pressed);
  }
  return c;
}

}  // namespace

TEST(Metrics, ReadsCsvWithMetadataAndStates) {
  const std::string text =
      "# needle_gauge: 18\n"
      "# speed_mm_per_s: 10\n"
      "# source: bench test, porcine skin\n"
      "time_s,depth_mm,velocity_mm_per_s,force_N,skin_state,skin_surface_force_N\n"
      "0,-1,10,0,untouched,0\n"
      "0.1,0,10,0.05,pressed,0.05\n"
      "0.2,1,10,0.5,punctured,0\n";
  const pv::InsertionCurve c = pv::parse_insertion_curve(text, "measured.csv");
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c.metadata.at("needle_gauge"), "18");
  EXPECT_EQ(c.metadata.at("source"), "bench test, porcine skin");
  double speed = 0.0;
  ASSERT_TRUE(c.metadata_number("speed_mm_per_s", speed));
  EXPECT_DOUBLE_EQ(speed, 10.0);
  EXPECT_DOUBLE_EQ(c.depth_m[2], 1e-3);
  EXPECT_DOUBLE_EQ(c.velocity_m_per_s[0], 0.01);
  EXPECT_DOUBLE_EQ(c.force_N[2], 0.5);
  ASSERT_EQ(c.layer_names, std::vector<std::string>{"skin"});
  EXPECT_EQ(c.layer_states[0][1], LayerState::Pressed);
  EXPECT_EQ(c.layer_states[0][2], LayerState::Punctured);

  // Round trip through the writer.
  const pv::InsertionCurve back = pv::parse_insertion_curve(pv::insertion_curve_csv(c), "again.csv");
  EXPECT_EQ(back.metadata, c.metadata);
  EXPECT_EQ(back.depth_m, c.depth_m);
  EXPECT_EQ(back.force_N, c.force_N);
  EXPECT_EQ(back.layer_states, c.layer_states);
}

TEST(Metrics, ReadErrorsNameFileLineAndColumn) {
  auto message = [](const std::string& text) {
    try {
      pv::parse_insertion_curve(text, "bad.csv");
    } catch (const pv::CurveFormatError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string header = "time_s,depth_mm,velocity_mm_per_s,force_N,fat_state\n";
  // Depth and force are required (time and velocity are optional).
  std::string m = message("time_s,depth_mm,velocity_mm_per_s\n0,0,0\n");
  EXPECT_NE(m.find("bad.csv:1"), std::string::npos) << m;
  EXPECT_NE(m.find("force_N"), std::string::npos) << m;
  m = message("time_s,force_N\n0,0\n");
  EXPECT_NE(m.find("depth_mm"), std::string::npos) << m;
  m = message("depth_mm,force_N,tip_force_N,cutting_force_N\n0,0,0,0\n");
  EXPECT_NE(m.find("friction_force_N"), std::string::npos) << m;
  m = message("depth_mm,force_N,phase\n0,0,retraction\n");
  EXPECT_NE(m.find("bad.csv:2"), std::string::npos) << m;
  EXPECT_NE(m.find("column 'phase'"), std::string::npos) << m;
  m = message(header + "0,0,10,0,untouched\n0.1,0.5,10,abc,pressed\n");
  EXPECT_NE(m.find("bad.csv:3"), std::string::npos) << m;
  EXPECT_NE(m.find("column 'force_N'"), std::string::npos) << m;
  m = message(header + "0,0,10,0,broken\n");
  EXPECT_NE(m.find("bad.csv:2"), std::string::npos) << m;
  EXPECT_NE(m.find("fat_state"), std::string::npos) << m;
  m = message(header + "0,0,10,0\n");
  EXPECT_NE(m.find("expected 5 fields"), std::string::npos) << m;
  m = message(header + "0,0,10,0,untouched\n0,1,10,0,untouched\n");
  EXPECT_NE(m.find("time must increase"), std::string::npos) << m;
  m = message(header + "0,0,10,nan,untouched\n");
  EXPECT_NE(m.find("not a finite number"), std::string::npos) << m;
  EXPECT_THROW(pv::read_insertion_curve("/nonexistent/curve.csv"), pv::CurveFormatError);
}

TEST(Metrics, ReadFromFileRecordsContentHash) {
  const auto path = std::filesystem::temp_directory_path() / "puncture_test_metrics_curve.csv";
  {
    std::ofstream out(path);
    out << "time_s,depth_mm,velocity_mm_per_s,force_N\n0,0,1,0\n1,1,1,1\n";
  }
  const pv::InsertionCurve a = pv::read_insertion_curve(path);
  EXPECT_EQ(a.content_hash.size(), 16u);
  {
    std::ofstream out(path);
    out << "time_s,depth_mm,velocity_mm_per_s,force_N\n0,0,1,0\n1,1,1,2\n";
  }
  EXPECT_NE(pv::read_insertion_curve(path).content_hash, a.content_hash);
  std::filesystem::remove(path);
}

TEST(Metrics, RmseOfLinearRampsIsExact) {
  // Reference F = 100 d on d = 0, 0.5, ..., 10 mm; model F = 120 d sampled
  // twice as densely (linear interpolation is exact for a linear curve).
  // Error at d_i is 20 d_i, so RMSE = 20 sqrt(mean d_i^2) with
  // mean d_i^2 = step^2 * sum_{i=0}^{20} i^2 / 21 = step^2 * 2870 / 21.
  const double step = 0.5e-3;
  const auto ref = ramp_curve(21, step, [](double d) { return 100.0 * d; }, 1.0);
  const auto model = ramp_curve(41, step / 2, [](double d) { return 120.0 * d; }, 1.0);
  const pv::CurveComparison c = pv::compare_curves(model, ref);
  EXPECT_EQ(c.n_compared, 21u);
  const double expected = 20.0 * step * std::sqrt(2870.0 / 21.0);
  EXPECT_NEAR(c.force_rmse_N, expected, 1e-14);
  EXPECT_NEAR(c.reference_peak_force_N, 100.0 * 10e-3, 1e-14);
  EXPECT_NEAR(c.force_rmse_relative, expected / 1.0, 1e-12);

  // A constant offset of 0.03 N: RMSE = 0.03 exactly.
  const auto shifted = ramp_curve(41, step / 2, [](double d) { return 100.0 * d + 0.03; }, 1.0);
  EXPECT_NEAR(pv::compare_curves(shifted, ref).force_rmse_N, 0.03, 1e-14);

  // max_depth: only d <= 5 mm (11 samples): mean d^2 = step^2 * 385 / 11.
  const pv::CurveComparison half = pv::compare_curves(model, ref, 5e-3);
  EXPECT_EQ(half.n_compared, 11u);
  EXPECT_NEAR(half.force_rmse_N, 20.0 * step * std::sqrt(385.0 / 11.0), 1e-14);
}

TEST(Metrics, ReferenceSamplesOutsideTheModelRangeAreSkipped) {
  const auto ref = ramp_curve(21, 0.5e-3, [](double d) { return 100.0 * d; }, 1.0);
  const auto shorter = ramp_curve(11, 0.5e-3, [](double d) { return 100.0 * d; }, 1.0);  // to 5 mm
  const pv::CurveComparison c = pv::compare_curves(shorter, ref);
  EXPECT_EQ(c.n_compared, 11u);
  EXPECT_NEAR(c.force_rmse_N, 0.0, 1e-15);
  EXPECT_NEAR(c.compared_to_depth_m, 5e-3, 1e-15);
}

TEST(Metrics, OnlyTheInsertionPhaseIsCompared) {
  auto ref = ramp_curve(11, 1e-3, [](double d) { return 50.0 * d; }, 1.0);
  auto model = ref;
  // Withdrawal samples (velocity < 0) with a very different force: ignored.
  for (int i = 1; i <= 5; ++i) {
    model.time_s.push_back(10.0 + i);
    model.depth_m.push_back(10e-3 - i * 1e-3);
    model.velocity_m_per_s.push_back(-0.01);
    model.force_N.push_back(-7.0);
    model.layer_states[0].push_back(LayerState::Pressed);
  }
  EXPECT_EQ(pv::insertion_phase(model).size(), 11u);
  EXPECT_NEAR(pv::compare_curves(model, ref).force_rmse_N, 0.0, 1e-15);

  // Depth going back during the insertion phase is an error naming the sample.
  auto bad = ref;
  bad.depth_m[5] = bad.depth_m[3];
  try {
    pv::insertion_phase(bad);
    FAIL();
  } catch (const pv::CurveFormatError& e) {
    EXPECT_NE(std::string(e.what()).find("sample 6"), std::string::npos) << e.what();
  }
}

TEST(Metrics, PerLayerRmseAndShiftedPunctureDepth) {
  // Reference: skin pressed on [0, 3) mm with F = 200 d, punctured from 3 mm
  // (F = 0.1 N after). Model: same slope, punctures at 3.5 mm.
  const double step = 0.25e-3;
  auto force_ref = [](double d) { return d < 3e-3 - 1e-12 ? 200.0 * d : 0.1; };
  auto force_mod = [](double d) { return d < 3.5e-3 - 1e-12 ? 200.0 * d : 0.1; };
  const auto ref = ramp_curve(25, step, force_ref, 3e-3);    // 0 .. 6 mm
  const auto model = ramp_curve(25, step, force_mod, 3.5e-3);
  const pv::CurveComparison c = pv::compare_curves(model, ref);
  const pv::LayerMetrics* skin = c.layer("skin");
  ASSERT_NE(skin, nullptr);
  ASSERT_TRUE(skin->has_pressed_interval);
  EXPECT_NEAR(skin->pressed_from_depth_m, 0.0, 1e-15);
  EXPECT_NEAR(skin->pressed_to_depth_m, 2.75e-3, 1e-15);
  EXPECT_EQ(skin->n_samples, 12u);
  EXPECT_NEAR(skin->force_rmse_N, 0.0, 1e-15);  // identical inside the reference pressed interval
  ASSERT_TRUE(skin->reference_puncture.found);
  ASSERT_TRUE(skin->model_puncture.found);
  EXPECT_NEAR(skin->reference_puncture.depth_m, 3e-3, 1e-15);
  EXPECT_NEAR(skin->model_puncture.depth_m, 3.5e-3, 1e-15);
  EXPECT_NEAR(skin->puncture_depth_error_m, 0.5e-3, 1e-15);
  // Puncture force: max over the pressed samples just before = F(last pressed depth).
  EXPECT_NEAR(skin->reference_puncture.force_N, 200.0 * 2.75e-3, 1e-14);
  EXPECT_NEAR(skin->model_puncture.force_N, 200.0 * 3.25e-3, 1e-14);
  EXPECT_NEAR(skin->puncture_force_error_N, 0.1, 1e-14);
  // Overall: errors only at d = 3.0 and 3.25 mm: 200 d - 0.1 = 0.5 and 0.55.
  const double expected = std::sqrt((0.5 * 0.5 + 0.55 * 0.55) / 25.0);
  EXPECT_NEAR(c.force_rmse_N, expected, 1e-14);
  EXPECT_NEAR(c.force_rmse_relative, expected / 0.55, 1e-12);

  // A layer the model never punctures: found only on the reference side.
  auto never = ramp_curve(25, step, [](double d) { return 200.0 * d; }, 1.0);
  const pv::CurveComparison n = pv::compare_curves(never, ref);
  EXPECT_TRUE(n.layer("skin")->reference_puncture.found);
  EXPECT_FALSE(n.layer("skin")->model_puncture.found);
  EXPECT_DOUBLE_EQ(n.layer("skin")->puncture_depth_error_m, 0.0);
}

TEST(Metrics, ReferenceWithoutStatesIsJudgedOnItsOwnForceDrop) {
  // The model punctures the skin early (at 1 mm); the reference has no state
  // columns and drops at 3.5 mm. The skin's pressed interval is the
  // reference's own (contact onset to its drop), not the model's tiny one.
  auto model = ramp_curve(21, 0.5e-3, [](double d) { return 100.0 * d; }, 1e-3);
  auto ref = ramp_curve(21, 0.5e-3, [](double d) { return 100.0 * d + 0.02; }, 4e-3);
  ref.layer_names.clear();
  ref.layer_states.clear();
  ref.force_N[8] = 0.1;  // drop after 3.5 mm (100 x 3.5 mm + 0.02 = 0.37 N there)
  for (std::size_t i = 9; i < ref.size(); ++i) ref.force_N[i] = 0.1 + 10.0 * (ref.depth_m[i] - 4e-3);
  const pv::CurveComparison c = pv::compare_curves(model, ref);
  const pv::LayerMetrics* skin = c.layer("skin");
  ASSERT_NE(skin, nullptr);
  ASSERT_TRUE(skin->reference_puncture.found);
  EXPECT_NEAR(skin->reference_puncture.depth_m, 4e-3, 1e-15);  // first sample after the maximum
  EXPECT_NEAR(skin->reference_puncture.force_N, 0.37, 1e-12);
  EXPECT_NEAR(skin->pressed_to_depth_m, 4e-3, 1e-15);
  EXPECT_GE(skin->n_samples, 7u);  // from the contact onset to the drop, not the model's 2 samples
  EXPECT_TRUE(skin->model_puncture.found);
  EXPECT_NEAR(skin->puncture_depth_error_m, 1e-3 - 4e-3, 1e-15);
}

TEST(Metrics, CurveFromRunCopiesTicks) {
  puncture::Scene scene;
  puncture::Layer skin;
  skin.name = "skin";
  scene.layers = {skin};
  puncture::ScriptedRunResult run;
  for (int i = 0; i < 3; ++i) {
    puncture::TickResult t;
    t.time_s = i * 1e-3;
    t.depth_m = i * 1e-5;
    t.velocity_m_per_s = 0.01;
    t.total_force_N = 0.1 * i;
    t.layers.resize(1);
    t.layers[0].state = i == 2 ? LayerState::Punctured : LayerState::Pressed;
    run.ticks.push_back(t);
  }
  const pv::InsertionCurve c = pv::curve_from_run(scene, run);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_DOUBLE_EQ(c.force_N[2], 0.2);
  EXPECT_EQ(c.layer_states[0][2], LayerState::Punctured);
  const pv::PunctureEventMetrics e = pv::puncture_event(c, "skin");
  ASSERT_TRUE(e.found);
  EXPECT_DOUBLE_EQ(e.depth_m, 2e-5);
  EXPECT_DOUBLE_EQ(e.force_N, 0.1);
}

TEST(Metrics, PunctureForceIsThePeakOfTheRiseToTheBreakNotOfAnEarlierBreak) {
  // A layer pressed from the moment the layer above gave way: its pressed
  // samples start on the fall after that break (1.6 -> 0.9 N), then rise to its
  // own break at 1.2 N. Its puncture force is 1.2 N (the peak of the rise), not
  // the 1.6 N of the break above. A dip of less than 10 % of the peak on the
  // rise (1.15 -> 1.10 -> 1.2 N) is noise, not a trough.
  puncture::Scene scene;
  puncture::Layer muscle;
  muscle.name = "muscle";
  scene.layers = {muscle};
  const std::vector<double> force = {1.6, 1.3, 1.0, 0.9, 0.95, 1.05, 1.15, 1.10, 1.2, 0.8};
  puncture::ScriptedRunResult run;
  for (std::size_t i = 0; i < force.size(); ++i) {
    puncture::TickResult t;
    t.time_s = i * 1e-3;
    t.depth_m = i * 1e-5;
    t.velocity_m_per_s = 0.01;
    t.total_force_N = force[i];
    t.layers.resize(1);
    t.layers[0].state = i + 1 == force.size() ? LayerState::Punctured : LayerState::Pressed;
    run.ticks.push_back(t);
  }
  const pv::InsertionCurve c = pv::curve_from_run(scene, run);
  const pv::PunctureEventMetrics e = pv::puncture_event(c, "muscle");
  ASSERT_TRUE(e.found);
  EXPECT_DOUBLE_EQ(e.force_N, 1.2);
  // Pressed from the trough on, or rising all the way: the plain maximum.
  pv::InsertionCurve rising = c;
  rising.force_N = {0.2, 0.4, 0.6, 0.9, 1.0, 1.1, 1.3, 1.25, 1.2, 0.8};
  EXPECT_DOUBLE_EQ(pv::puncture_event(rising, "muscle").force_N, 1.3);
}

TEST(Metrics, DeflectionProfileErrorAgainstLinearProfile) {
  // Reference u_z(r) = -a (1 - r / R) on r = 0..R (deflection a (1 - r/R)),
  // R = 10 mm. Rings at r_j = (j - 1) L, L = 2 mm, w = 8: rings 1..6 lie
  // inside (r <= 10 mm), rings 7, 8 (12, 14 mm) are skipped. Model ring
  // deflections = reference + e_j with e = (1, -1, 1, -1, 1, -1) um:
  // RMSE = 1 um, max 1 um, relative = 1 um / a.
  const double a = 0.5e-3, R = 10e-3, L = 2e-3;
  pv::RadialProfile ref;
  for (int i = 0; i <= 20; ++i) {
    const double r = R * i / 20.0;
    ref.r_m.push_back(r);
    ref.uz_m.push_back(-a * (1.0 - r / R));
  }
  std::vector<double> rings;
  for (int j = 1; j <= 8; ++j) {
    const double r = (j - 1) * L;
    rings.push_back(a * (1.0 - r / R) + ((j % 2) ? 1e-6 : -1e-6));
  }
  const pv::DeflectionProfileError e = pv::deflection_profile_error(rings, L, ref);
  EXPECT_EQ(e.n_rings, 6u);
  EXPECT_NEAR(e.rmse_m, 1e-6, 1e-15);
  EXPECT_NEAR(e.max_abs_error_m, 1e-6, 1e-15);
  EXPECT_NEAR(e.relative_rmse, 1e-6 / a, 1e-12);
  EXPECT_THROW(pv::deflection_profile_error(rings, 0.0, ref), std::invalid_argument);
}

TEST(Metrics, SurfaceProfilesCsv) {
  const std::string text =
      "step,depth_mm,r_mm,uz_mm\n"
      "1,0.5,0,-0.5\n1,0.5,1,-0.25\n1,0.5,2,0\n"
      "2,1.0,0,-1.0\n2,1.0,1,-0.5\n2,1.0,2,0\n";
  const auto profiles = pv::parse_surface_profiles(text, "fem_surface_profile.csv");
  ASSERT_EQ(profiles.size(), 2u);
  EXPECT_EQ(profiles[1].step, 2);
  EXPECT_DOUBLE_EQ(profiles[1].uz_m[1], -0.5e-3);
  EXPECT_EQ(pv::profile_nearest_depth(profiles, 0.9e-3).step, 2);
  EXPECT_EQ(pv::profile_nearest_depth(profiles, 0.6e-3).step, 1);
  try {
    pv::parse_surface_profiles("step,depth_mm,r_mm,uz_mm\n1,0.5,1,0\n1,0.5,0.5,0\n", "p.csv");
    FAIL();
  } catch (const pv::CurveFormatError& e) {
    EXPECT_NE(std::string(e.what()).find("p.csv:3"), std::string::npos) << e.what();
    EXPECT_EQ(e.column(), "r_mm");
  }
}

TEST(Metrics, CurveRecordedTickByTickEqualsTheCurveOfTheStoredRun) {
  // simulate_curve (calibration's model runs) must give exactly what
  // curve_from_run of a stored scripted run gives, with and without damping.
  const puncture::Scene scene = puncture::load_scene(std::filesystem::path(PUNCTURE_SOURCE_DIR) / "scenes/default_force_law.json");
  puncture::Scene short_run = scene;
  short_run.insertion.target_depth_m = 12e-3;  // through skin and fat, into muscle
  short_run.insertion.dwell_s = 0.1;
  for (bool damping : {true, false}) {
    puncture::RealtimeModel a = puncture::build_realtime_model(short_run);
    puncture::RealtimeModel b = puncture::build_realtime_model(short_run);
    const pv::InsertionCurve stored = pv::curve_from_run(short_run, puncture::run_scripted_insertion(a, short_run), "x", damping);
    const pv::InsertionCurve streamed = pv::simulate_curve(b, short_run, "x", damping);
    ASSERT_EQ(stored.size(), streamed.size());
    EXPECT_EQ(stored.time_s, streamed.time_s);
    EXPECT_EQ(stored.depth_m, streamed.depth_m);
    EXPECT_EQ(stored.force_N, streamed.force_N);
    EXPECT_EQ(stored.tip_force_N, streamed.tip_force_N);
    EXPECT_EQ(stored.cutting_force_N, streamed.cutting_force_N);
    EXPECT_EQ(stored.friction_force_N, streamed.friction_force_N);
    EXPECT_EQ(stored.layer_states, streamed.layer_states);
    EXPECT_EQ(stored.phase, streamed.phase);
    EXPECT_EQ(stored.metadata, streamed.metadata);
    EXPECT_TRUE(pv::puncture_event(streamed, "skin").found);
  }
}
