// The shaft-force rule shared by the haptic tick and the comparison harness
// (shaft_forces.hpp), against hand values of phi h, d h v and the crack law.
#include <cmath>
#include <gtest/gtest.h>

#include "puncture/shaft_forces.hpp"

using namespace puncture;

namespace {

NeedleState needle_at(double depth_m, double velocity_m_per_s) {
  NeedleState n;
  n.tip_position_m = Eigen::Vector3d(0.0, 0.0, -depth_m);
  n.axial_velocity_m_per_s = velocity_m_per_s;
  return n;
}

}  // namespace

TEST(ShaftForces, FrictionAndDampingOfAPuncturedLayerAreThePaperTerms) {
  // Layer from 2 mm to 10 mm, tip at 6 mm: h = 4 mm inside it.
  ShaftFrictionLaw law;
  law.static_N_per_m = 300.0;
  law.dynamic_N_per_m = 200.0;
  LayerShaftFriction friction(law, Viscoelasticity{});
  const double d = 500.0;  // N s / m^2
  const LayerShaftForce f = punctured_layer_shaft_force(2e-3, 8e-3, &friction, true, d, needle_at(6e-3, 0.01));
  EXPECT_DOUBLE_EQ(f.shaft_length_m, 4e-3);
  EXPECT_NEAR(f.friction_N, 200.0 * 4e-3, 1e-12);    // sliding in: f_d h
  EXPECT_NEAR(f.damping_N, 500.0 * 4e-3 * 0.01, 1e-15);  // d h v

  // Tip below the layer: the whole thickness; withdrawing reverses friction.
  const LayerShaftForce out = punctured_layer_shaft_force(2e-3, 8e-3, &friction, true, d, needle_at(15e-3, -0.01));
  EXPECT_DOUBLE_EQ(out.shaft_length_m, 8e-3);
  EXPECT_NEAR(out.friction_N, -200.0 * 8e-3, 1e-12);
  EXPECT_NEAR(out.damping_N, -500.0 * 8e-3 * 0.01, 1e-15);
}

TEST(ShaftForces, NothingWhenFrictionAndDampingAreOff) {
  const LayerShaftForce f = punctured_layer_shaft_force(0.0, 5e-3, nullptr, false, 1e3, needle_at(4e-3, 0.01));
  EXPECT_EQ(f.shaft_length_m, 0.0);
  EXPECT_EQ(f.friction_N, 0.0);
  EXPECT_EQ(f.damping_N, 0.0);
  const LayerShaftForce damping_only = punctured_layer_shaft_force(0.0, 5e-3, nullptr, true, 1e3, needle_at(4e-3, 0.01));
  EXPECT_EQ(damping_only.friction_N, 0.0);
  EXPECT_NEAR(damping_only.damping_N, 1e3 * 4e-3 * 0.01, 1e-15);
}

TEST(ShaftForces, CrackIsCutWhileOpenAndReleasesOnRetraction) {
  ForceLaw law;
  law.cutting_force_N = 1.5;
  law.cutting_release_m = 0.2e-3;
  double front = 5e-3;
  // Open (next layer untouched): the front follows the tip, the force is C.
  EXPECT_DOUBLE_EQ(open_crack_force_N(law, front, 6e-3, 0.01, NextLayerContact::None).total_N(), 1.5);
  EXPECT_DOUBLE_EQ(front, 6e-3);
  // Backing off by half the release distance: half the force, front kept.
  EXPECT_NEAR(open_crack_force_N(law, front, 5.9e-3, -0.01, NextLayerContact::MetAtTip).total_N(), 0.75, 1e-9);
  EXPECT_DOUBLE_EQ(front, 6e-3);
  // The next layer touched at its surface: the crack is closed, no force, front kept.
  EXPECT_EQ(open_crack_force_N(law, front, 7e-3, 0.01, NextLayerContact::Touched).total_N(), 0.0);
  EXPECT_DOUBLE_EQ(front, 6e-3);
  // Re-opened (met at the tip: the broken layer squeezed between): C again at the new front.
  EXPECT_DOUBLE_EQ(open_crack_force_N(law, front, 7e-3, 0.01, NextLayerContact::MetAtTip).total_N(), 1.5);
  EXPECT_DOUBLE_EQ(front, 7e-3);
}

TEST(ShaftForces, CuttingRateSplitsTheCrackForceIntoFractureAndViscousParts) {
  // C(v) = C [(1 - b) + b v / v_ref] (cutting.hpp), by hand: C = 1.2 N, b = 0.25, v_ref = 10 mm/s.
  ForceLaw law;
  law.cutting_force_N = 1.2;
  law.cutting_release_m = 0.2e-3;
  law.cutting_rate.viscous_fraction = 0.25;
  law.cutting_rate.reference_speed_m_per_s = 0.01;
  double front = 5e-3;
  // At v_ref the whole C, of it b C viscous.
  CuttingForceParts c = open_crack_force_N(law, front, 6e-3, 0.01, NextLayerContact::None);
  EXPECT_NEAR(c.fracture_N, 0.9, 1e-12);
  EXPECT_NEAR(c.bevel_N, 0.3, 1e-12);
  // At 20 mm/s: 0.9 + 0.3 x 2 = 1.5 N; at 3 mm/s 0.9 + 0.09 N.
  EXPECT_NEAR(open_crack_force_N(law, front, 6.1e-3, 0.02, NextLayerContact::None).total_N(), 1.5, 1e-12);
  EXPECT_NEAR(open_crack_force_N(law, front, 6.2e-3, 0.003, NextLayerContact::None).total_N(), 0.99, 1e-12);
  // Standing still (a dwell) or backing off: C (1 - b) only, released on
  // retraction; the crack does not grow, so none of it is fracture.
  c = open_crack_force_N(law, front, 6.2e-3, 0.0, NextLayerContact::None);
  EXPECT_NEAR(c.total_N(), 0.9, 1e-12);
  EXPECT_EQ(c.fracture_N, 0.0);
  c = open_crack_force_N(law, front, 6.1e-3, -0.01, NextLayerContact::None);
  EXPECT_NEAR(c.bevel_N, 0.45, 1e-9);
  EXPECT_EQ(c.fracture_N, 0.0);
  // Moving in again behind the front (re-entering the crack): still no growth.
  c = open_crack_force_N(law, front, 6.15e-3, 0.01, NextLayerContact::None);
  EXPECT_EQ(c.fracture_N, 0.0);
  EXPECT_GT(c.bevel_N, 0.0);
  // The speed is clamped to 100 v_ref.
  EXPECT_NEAR(rate_cutting_force(law, 5.0).bevel_N, 0.3 * 100.0, 1e-9);
  // b = 0: the paper's constant C at any speed.
  law.cutting_rate.viscous_fraction = 0.0;
  EXPECT_EQ(rate_cutting_force(law, 0.02).total_N(), 1.2);
  EXPECT_EQ(rate_cutting_force(law, 0.02).bevel_N, 0.0);
}

TEST(ShaftForces, OfTheCuttingForceOnlyGcTimesTheCutWidthIsFracture) {
  // C = 1.2 N, b = 0.25 at 10 mm/s: fracture part 0.9 N, bevel 0.3 N. With a
  // fracture limit G_c w = 550 J/m^2 x 1.27 mm = 0.6985 N, 0.2015 N of the
  // static part goes to the bevel; the total stays; released alike.
  ForceLaw law;
  law.cutting_force_N = 1.2;
  law.cutting_release_m = 0.2e-3;
  law.cutting_rate.viscous_fraction = 0.25;
  law.cutting_rate.reference_speed_m_per_s = 0.01;
  Layer muscle;
  muscle.puncture.kind = PunctureCriterion::Kind::FractureEnergy;
  muscle.puncture.toughness_J_per_m2 = 550.0;
  Needle needle;
  needle.radius_m = 0.635e-3;
  const double limit = fracture_limit_N(muscle, needle);
  EXPECT_NEAR(limit, 0.6985, 1e-12);
  double front = 5e-3;
  CuttingForceParts c = open_crack_force_N(law, front, 6e-3, 0.01, NextLayerContact::None, limit);
  EXPECT_NEAR(c.fracture_N, 0.6985, 1e-12);
  EXPECT_NEAR(c.bevel_N, 0.3 + 0.2015, 1e-12);
  EXPECT_NEAR(c.total_N(), 1.2, 1e-12);
  c = open_crack_force_N(law, front, 5.9e-3, 0.0, NextLayerContact::None, limit);  // half released, at rest
  EXPECT_EQ(c.fracture_N, 0.0);                   // the crack does not grow
  EXPECT_NEAR(c.bevel_N, 0.5 * 0.9, 1e-9);
  // A limit above the fracture part changes nothing; no toughness in the scene: no limit.
  c = open_crack_force_N(law, front, 6e-3, 0.01, NextLayerContact::None, 2.0);
  EXPECT_NEAR(c.fracture_N, 0.9, 1e-12);
  muscle.puncture.kind = PunctureCriterion::Kind::CriticalForce;
  EXPECT_TRUE(std::isinf(fracture_limit_N(muscle, needle)));
}

TEST(ShaftForces, RuptureReleaseLengthIsAPowerOfTheBreakSpeed) {
  // l(v_b) = l (v_b / v_ref)^m (cutting.hpp), by hand: l = 0.9 mm, m = 0.35, v_ref = 10 mm/s.
  ForceLaw law;
  law.rupture_release_m = 0.9e-3;
  law.rupture_release_rate.exponent = 0.35;
  law.rupture_release_rate.reference_speed_m_per_s = 0.01;
  EXPECT_NEAR(rupture_release_length_m(law, 0.01), 0.9e-3, 1e-15);
  EXPECT_NEAR(rupture_release_length_m(law, 0.02), 0.9e-3 * std::pow(2.0, 0.35), 1e-15);  // 1.15 mm
  EXPECT_NEAR(rupture_release_length_m(law, 0.001), 0.9e-3 * std::pow(0.1, 0.35), 1e-15);  // 0.40 mm
  // Clamped to [v_ref / 100, 100 v_ref]: a break at rest or backing off keeps a length.
  EXPECT_NEAR(rupture_release_length_m(law, 0.0), 0.9e-3 * std::pow(0.01, 0.35), 1e-15);
  EXPECT_NEAR(rupture_release_length_m(law, -0.01), 0.9e-3 * std::pow(0.01, 0.35), 1e-15);
  EXPECT_NEAR(rupture_release_length_m(law, 10.0), 0.9e-3 * std::pow(100.0, 0.35), 1e-15);
  // m = 0 or no release: l as given.
  law.rupture_release_rate.exponent = 0.0;
  EXPECT_EQ(rupture_release_length_m(law, 0.02), 0.9e-3);
  law.rupture_release_rate.exponent = 0.35;
  law.rupture_release_m = 0.0;
  EXPECT_EQ(rupture_release_length_m(law, 0.02), 0.0);
}

TEST(ShaftForces, RuptureReleaseIsTheLoadBeyondTheCuttingForceAtTheBreakSpeed) {
  ForceLaw law;
  law.cutting_force_N = 1.0;
  law.rupture_release_m = 0.5e-3;
  EXPECT_NEAR(rupture_release_N(law, 2.5, 0.02), 1.5, 1e-12);
  law.cutting_rate.viscous_fraction = 0.5;
  // C(20 mm/s) = 0.5 + 0.5 x 2 = 1.5 N: R = 2.5 - 1.5.
  EXPECT_NEAR(rupture_release_N(law, 2.5, 0.02), 1.0, 1e-12);
  // Never negative; none without a release length.
  EXPECT_EQ(rupture_release_N(law, 1.0, 0.02), 0.0);
  law.rupture_release_m = 0.0;
  EXPECT_EQ(rupture_release_N(law, 2.5, 0.02), 0.0);
}
