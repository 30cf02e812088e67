// The shaft's contact pressure relaxing with the layer's Prony series
// (shaft_pressure_relaxation.hpp), against closed forms of
//     h_eff(t) = g_inf h + sum_i g_i integral exp(-(t - t_pass(z)) / tau_i) dz
// for insertion at constant speed, a dwell and a withdrawal, and in the shaft
// force of a punctured layer.
#include <cmath>
#include <gtest/gtest.h>

#include "puncture/shaft_forces.hpp"
#include "puncture/shaft_pressure_relaxation.hpp"

using namespace puncture;

namespace {

constexpr double kG = 0.55, kTau = 6.0;  // the default muscle's Prony term (Bosboom et al. 2001)
constexpr double kV = 0.01;              // insertion speed, m/s
constexpr double kDt = 1e-3;             // haptic tick, s

std::vector<PronyRelaxationTerm> muscle() { return {{kG, kTau}}; }

/// h_eff after inserting at kV from t = 0 to t (closed form).
double inserted(double t) { return (1.0 - kG) * kV * t + kG * kTau * kV * (1.0 - std::exp(-t / kTau)); }

/// Drives p at kV from t0 to t1 with one update per tick (t1 > t0).
double insert(ShaftPressureRelaxation& p, double t0, double t1, double h0 = 0.0, double sign = 1.0) {
  double h_eff = 0.0;
  const int n = static_cast<int>(std::lround((t1 - t0) / kDt));
  for (int i = 1; i <= n; ++i) h_eff = p.update(h0 + sign * kV * i * kDt, t0 + i * kDt);
  return h_eff;
}

}  // namespace

TEST(ShaftPressureRelaxation, WithoutTermsTheContactLengthIsTheShaftLength) {
  ShaftPressureRelaxation p;
  EXPECT_FALSE(p.relaxes());
  EXPECT_EQ(p.update(3e-3, 0.0), 3e-3);
  EXPECT_EQ(p.update(5e-3, 10.0), 5e-3);
  EXPECT_EQ(p.update(1e-3, 20.0), 1e-3);
}

TEST(ShaftPressureRelaxation, InsertionAtConstantSpeedMatchesTheClosedForm) {
  for (double t : {0.5, 2.0, 6.0, 20.0}) {
    ShaftPressureRelaxation q(muscle());
    q.update(0.0, 0.0);
    const double h_eff = insert(q, 0.0, t);
    // The merge window (1 % of tau) shifts pass times by at most 60 ms.
    EXPECT_NEAR(h_eff, inserted(t), 2e-3 * inserted(t)) << "t = " << t;
    EXPECT_LT(h_eff, kV * t);
    EXPECT_GE(h_eff, (1.0 - kG) * kV * t);
  }
}

TEST(ShaftPressureRelaxation, FrictionPerLengthGrowsWithSpeedAndSaturates) {
  // 20 mm of shaft inserted at 1, 10 and 100 mm/s: h_eff / h is the mean
  // relaxation factor over the shaft, 1 - g + g tau v / h (1 - exp(-h / (v tau))).
  const double h = 0.02;
  double last = 0.0;
  for (double v : {0.001, 0.01, 0.1}) {
    ShaftPressureRelaxation p(muscle());
    const double T = h / v;
    const int n = 2000;
    double h_eff = p.update(0.0, 0.0);
    for (int i = 1; i <= n; ++i) h_eff = p.update(h * i / n, T * i / n);
    const double expected = 1.0 - kG + kG * kTau * v / h * (1.0 - std::exp(-h / (v * kTau)));
    EXPECT_NEAR(h_eff / h, expected, 2e-3) << "v = " << v;
    EXPECT_GT(h_eff / h, last);
    last = h_eff / h;
  }
  EXPECT_GT(last, 0.99);  // fast: barely relaxed
}

TEST(ShaftPressureRelaxation, DwellRelaxesTowardsTheLongTermFraction) {
  ShaftPressureRelaxation p(muscle());
  p.update(0.0, 0.0);
  const double t0 = 1.5, h0 = kV * t0;
  insert(p, 0.0, t0);
  for (double hold : {1.0, 10.0, 100.0}) {
    const double h_eff = p.update(h0, t0 + hold);
    const double expected = (1.0 - kG) * h0 + kG * kTau * kV * (1.0 - std::exp(-t0 / kTau)) * std::exp(-hold / kTau);
    EXPECT_NEAR(h_eff, expected, 2e-3 * h0) << "hold " << hold << " s";
  }
  EXPECT_NEAR(p.relaxed_length_m(), (1.0 - kG) * h0, 1e-6 * h0);
}

TEST(ShaftPressureRelaxation, WithdrawalRemovesTheNewestShaftFirst) {
  // Insert for T, withdraw half at once: what remains is the shaft passed in
  // [0, T/2], S = v tau exp(-T / tau) (exp(T / (2 tau)) - 1).
  const double T = 4.0, h = kV * T;
  ShaftPressureRelaxation p(muscle());
  p.update(0.0, 0.0);
  insert(p, 0.0, T);
  const double h_eff = p.update(0.5 * h, T);
  const double S = kV * kTau * std::exp(-T / kTau) * (std::exp(T / (2.0 * kTau)) - 1.0);
  EXPECT_NEAR(h_eff, (1.0 - kG) * 0.5 * h + kG * S, 2e-3 * h);
  // The oldest half has relaxed more than the newest half had.
  EXPECT_LT(h_eff, inserted(T) - h_eff);
  // Fully withdrawn: nothing left; re-inserting starts fresh.
  EXPECT_EQ(p.update(0.0, T + 0.1), 0.0);
  EXPECT_EQ(p.entries(), 0u);
  const double again = insert(p, T + 0.1, T + 1.1);
  EXPECT_NEAR(again, inserted(1.0), 2e-3 * inserted(1.0));
}

TEST(ShaftPressureRelaxation, StackStaysWithinItsAllocationOnALongSlowInsertion) {
  // Skin-like tau 0.25 s (merge window 2.5 ms) inserted at 0.1 mm/s for 60 s:
  // 24,000 windows, so the stack is halved several times; the result stays the closed form.
  const double tau = 0.25, g = 0.5, v = 1e-4, T = 60.0;
  ShaftPressureRelaxation p({{g, tau}});
  double h_eff = p.update(0.0, 0.0);
  const int n = static_cast<int>(T / kDt);
  for (int i = 1; i <= n; ++i) {
    h_eff = p.update(v * i * kDt, i * kDt);
    ASSERT_LE(p.entries(), ShaftPressureRelaxation::kMaxEntries);
  }
  const double expected = (1.0 - g) * v * T + g * tau * v * (1.0 - std::exp(-T / tau));
  EXPECT_NEAR(h_eff, expected, 1e-3 * expected);
  // Withdrawing to half: the remaining shaft passed long ago is fully relaxed.
  EXPECT_NEAR(p.update(0.5 * v * T, T), (1.0 - g) * 0.5 * v * T, 2e-3 * v * T);
}

TEST(ShaftPressureRelaxation, RejectsInvalidTerms) {
  EXPECT_THROW(ShaftPressureRelaxation({{0.0, 1.0}}), std::invalid_argument);
  EXPECT_THROW(ShaftPressureRelaxation({{0.5, 0.0}}), std::invalid_argument);
  EXPECT_THROW(ShaftPressureRelaxation({{0.5, NAN}}), std::invalid_argument);
  EXPECT_THROW(ShaftPressureRelaxation({{0.6, 1.0}, {0.6, 2.0}}), std::invalid_argument);
}

TEST(ShaftPressureRelaxation, LayerFrictionIsPhiTimesTheRelaxedLengthOnlyWhenTheLawSaysSo) {
  ShaftFrictionLaw law;
  law.static_N_per_m = law.dynamic_N_per_m = 60.0;
  Viscoelasticity material;
  material.terms = muscle();
  auto needle = [](double depth_m, double v, double t) {
    NeedleState n;
    n.tip_position_m = Eigen::Vector3d(0.0, 0.0, -depth_m);
    n.axial_velocity_m_per_s = v;
    n.time_s = t;
    return n;
  };
  LayerShaftFriction plain(law, material);  // the law does not ask for relaxation
  law.pressure_relaxes_with_material = true;
  LayerShaftFriction relaxing(law, material);
  // Layer from 0 to 30 mm, inserted at 10 mm/s to 20 mm, then a 10 s dwell.
  LayerShaftForce a, b;
  for (int i = 0; i <= 2000; ++i) {
    a = punctured_layer_shaft_force(0.0, 0.03, &plain, false, 0.0, needle(kV * i * kDt, kV, i * kDt));
    b = punctured_layer_shaft_force(0.0, 0.03, &relaxing, false, 0.0, needle(kV * i * kDt, kV, i * kDt));
  }
  EXPECT_NEAR(a.friction_N, 60.0 * 0.02, 1e-12);
  EXPECT_NEAR(b.friction_N, 60.0 * inserted(2.0), 2e-3 * b.friction_N);
  a = punctured_layer_shaft_force(0.0, 0.03, &plain, false, 0.0, needle(0.02, 0.0, 12.0));
  b = punctured_layer_shaft_force(0.0, 0.03, &relaxing, false, 0.0, needle(0.02, 0.0, 12.0));
  EXPECT_NEAR(a.friction_N, 60.0 * 0.02, 1e-12);  // stuck: phi kept
  const double relaxed = (1.0 - kG) * 0.02 + kG * kTau * kV * (1.0 - std::exp(-2.0 / kTau)) * std::exp(-10.0 / kTau);
  EXPECT_NEAR(b.friction_N, 60.0 * relaxed, 2e-3 * b.friction_N);
}
