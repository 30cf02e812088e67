// puncture_force_shares (puncture_force_shares.hpp): the force at a break split by term.
#include <gtest/gtest.h>

#include "puncture/model/realtime_model.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/puncture_force_shares.hpp"
#include "puncture/validation/recording.hpp"

namespace pv = puncture::validation;

TEST(PunctureForceShares, TermsAddUpToTheForceAtTheBreak) {
  puncture::PunctureEvent e;
  e.layer_name = "skin";
  e.depth_m = 9.5e-3;
  e.total_force_N = 3.5;
  e.cutting_force_N = 0.5;
  e.surface_force_N = 2.8;
  e.eq5_force_N = 2.0;
  e.mesh_reaction_N = 2.1;
  e.tip_stiffening_force_N = 0.7;
  const std::vector<pv::PunctureForceShares> s = pv::puncture_force_shares({e});
  ASSERT_EQ(s.size(), 1u);
  EXPECT_DOUBLE_EQ(s[0].eq5_N, 2.0);
  EXPECT_NEAR(s[0].mesh_dynamics_N, 0.1, 1e-15);
  EXPECT_DOUBLE_EQ(s[0].tip_stiffening_N, 0.7);
  EXPECT_DOUBLE_EQ(s[0].cutting_N, 0.5);
  EXPECT_NEAR(s[0].other_N, 0.2, 1e-15);
  EXPECT_NEAR(s[0].eq5_share(), 2.0 / 3.5, 1e-15);
  const std::string md = pv::puncture_force_shares_markdown(s);
  EXPECT_NE(md.find("| skin | 9.50 | 3.500 N | 2.000 N (57 %)"), std::string::npos) << md;
  EXPECT_NE(md.find("| 0.500 N (14 %) | 0.200 N (6 %) |"), std::string::npos) << md;
  EXPECT_DOUBLE_EQ(pv::puncture_force_shares_json(s)[0]["eq5_share"].get<double>(), 2.0 / 3.5);
}

TEST(PunctureForceShares, Eq5ShareOfTheLayersOwnPressingLeavesTheLayersAboveOut) {
  // The layer's own pressing force is its surface force: Eq. 5 + the mesh's
  // inertia and damping + the tip stiffening (2.0 + 0.1 + 0.7 N); the cutting
  // force of the crack above and the shaft are not the layer's.
  puncture::PunctureEvent e;
  e.layer_name = "fat";
  e.depth_m = 10e-3;
  e.total_force_N = 1.6;
  e.cutting_force_N = 1.5;
  e.eq5_force_N = 0.06;
  e.mesh_reaction_N = 0.07;
  e.tip_stiffening_force_N = 0.01;
  const pv::PunctureForceShares s = pv::puncture_force_shares({e}).at(0);
  EXPECT_NEAR(s.surface_N(), 0.08, 1e-15);
  EXPECT_NEAR(s.eq5_share(), 0.06 / 1.6, 1e-15);
  EXPECT_NEAR(s.eq5_share_of_surface(), 0.75, 1e-12);
  EXPECT_FALSE(s.reference.has_value());
  const std::string md = pv::puncture_force_shares_markdown({s});
  EXPECT_NE(md.find("| 75 % of 0.080 N |"), std::string::npos) << md;
  EXPECT_EQ(md.find("FEM depth"), std::string::npos) << "no reference table without a reference\n" << md;
  EXPECT_NEAR(pv::puncture_force_shares_json({s})[0]["eq5_share_of_surface"].get<double>(), 0.75, 1e-12);
  EXPECT_TRUE(pv::puncture_force_shares_json({s})[0]["reference"].is_null());
}

namespace {
// A reference curve with parts and states: the skin pressed to 9.6 mm and
// punctured from 9.8, the fat pressed at 9.8 and punctured from 10.0, the
// muscle never reached. Force = tip + cutting + friction on every row.
const char* kReferenceCurve =
    "time_s,depth_mm,velocity_mm_per_s,force_N,tip_force_N,cutting_force_N,friction_force_N,phase,skin_state,fat_state,"
    "muscle_state\n"
    "0.94,9.4,10,2.6,2.55,0,0.05,insertion,pressed,untouched,untouched\n"
    "0.96,9.6,10,2.8,2.75,0,0.05,insertion,pressed,untouched,untouched\n"
    "0.98,9.8,10,2.5,-0.05,2.3,0.25,insertion,punctured,pressed,untouched\n"
    "1.00,10.0,10,2.2,0.85,1.2,0.15,insertion,punctured,punctured,untouched\n"
    "1.02,10.2,10,1.9,0.5,1.3,0.1,insertion,punctured,punctured,untouched\n";
}  // namespace

TEST(PunctureForceShares, ReferencePartsAreTheLastPressedSampleBeforeTheBreak) {
  const pv::InsertionCurve fem = pv::parse_insertion_curve(kReferenceCurve, "fem");
  const auto skin = pv::reference_parts_before_puncture(fem, "skin");
  ASSERT_TRUE(skin.has_value());
  EXPECT_NEAR(skin->depth_m, 9.6e-3, 1e-12);
  EXPECT_DOUBLE_EQ(skin->total_N, 2.8);
  EXPECT_DOUBLE_EQ(skin->tip_N, 2.75);
  const auto fat = pv::reference_parts_before_puncture(fem, "fat");
  ASSERT_TRUE(fat.has_value());
  EXPECT_NEAR(fat->depth_m, 9.8e-3, 1e-12);
  EXPECT_DOUBLE_EQ(fat->tip_N, -0.05);
  EXPECT_DOUBLE_EQ(fat->cutting_N, 2.3);
  EXPECT_DOUBLE_EQ(fat->friction_N, 0.25);
  EXPECT_FALSE(pv::reference_parts_before_puncture(fem, "muscle").has_value()) << "never punctured";
  EXPECT_FALSE(pv::reference_parts_before_puncture(fem, "bone").has_value()) << "no such layer";

  // Punctured at the first sample, never pressed before: nothing.
  const pv::InsertionCurve at_once = pv::parse_insertion_curve(
      "time_s,depth_mm,force_N,tip_force_N,cutting_force_N,friction_force_N,skin_state\n"
      "0,1,0.5,0.5,0,0,punctured\n0.1,2,0.6,0.6,0,0,punctured\n",
      "at_once");
  EXPECT_FALSE(pv::reference_parts_before_puncture(at_once, "skin").has_value());
  // Without parts: nothing.
  const pv::InsertionCurve no_parts = pv::parse_insertion_curve(
      "time_s,depth_mm,force_N,skin_state\n0,1,0.5,pressed\n0.1,2,0.6,punctured\n", "no_parts");
  EXPECT_FALSE(pv::reference_parts_before_puncture(no_parts, "skin").has_value());

  // The shares carry it and the page shows it beside the model's own pressing.
  puncture::PunctureEvent e;
  e.layer_name = "fat";
  e.depth_m = 10e-3;
  e.total_force_N = 1.6;
  e.cutting_force_N = 1.5;
  e.eq5_force_N = 0.08;
  e.mesh_reaction_N = 0.08;
  const std::vector<pv::PunctureForceShares> s = pv::puncture_force_shares({e}, &fem);
  ASSERT_TRUE(s.at(0).reference.has_value());
  const std::string md = pv::puncture_force_shares_markdown(s);
  EXPECT_NE(md.find("| fat | 9.80 | 2.500 N | -0.050 N (-2 %) | 2.300 N (92 %) | 0.250 N (10 %) | 0.080 N (5 %) |"),
            std::string::npos)
      << md;
  EXPECT_NEAR(pv::puncture_force_shares_json(s)[0]["reference"]["cutting_above_N"].get<double>(), 2.3, 1e-15);
}

TEST(PunctureForceShares, Eq5CarriesEachLayersOwnPressingInTheCommittedTunedPreset) {
  // The real-time physics acceptance: before each puncture the layer's force
  // is Eq. 5 on its force mesh's deflections, not the tip spring's
  // stiffening. Run the committed tuned preset along its own trajectory.
  const puncture::Scene scene =
      puncture::load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/results/tuned_preset/default_tuned.json");
  puncture::RealtimeModel model = puncture::build_realtime_model(scene);
  const puncture::ScriptedRunResult run = puncture::run_scripted_insertion(model, scene);
  const std::vector<pv::PunctureForceShares> shares = pv::puncture_force_shares(run.events);
  ASSERT_EQ(shares.size(), scene.layers.size());
  for (const pv::PunctureForceShares& s : shares) {
    SCOPED_TRACE(s.layer);
    EXPECT_GT(s.surface_N(), 0.0);
    EXPECT_GT(s.eq5_share_of_surface(), 0.5);
    EXPECT_LT(s.tip_stiffening_N, 0.1 * s.surface_N());
  }
  // The skin, met first, has nothing above it: Eq. 5 is most of the needle force.
  EXPECT_EQ(shares.front().layer, scene.layers.front().name);
  EXPECT_GT(shares.front().eq5_share(), 0.5);
}
