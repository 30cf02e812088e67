// Short soak (the long one is scripts/results_soak.sh, 10^7 ticks): random
// trajectories with every effect on, all three integrators; no NaN, the mesh
// energy bounded by the work done on it, no allocation in the tick.
#include <gtest/gtest.h>

#include "soak_driver.hpp"

namespace puncture::soak {
namespace {

TEST(Soak, RandomTrajectoriesEveryEffectAllIntegrators) {
  SoakOptions options;
  options.ticks = 300000;
  options.seed = 7;
  options.min_episode_ticks = 8000;
  options.max_episode_ticks = 20000;
  const SoakReport r = run_soak(options);
  for (const std::string& f : r.failures) ADD_FAILURE() << f;
  EXPECT_EQ(r.ticks, options.ticks);
  EXPECT_EQ(r.non_finite, 0);
  EXPECT_EQ(r.energy_violations, 0);
  EXPECT_EQ(r.allocations, 0);
  // The random trajectories did what a soak needs: every integrator ran,
  // layers broke (and some episodes went through all of them), the needle
  // reversed and dwelt, the needle came in inclined, and the meshes stored energy.
  for (long long n : r.ticks_per_integrator) EXPECT_GT(n, 10000);
  EXPECT_GT(r.max_angle_deg, 10.0);
  EXPECT_GT(r.punctures, 10);
  EXPECT_GT(r.episodes_all_punctured, 0);
  EXPECT_GT(r.reversals, 20);
  EXPECT_GT(r.dwell_ticks, 1000);
  EXPECT_GT(r.max_energy_J, 0.0);
  EXPECT_GT(r.max_abs_force_N, 0.1);
  EXPECT_LE(r.max_energy_to_work, 1.0 + options.energy_rel_tolerance);
  EXPECT_GE(r.effects.size(), 4u);
}

TEST(Soak, TheEnergyCheckCanFail) {
  // With a negative tolerance the passivity bound E <= W (1 + tol) must be
  // violated as soon as a mesh stores energy: the check is not vacuous.
  SoakOptions options;
  options.ticks = 20000;
  options.seed = 3;
  options.energy_rel_tolerance = -0.9;
  const SoakReport r = run_soak(options);
  EXPECT_GT(r.energy_violations, 0);
}

}  // namespace
}  // namespace puncture::soak
