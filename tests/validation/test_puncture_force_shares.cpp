// puncture_force_shares (puncture_force_shares.hpp): the force at a break split by term.
#include <gtest/gtest.h>

#include "puncture/validation/puncture_force_shares.hpp"

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
