// The cohesive law of the needle's crack and the needle contact with
// friction, against closed forms and finite differences: the work of
// separation equals G_c on every path, the peak traction is sigma_c, the
// tangents are the derivatives of the tractions, damage is irreversible and
// viscously delayed as the implicit update says; the needle geometry gives
// the right penetration and normal; Coulomb friction sticks below mu_s N,
// slides at mu_d N and reverses with the motion.
#include <gtest/gtest.h>

#include <cmath>

#include <puncture/fem/cohesive_law.hpp>
#include <puncture/fem/needle_contact.hpp>

using namespace puncture::fem;

namespace {

CohesiveLawParameters skin_law() {
  CohesiveLawParameters p;
  p.strength_Pa = 2e6;
  p.toughness_J_per_m2 = 1136.0;
  p.elastic_fraction = 0.01;
  return p;
}

/// Work of the traction and accumulated dissipation along a straight
/// monotonic path delta(s) = s (cos phi, sin phi), s from 0 to s_end.
std::pair<double, double> work_along_path(const CohesiveLawParameters& p, double phi, double s_end, int n) {
  CohesiveHistory h;
  double work = 0.0;
  double prev_s = 0.0;
  CohesiveResponse prev = cohesive_response(p, h, 0.0, 0.0, 0.0);
  for (int k = 1; k <= n; ++k) {
    const double s = s_end * k / n;
    const CohesiveResponse r = cohesive_response(p, h, s * std::cos(phi), s * std::sin(phi), 0.0);
    // trapezoid rule on t . d(delta)
    const double t_prev = prev.traction[0] * std::cos(phi) + prev.traction[1] * std::sin(phi);
    const double t_now = r.traction[0] * std::cos(phi) + r.traction[1] * std::sin(phi);
    work += 0.5 * (t_prev + t_now) * (s - prev_s);
    h = r.history;
    prev = r;
    prev_s = s;
  }
  return {work, h.dissipated_J_per_m2};
}

}  // namespace

TEST(CohesiveLaw, WorkOfSeparationIsTheToughnessInEveryMode) {
  const CohesiveLawParameters p = skin_law();
  for (double phi : {0.0, 0.5, 1.0, 1.5707963}) {  // opening, mixed, sliding
    const auto [work, dissipated] = work_along_path(p, phi, 1.2 * p.failure_separation_m(), 20000);
    EXPECT_NEAR(work, p.toughness_J_per_m2, 2e-3 * p.toughness_J_per_m2) << "phi " << phi;
    EXPECT_NEAR(dissipated, p.toughness_J_per_m2, 2e-3 * p.toughness_J_per_m2) << "phi " << phi;
  }
}

TEST(CohesiveLaw, DissipationIsWorkLessStoredEnergyAtEveryStageAndNeverExceedsTheToughness) {
  // Halfway along the softening branch the dissipated energy is the work done
  // so far less the energy still stored in the damaged spring (0.5 t lambda);
  // a single huge viscous step (damage jumps to 1 at 10 x the failure
  // separation) dissipates exactly G_c, not 0.5 K0 lambda^2.
  CohesiveLawParameters p = skin_law();
  for (double frac : {0.3, 0.6, 0.9}) {
    const double s_end = p.onset_separation_m() + frac * (p.failure_separation_m() - p.onset_separation_m());
    const auto [work, dissipated] = work_along_path(p, 0.0, s_end, 20000);
    const CohesiveResponse r = cohesive_response(p, CohesiveHistory{}, s_end, 0.0, 0.0);
    EXPECT_NEAR(dissipated, work - 0.5 * r.traction[0] * s_end, 1e-3 * p.toughness_J_per_m2) << frac;
  }
  p.viscosity_s = 1e-3;
  const CohesiveResponse big = cohesive_response(p, CohesiveHistory{}, 10 * p.failure_separation_m(), 0.0, 1.0);
  EXPECT_GT(big.history.damage, 0.99);
  EXPECT_LE(big.history.dissipated_J_per_m2, p.toughness_J_per_m2 * (1 + 1e-12));
  EXPECT_NEAR(bilinear_dissipation_J_per_m2(p, 1.0), p.toughness_J_per_m2, 1e-9 * p.toughness_J_per_m2);
  EXPECT_EQ(bilinear_dissipation_J_per_m2(p, 0.0), 0.0);
}

TEST(CohesiveLaw, PeakTractionIsTheStrengthAtOnset) {
  const CohesiveLawParameters p = skin_law();
  const CohesiveResponse r = cohesive_response(p, {}, p.onset_separation_m(), 0.0, 0.0);
  EXPECT_NEAR(r.traction[0], p.strength_Pa, 1e-9 * p.strength_Pa);
  EXPECT_DOUBLE_EQ(r.history.damage, 0.0);
  // Halfway through softening the traction is half the strength... of the line
  // from (delta_0, sigma_c) to (delta_f, 0).
  const double mid = 0.5 * (p.onset_separation_m() + p.failure_separation_m());
  EXPECT_NEAR(cohesive_response(p, {}, 0.0, mid, 0.0).traction[1], 0.5 * p.strength_Pa, 1e-9 * p.strength_Pa);
  EXPECT_DOUBLE_EQ(cohesive_response(p, {}, 1.01 * p.failure_separation_m(), 0.0, 0.0).traction[0], 0.0);
}

TEST(CohesiveLaw, TangentIsTheDerivativeOfTheTraction) {
  CohesiveLawParameters p = skin_law();
  CohesiveHistory unloaded;  // damaged earlier to 40 % of delta_f: unloading/reloading branch
  unloaded.max_separation_m = 0.4 * p.failure_separation_m();
  unloaded.damage = bilinear_damage(p, unloaded.max_separation_m);
  for (double eta : {0.0, 1e-3}) {
    p.viscosity_s = eta;
    for (const CohesiveHistory& h : {CohesiveHistory{}, unloaded})
      for (const auto& d : {std::array<double, 2>{0.3e-3, 0.2e-3}, std::array<double, 2>{-0.05e-3, 0.5e-3},
                            std::array<double, 2>{0.1e-3, -0.05e-3}}) {
        const CohesiveResponse r = cohesive_response(p, h, d[0], d[1], 2e-3);
        const double step = 1e-10;
        for (int j = 0; j < 2; ++j) {
          std::array<double, 2> dp = d, dm = d;
          dp[j] += step;
          dm[j] -= step;
          const CohesiveResponse rp = cohesive_response(p, h, dp[0], dp[1], 2e-3);
          const CohesiveResponse rm = cohesive_response(p, h, dm[0], dm[1], 2e-3);
          for (int i = 0; i < 2; ++i)
            EXPECT_NEAR(r.tangent[i][j], (rp.traction[i] - rm.traction[i]) / (2 * step),
                        1e-5 * p.initial_stiffness_Pa_per_m())
                << "i " << i << " j " << j << " eta " << eta << " delta " << d[0] << "," << d[1];
        }
      }
  }
}

TEST(CohesiveLaw, DamageIsIrreversibleAndClosingIsResisted) {
  const CohesiveLawParameters p = skin_law();
  const double d1 = 0.5 * p.failure_separation_m();
  const CohesiveResponse loaded = cohesive_response(p, {}, d1, 0.0, 0.0);
  ASSERT_GT(loaded.history.damage, 0.0);
  // Unloading to half the opening: secant stiffness, same damage.
  const CohesiveResponse unloaded = cohesive_response(p, loaded.history, 0.5 * d1, 0.0, 0.0);
  EXPECT_DOUBLE_EQ(unloaded.history.damage, loaded.history.damage);
  EXPECT_NEAR(unloaded.traction[0], 0.5 * loaded.traction[0], 1e-9 * p.strength_Pa);
  // Closing beyond contact: the undamaged penalty, whatever the damage.
  const CohesiveResponse closed = cohesive_response(p, loaded.history, -1e-6, 0.0, 0.0);
  EXPECT_NEAR(closed.traction[0], -p.initial_stiffness_Pa_per_m() * 1e-6, 1e-9 * p.strength_Pa);
}

TEST(CohesiveLaw, ViscousDamageFollowsTheImplicitUpdate) {
  // dD/dt = (D_inf - D) / eta over dt, implicit: D = (D_old + q D_inf) / (1 + q), q = dt / eta.
  CohesiveLawParameters p = skin_law();
  p.viscosity_s = 4e-3;
  const double lambda = 0.6 * p.failure_separation_m();
  const double D_inf = bilinear_damage(p, lambda);
  CohesiveHistory h;
  double expected = 0.0;
  for (int k = 0; k < 5; ++k) {
    const CohesiveResponse r = cohesive_response(p, h, 0.0, lambda, 1e-3);
    expected = (expected + 0.25 * D_inf) / 1.25;
    EXPECT_NEAR(r.history.damage, expected, 1e-12);
    h = r.history;
  }
  EXPECT_LT(h.damage, D_inf);
}

namespace {

RigidNeedle bevel_needle() {
  RigidNeedle n;
  n.edge_radius_m = 0.404e-3;
  n.shaft_radius_m = 0.635e-3;
  n.flank_angle_rad = 20.0 * 3.14159265358979 / 180.0;
  n.z_tip_m = -1e-3;
  return n;
}

}  // namespace

TEST(NeedleContact, PenetrationAndNormalOfFlankAndShaft) {
  const RigidNeedle n = bevel_needle();
  const double b = n.flank_angle_rad;
  // Outside the body: above the flank line's outside, or beyond the shaft.
  EXPECT_EQ(outer_contact(n, {0.7e-3, 0.0}).penetration_m, 0.0);
  EXPECT_EQ(outer_contact(n, {0.5e-3, n.z_tip_m - 1e-6}).penetration_m, 0.0);
  // On the flank: a point a distance d inside the flank line.
  const Vec2 on_flank{n.edge_radius_m + 0.1e-3 * std::sin(b), n.z_tip_m + 0.1e-3 * std::cos(b)};
  const double d = 20e-6;
  const Vec2 inside{on_flank[0] - d * std::cos(b), on_flank[1] + d * std::sin(b)};
  const ContactPoint c = outer_contact(n, inside);
  EXPECT_NEAR(c.penetration_m, d, 1e-12);
  EXPECT_NEAR(c.normal[0], std::cos(b), 1e-12);
  EXPECT_NEAR(c.normal[1], -std::sin(b), 1e-12);
  EXPECT_FALSE(c.frictional) << "the flank is the cutting bevel: no friction";
  // Along the shaft, above the shoulder: penetration a - r, normal +r.
  const ContactPoint s = outer_contact(n, {0.6e-3, n.shoulder_z() + 1e-3});
  EXPECT_NEAR(s.penetration_m, 0.035e-3, 1e-12);
  EXPECT_NEAR(s.normal[0], 1.0, 1e-12);
  EXPECT_TRUE(s.frictional);
  // Core side: only the inner wall, fully on 20 um above the edge, off below it.
  const ContactPenalty pen{1e4, 0.0};
  EXPECT_NEAR(core_wall_contact(n, {0.41e-3, n.z_tip_m + 1e-4}, pen, 20e-6).normal_force[0], -1e4 * 0.006e-3, 1e-12);
  EXPECT_FALSE(core_wall_contact(n, {0.41e-3, n.z_tip_m - 1e-4}, pen, 20e-6).history.in_contact);
  EXPECT_FALSE(core_wall_contact(n, {0.3e-3, n.z_tip_m + 1e-4}, pen, 20e-6).history.in_contact);
}

TEST(NeedleContact, CoulombFrictionSticksSlidesAndReverses) {
  const RigidNeedle n = bevel_needle();
  const FrictionCoefficients mu{0.2, 0.3};
  const double k_n = 1e4, k_t = 5e3;
  const ContactPenalty pen{k_n, 0.0};
  const Vec2 edge{n.edge_radius_m, n.z_tip_m};
  // A node pressed 10 um into the shaft: N = 0.1 N.
  const double z = n.shoulder_z() + 1e-3;
  const Vec2 x0{n.shaft_radius_m - 10e-6, z};
  const ContactPoint c = outer_contact(n, x0);
  // First touch: no friction; it sticks where it is.
  const NodalContactResponse first = nodal_contact(c, x0, edge, FrictionHistory{}, mu, pen, k_t);
  EXPECT_NEAR(first.normal_force[0], 0.1, 1e-12);
  EXPECT_EQ(first.friction_force[1], 0.0);
  ASSERT_TRUE(first.history.in_contact);
  // Closed form of the regularised law: f = -mu N tanh(k_t xi / (mu N)) on the tissue.
  const auto coulomb = [&](double mu_N, double xi) { return -mu_N * std::tanh(k_t * xi / mu_N); };
  // The needle moves down 1 um relative to the node: stick, f = k_t xi to 1 %.
  const Vec2 edge_down{edge[0], edge[1] - 1e-6};
  const NodalContactResponse stick = nodal_contact(c, x0, edge_down, first.history, mu, pen, k_t);
  EXPECT_NEAR(stick.friction_force[1], coulomb(0.03, 1e-6), 1e-14);
  EXPECT_NEAR(stick.friction_force[1], -k_t * 1e-6, 1e-2 * k_t * 1e-6);  // on the tissue: dragged down
  EXPECT_FALSE(stick.history.sliding);
  EXPECT_EQ(stick.history.anchor[1], first.history.anchor[1]);
  // 30 um: far beyond mu_s N / k_t = 6 um: slides at mu_s N = 0.03 N in this
  // step (to 1e-3), drags the tissue down, and keeps 2 mu_s N / k_t of elastic slip.
  const Vec2 edge_far{edge[0], edge[1] - 30e-6};
  const NodalContactResponse slide = nodal_contact(c, x0, edge_far, first.history, mu, pen, k_t);
  EXPECT_NEAR(slide.friction_force[1], -0.3 * 0.1, 1e-3 * 0.03);
  EXPECT_TRUE(slide.history.sliding);
  EXPECT_NEAR(std::abs(x0[1] - edge_far[1] - slide.history.anchor[1]), kCommittedSlipRatio * 0.03 / k_t, 1e-15);
  // The next step it keeps sliding, at mu_d N = 0.02 N.
  const Vec2 edge_further{edge[0], edge_far[1] - 30e-6};
  const NodalContactResponse sliding = nodal_contact(c, x0, edge_further, slide.history, mu, pen, k_t);
  EXPECT_NEAR(sliding.friction_force[1], -0.2 * 0.1, 1e-4 * 0.02);
  // Reversal: the needle goes back up 40 um: the force changes sign, through
  // zero when the elastic slip does (continuously: no jump for Newton).
  const Vec2 edge_up{edge[0], edge_far[1] + 40e-6};
  const NodalContactResponse back = nodal_contact(c, x0, edge_up, slide.history, mu, pen, k_t);
  EXPECT_NEAR(back.friction_force[1], +0.2 * 0.1, 1e-4 * 0.02);
  const double xi_zero = kCommittedSlipRatio * 0.03 / k_t;  // back by the kept elastic slip
  const Vec2 edge_zero{edge[0], edge_far[1] + xi_zero};
  EXPECT_NEAR(nodal_contact(c, x0, edge_zero, slide.history, mu, pen, k_t).friction_force[1], 0.0, 1e-12);
  // Out of contact: no force, history reset.
  const NodalContactResponse off = nodal_contact(outer_contact(n, {0.7e-3, z}), {0.7e-3, z}, edge, slide.history, mu, pen, k_t);
  EXPECT_FALSE(off.history.in_contact);
  EXPECT_EQ(off.normal_force[0] + off.friction_force[1], 0.0);
}

TEST(NeedleContact, ForceDerivativeMatchesFiniteDifferences) {
  const RigidNeedle n = bevel_needle();
  const FrictionCoefficients mu{0.2, 0.3};
  const double k_n = 1e4, k_t = 5e3, b = n.flank_angle_rad;
  const ContactPenalty pen{k_n, 15e-6};  // the flank node (10 um) is in the rounded part, the shaft node too
  const Vec2 edge{n.edge_radius_m, n.z_tip_m};
  FrictionHistory sticking;
  sticking.in_contact = true;
  // Nodes on the flank and on the shaft; anchors making them stick or slide.
  const Vec2 flank_node{n.edge_radius_m + 0.1e-3 * std::sin(b) - 10e-6 * std::cos(b),
                        n.z_tip_m + 0.1e-3 * std::cos(b) + 10e-6 * std::sin(b)};
  const Vec2 shaft_node{n.shaft_radius_m - 10e-6, n.shoulder_z() + 1e-3};
  // min_slip 0: the slip length is mu N / k_t (about 3 um here); 20 um: the floor holds.
  for (double min_slip : {0.0, 20e-6})
    for (const Vec2& x : {flank_node, shaft_node})
      for (double slip : {1e-6, 30e-6}) {  // stick, slide
        FrictionHistory h = sticking;
        const ContactPoint c0 = outer_contact(n, x);
        h.anchor = {x[0] - edge[0] - slip * c0.tangent[0], x[1] - edge[1] - slip * c0.tangent[1]};
        const NodalContactResponse r = nodal_contact(c0, x, edge, h, mu, pen, k_t, min_slip);
        const double step = 1e-10;
        for (int j = 0; j < 2; ++j) {
          Vec2 xp = x, xm = x;
          xp[j] += step;
          xm[j] -= step;
          const auto rp = nodal_contact(outer_contact(n, xp), xp, edge, h, mu, pen, k_t, min_slip);
          const auto rm = nodal_contact(outer_contact(n, xm), xm, edge, h, mu, pen, k_t, min_slip);
          for (int i = 0; i < 2; ++i) {
            const double fd =
                ((rp.normal_force[i] + rp.friction_force[i]) - (rm.normal_force[i] + rm.friction_force[i])) / (2 * step);
            EXPECT_NEAR(r.dforce_dx[i][j], fd, 1e-4 * k_n)
                << "i " << i << " j " << j << " slip " << slip << " min_slip " << min_slip;
          }
        }
      }
}

TEST(NeedleContact, FrictionBuildsUpOverAtLeastTheMinimumSlipWhateverThePressure) {
  // Lightly pressed (N = 1e-4 N): mu N / k_t is 6 nm; with a floor of 1 um the
  // friction is -mu N tanh(xi / 1 um) and a node slips over the floor's length.
  const RigidNeedle n = bevel_needle();
  const FrictionCoefficients mu{0.2, 0.3};
  const double k_n = 1e4, k_t = 5e3;
  const ContactPenalty pen{k_n, 0.0};
  const Vec2 x{n.shaft_radius_m - 1e-8, n.shoulder_z() + 1e-3};  // 10 nm into the shaft: N = 1e-4 N
  const Vec2 edge{n.edge_radius_m, n.z_tip_m};
  const ContactPoint c = outer_contact(n, x);
  FrictionHistory h;
  h.in_contact = true;
  const double N = pen.force(c.penetration_m);
  ASSERT_NEAR(N, 1e-4, 1e-9);
  for (double xi : {0.2e-6, 1e-6, 3e-6}) {
    h.anchor = {x[0] - edge[0] - xi * c.tangent[0], x[1] - edge[1] - xi * c.tangent[1]};
    const Vec2 f = nodal_contact(c, x, edge, h, mu, pen, k_t, 1e-6).friction_force;
    EXPECT_NEAR(f[0] * c.tangent[0] + f[1] * c.tangent[1], -mu.static_ * N * std::tanh(xi / 1e-6), 1e-12) << xi;
    // Without the floor the same slips are full sliding already.
    const Vec2 g = nodal_contact(c, x, edge, h, mu, pen, k_t, 0.0).friction_force;
    EXPECT_NEAR(g[0] * c.tangent[0] + g[1] * c.tangent[1], -mu.static_ * N, 1e-9 * N) << xi;
  }
}

TEST(NeedleContact, FrictionFadesSmoothlyRoundTheShoulderAndItsDerivativeMatchesFiniteDifferences) {
  const RigidNeedle n = bevel_needle();
  const FrictionCoefficients mu{0.2, 0.3};
  const double k_n = 1e4, k_t = 5e3, b = n.flank_angle_rad, rho = 20e-6;
  const ContactPenalty pen{k_n, 2e-6};
  const Vec2 edge{n.edge_radius_m, n.z_tip_m};
  // Centre of the rounded corner: the shoulder of the body shrunk by rho.
  const double rc = n.shaft_radius_m - rho;
  const double zc = n.z_tip_m + (rc - n.edge_radius_m + rho * std::cos(b)) / std::sin(b) * std::cos(b) + rho * std::sin(b);
  // The weight goes 0 (flank normal) -> 1 (shaft normal) monotonically and continuously.
  double last = -1.0;
  for (int k = 0; k <= 20; ++k) {
    const double phi = -b + b * k / 20.0;  // normal angle from the flank's (-b) to the shaft's (0)
    const Vec2 x{rc + (rho - 5e-6) * std::cos(phi), zc + (rho - 5e-6) * std::sin(phi)};
    const ContactPoint c = outer_contact(n, x, rho);
    ASSERT_GT(c.penetration_m, 0.0);
    EXPECT_NEAR(c.normal[0], std::cos(phi), 1e-9);
    EXPECT_GE(c.friction_weight, last - 1e-12);
    if (k > 0) EXPECT_LT(c.friction_weight - last, 0.2) << "no jump";
    last = c.friction_weight;
  }
  EXPECT_NEAR(outer_contact(n, {rc + 15e-6 * std::cos(-b), zc + 15e-6 * std::sin(-b)}, rho).friction_weight, 0.0, 1e-9);
  EXPECT_NEAR(outer_contact(n, {rc + 15e-6, zc}, rho).friction_weight, 1.0, 1e-9);
  // Force derivative on the corner, sticking and sliding, against central differences.
  FrictionHistory h;
  h.in_contact = true;
  const Vec2 x{rc + 15e-6 * std::cos(-0.4 * b), zc + 15e-6 * std::sin(-0.4 * b)};
  const ContactPoint c0 = outer_contact(n, x, rho);
  ASSERT_GT(c0.friction_weight, 0.05);
  ASSERT_LT(c0.friction_weight, 0.95);
  for (double slip : {1e-6, 30e-6}) {
    h.anchor = {x[0] - edge[0] - slip * c0.tangent[0], x[1] - edge[1] - slip * c0.tangent[1]};
    const NodalContactResponse r = nodal_contact(c0, x, edge, h, mu, pen, k_t);
    const double step = 1e-11;
    for (int j = 0; j < 2; ++j) {
      Vec2 xp = x, xm = x;
      xp[j] += step;
      xm[j] -= step;
      const auto rp = nodal_contact(outer_contact(n, xp, rho), xp, edge, h, mu, pen, k_t);
      const auto rm = nodal_contact(outer_contact(n, xm, rho), xm, edge, h, mu, pen, k_t);
      // The whole force (normal and friction), with the normal and the tangent
      // turning round the corner, is linearised consistently.
      for (int i = 0; i < 2; ++i) {
        const double fd = ((rp.normal_force[i] + rp.friction_force[i]) - (rm.normal_force[i] + rm.friction_force[i])) /
                          (2 * step);
        EXPECT_NEAR(r.dforce_dx[i][j], fd, 1e-5 * std::abs(fd) + 1e-6 * k_n) << "i " << i << " j " << j << " slip " << slip;
      }
    }
  }
}

TEST(NeedleContact, PenaltyLawIsC1AndItsEnergyIntegratesTheForce) {
  const ContactPenalty pen{2e4, 5e-6};
  EXPECT_EQ(pen.force(0.0), 0.0);
  EXPECT_EQ(pen.stiffness(0.0), 0.0);
  const double e = pen.rounding_m;
  EXPECT_NEAR(pen.force(e * (1 - 1e-9)), pen.force(e * (1 + 1e-9)), 1e-9);
  EXPECT_NEAR(pen.stiffness(e * (1 - 1e-9)), pen.stiffness(e * (1 + 1e-9)), 1e-3);
  for (double p : {2e-6, 5e-6, 9e-6}) {
    const double h = 1e-10;
    EXPECT_NEAR(pen.force(p), (pen.energy(p + h) - pen.energy(p - h)) / (2 * h), 1e-6 * pen.force(p));
    EXPECT_NEAR(pen.stiffness(p), (pen.force(p + h) - pen.force(p - h)) / (2 * h), 1e-5 * pen.k_N_per_m);
  }
}

TEST(NeedleContact, InnerWallForceDerivativeMatchesFiniteDifferences) {
  const RigidNeedle n = bevel_needle();
  const ContactPenalty pen{1e4, 2e-6};
  const double h_edge = 20e-6;
  for (const Vec2& x : {Vec2{n.edge_radius_m + 5e-6, n.z_tip_m + 8e-6}, Vec2{n.edge_radius_m + 1e-6, n.z_tip_m + 15e-6},
                        Vec2{n.edge_radius_m + 5e-6, n.z_tip_m + 40e-6}}) {
    const NodalContactResponse r = core_wall_contact(n, x, pen, h_edge);
    ASSERT_TRUE(r.history.in_contact);
    const double step = 1e-11;
    for (int j = 0; j < 2; ++j) {
      Vec2 xp = x, xm = x;
      xp[j] += step;
      xm[j] -= step;
      const auto rp = core_wall_contact(n, xp, pen, h_edge), rm = core_wall_contact(n, xm, pen, h_edge);
      for (int i = 0; i < 2; ++i)
        EXPECT_NEAR(r.dforce_dx[i][j], (rp.normal_force[i] - rm.normal_force[i]) / (2 * step), 1e-4 * pen.k_N_per_m)
            << "i " << i << " j " << j;
    }
  }
}

TEST(NeedleContact, RoundedShoulderGivesAContinuousNormal) {
  // Nodes 5 um inside the body (less than the 20 um rounding), swept from the
  // flank across the shoulder onto the shaft: the normal turns continuously
  // from the flank's to the shaft's, and the penetration stays 5 um.
  const RigidNeedle n = bevel_needle();
  const double rho = 20e-6, depth = 5e-6;
  Vec2 previous{0.0, 0.0};
  for (int k = 0; k <= 400; ++k) {
    // Walk along the boundary of the rounded body: flank, arc, shaft.
    const double s = -60e-6 + k * (160e-6 / 400);
    const double beta = n.flank_angle_rad;
    const double r_corner = n.shaft_radius_m - rho;
    const double z_corner =
        n.z_tip_m + (r_corner - n.edge_radius_m + rho * std::cos(beta)) / std::sin(beta) * std::cos(beta) + rho * std::sin(beta);
    Vec2 boundary, normal;
    if (s < 0.0) {  // on the flank, s before the arc
      normal = {std::cos(beta), -std::sin(beta)};
      const Vec2 tangent_point{r_corner + rho * normal[0], z_corner + rho * normal[1]};
      boundary = {tangent_point[0] + s * std::sin(beta), tangent_point[1] + s * std::cos(beta)};
    } else if (s < rho * beta) {  // on the arc (normal turns from -beta to 0)
      const double angle = -beta + s / rho;
      normal = {std::cos(angle), std::sin(angle)};
      boundary = {r_corner + rho * normal[0], z_corner + rho * normal[1]};
    } else {  // on the shaft
      normal = {1.0, 0.0};
      boundary = {n.shaft_radius_m, z_corner + (s - rho * beta)};
    }
    const Vec2 x{boundary[0] - depth * normal[0], boundary[1] - depth * normal[1]};
    const ContactPoint c = outer_contact(n, x, rho);
    ASSERT_NEAR(c.penetration_m, depth, 1e-9) << "s " << s;
    EXPECT_NEAR(c.normal[0], normal[0], 1e-6) << "s " << s;
    EXPECT_NEAR(c.normal[1], normal[1], 1e-6) << "s " << s;
    if (k > 0) EXPECT_LT(std::hypot(c.normal[0] - previous[0], c.normal[1] - previous[1]), 0.02) << "s " << s;
    previous = c.normal;
  }
}
