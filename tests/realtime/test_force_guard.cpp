// The haptic stability guard: the force sent to a device never exceeds the
// scene's magnitude limit, never changes faster than its rate limit, and is
// untouched when both hold; the passivity criterion K T / 2 + B <= b is
// applied as stated, with K probed from the model (checked against the force
// mesh's own static stiffness in a linear, quasi-static scene).
#include <gtest/gtest.h>

#include <random>

#include "puncture/model/realtime_model.hpp"
#include "puncture/realtime/force_guard.hpp"
#include "realtime_test_scenes.hpp"

namespace puncture::realtime {
namespace {

Haptics limits(double max_force_N, double rate_N_per_s) {
  Haptics h;
  h.max_force_N = max_force_N;
  h.max_force_rate_N_per_s = rate_N_per_s;
  return h;
}

TEST(ForceGuard, SmallSlowForcesPassUnchanged) {
  ForceGuard guard(limits(3.0, 1000.0), 1e-3);  // 1 N per tick allowed
  unsigned flags = 0;
  const Eigen::Vector3d f(0.1, -0.2, 0.5);
  EXPECT_EQ(guard.apply(f, flags), f);
  EXPECT_EQ(flags, 0u);
  const Eigen::Vector3d g(0.3, -0.1, 0.9);
  EXPECT_EQ(guard.apply(g, flags), g);
  EXPECT_EQ(flags, 0u);
}

TEST(ForceGuard, MagnitudeIsClampedAlongTheRequestedDirection) {
  ForceGuard guard(limits(2.0, 1e9), 1e-3);  // rate limit out of the way
  unsigned flags = 0;
  const Eigen::Vector3d request(0.0, 3.0, 4.0);  // |F| = 5 N
  const Eigen::Vector3d out = guard.apply(request, flags);
  EXPECT_NEAR(out.norm(), 2.0, 1e-15);
  EXPECT_NEAR(out.normalized().dot(request.normalized()), 1.0, 1e-15);
  EXPECT_TRUE(flags & kMagnitudeClamped);
  EXPECT_FALSE(flags & kRateClamped);
}

TEST(ForceGuard, StepIsRateLimited) {
  ForceGuard guard(limits(10.0, 200.0), 1e-3);  // 0.2 N per 1 ms tick
  unsigned flags = 0;
  // A 1 N step (a puncture force drop in reverse) is spread over 5 ticks.
  Eigen::Vector3d out;
  for (int i = 1; i <= 5; ++i) {
    out = guard.apply(Eigen::Vector3d(0, 0, 1.0), flags);
    EXPECT_NEAR(out.z(), 0.2 * i, 1e-12) << i;
    EXPECT_EQ(i < 5, (flags & kRateClamped) != 0) << i;
  }
  out = guard.apply(Eigen::Vector3d(0, 0, 1.0), flags);
  EXPECT_EQ(out.z(), 1.0);
  EXPECT_EQ(flags, 0u);
  // And the drop back to zero too.
  out = guard.apply(Eigen::Vector3d::Zero(), flags);
  EXPECT_NEAR(out.z(), 0.8, 1e-12);
  EXPECT_TRUE(flags & kRateClamped);
}

TEST(ForceGuard, BothLimitsHoldForArbitraryRequests) {
  const double max_force = 1.5, rate = 300.0, dt = 1e-3;
  ForceGuard guard(limits(max_force, rate), dt);
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 2.0);
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (int i = 0; i < 20000; ++i) {
    unsigned flags = 0;
    const Eigen::Vector3d out = guard.apply(Eigen::Vector3d(n(rng), n(rng), n(rng)), flags);
    ASSERT_LE(out.norm(), max_force * (1 + 1e-12)) << i;
    ASSERT_LE((out - previous).norm(), rate * dt * (1 + 1e-12)) << i;
    previous = out;
  }
}

TEST(ForceGuard, NonFiniteRequestIsTreatedAsZero) {
  ForceGuard guard(limits(3.0, 1e9), 1e-3);
  unsigned flags = 0;
  guard.apply(Eigen::Vector3d(0, 0, 1), flags);
  const Eigen::Vector3d out = guard.apply(Eigen::Vector3d(0, std::nan(""), 1), flags);
  EXPECT_TRUE(out.allFinite());
  EXPECT_EQ(out, Eigen::Vector3d::Zero());
  EXPECT_TRUE(flags & kNonFiniteRequest);
}

TEST(StabilityAssessment, PassivityCriterionAsStated) {
  Haptics h;
  h.device_damping_N_s_per_m = 0.5;
  h.device_max_stiffness_N_per_m = 1000.0;
  h.max_force_N = 3.0;
  RenderedImpedance imp;
  imp.stiffness_N_per_m = 600.0;  // K T / 2 = 0.3 N s/m at 1 kHz
  imp.damping_N_s_per_m = 0.15;   // + B = 0.45 <= 0.5: passive
  imp.peak_force_N = 1.0;
  StabilityAssessment a = assess_stability(h, 1e-3, imp);
  EXPECT_TRUE(a.passive);
  EXPECT_NEAR(a.passivity_demand_N_s_per_m, 0.45, 1e-12);
  EXPECT_NEAR(a.max_passive_stiffness_N_per_m, 2.0 * (0.5 - 0.15) / 1e-3, 1e-9);
  EXPECT_TRUE(a.warnings.empty());
  // Halving the rate doubles K T / 2: 0.6 + 0.15 > 0.5.
  a = assess_stability(h, 2e-3, imp);
  EXPECT_FALSE(a.passive);
  ASSERT_EQ(a.warnings.size(), 1u);
  EXPECT_NE(a.warnings[0].find("not passive"), std::string::npos);
  // Stiffer than the device and a peak above the force limit: two more warnings.
  imp.stiffness_N_per_m = 1500.0;
  imp.peak_force_N = 4.0;
  a = assess_stability(h, 1e-3, imp);
  EXPECT_FALSE(a.within_device_stiffness);
  EXPECT_FALSE(a.within_force_limit);
  EXPECT_EQ(a.warnings.size(), 3u);
}

TEST(StabilityAssessment, ProbedStiffnessIsTheForceMeshStaticStiffness) {
  // Linear force meshes at equilibrium (quasi-static), no damping: while one
  // layer is pressed F = k_static * (depth - contact depth), so the steepest
  // slope is the largest static stiffness of the three meshes.
  Scene scene = testing::default_scene();
  scene.realtime.integrator = "quasi_static";
  scene.effects = Effects{};
  scene.effects.damping = false;
  scene.effects.resumption = false;
  scene.effects.surface_output = false;
  const RenderedImpedance imp = probe_rendered_impedance(scene);
  RealtimeModel model = build_realtime_model(scene);
  double k_max = 0.0;
  std::string stiffest;
  for (std::size_t k = 0; k < model.simulator->layer_count(); ++k) {
    const double ks = model.simulator->force_mesh(k)->static_stiffness_N_per_m();
    if (ks > k_max) k_max = ks, stiffest = scene.layers[k].name;
  }
  EXPECT_NEAR(imp.stiffness_N_per_m, k_max, 1e-4 * k_max);  // contact normal of the SH fit ~ z
  EXPECT_EQ(imp.stiffness_layer, stiffest);
  EXPECT_EQ(imp.damping_N_s_per_m, 0.0);
  EXPECT_GT(imp.peak_force_N, 0.0);
}

TEST(StabilityAssessment, ShaftDampingIsTheSumOfDTimesThickness) {
  const Scene scene = testing::short_insertion_scene();
  const RenderedImpedance imp = probe_rendered_impedance(scene);
  double b = 0.0;
  for (const Layer& l : scene.layers) b += l.damping_N_s_per_m2 * l.thickness_m;
  EXPECT_DOUBLE_EQ(imp.damping_N_s_per_m, b);
  // By hand from scenes/default.json (d, h of skin, fat, muscle): 3000 x 0.8 mm + 1000 x 8.4 mm + 3000 x 39 mm.
  EXPECT_NEAR(imp.damping_N_s_per_m, 127.8, 1e-9);
}

}  // namespace
}  // namespace puncture::realtime
