// The committed tuned preset (stiffening meshes, rupture releases, rate laws)
// with the needle at an angle, on its fitted SH surfaces: the same breaks as
// the axial needle at the normal speed v cos a (depth and normal load; the
// independent value of tests/core/test_oblique_insertion.cpp on the model a
// user runs), no allocation in the tick.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "../allocation_counter.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/needle.hpp"
#include "puncture/scene_io.hpp"

using namespace puncture;

namespace {

/// The tuned preset on a 100 mm sample to 25 mm (every angle up to 60 deg fits), at `angle_deg`
/// and `speed_scale` times its speeds.
Scene tuned_at(double angle_deg, double speed_scale) {
  Scene s = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/results/tuned_preset/default_tuned.json");
  s.sample.diameter_m = 0.1;
  s.insertion.target_depth_m = 0.025;
  s.insertion.angle_deg = angle_deg;
  s.insertion.speed_m_per_s *= speed_scale;
  s.insertion.withdrawal_speed_m_per_s *= speed_scale;
  return s;
}

struct InclinedRun {
  std::vector<PunctureEvent> events;
  std::vector<double> axial_N;
  std::size_t allocations = 0;
};

InclinedRun run(const Scene& scene) {
  RealtimeModel model = build_realtime_model(scene);
  const ScriptedTrajectory tr(scene.insertion);
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  std::vector<NeedleState> states;
  for (int i = 0; i * dt <= tr.insertion_end_s(); ++i) states.push_back(tr.sample(i * dt));
  InclinedRun out;
  out.axial_N.reserve(states.size());
  test::start_counting_allocations();
  for (const NeedleState& s : states) out.axial_N.push_back(model.simulator->tick(s).total_force_N);
  out.allocations = test::stop_counting_allocations();
  out.events = model.simulator->puncture_events();
  return out;
}

}  // namespace

class ObliqueTuned : public ::testing::TestWithParam<double> {};

TEST_P(ObliqueTuned, BreaksAsTheAxialNeedleAtTheNormalSpeedAndAllocatesNothing) {
  const double angle = GetParam(), c = std::cos(angle * M_PI / 180.0);
  const InclinedRun inclined = run(tuned_at(angle, 1.0));
  const InclinedRun axial = run(tuned_at(0.0, c));
  EXPECT_EQ(inclined.allocations, 0u);
  ASSERT_EQ(inclined.events.size(), 3u);
  ASSERT_EQ(axial.events.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    const PunctureEvent &a = inclined.events[k], &z = axial.events[k];
    EXPECT_EQ(a.layer, z.layer);
    // The deeper layers are met off the axis, where the SH fit's top face is flat to about 10 um.
    EXPECT_NEAR(a.depth_m, z.depth_m, 0.02e-3) << a.layer;
    EXPECT_NEAR(a.surface_force_N, z.surface_force_N, 0.01 * z.surface_force_N + 1e-3) << a.layer;
  }
}

INSTANTIATE_TEST_SUITE_P(Angles, ObliqueTuned, ::testing::Values(30.0, 60.0));

// The needle at 45 deg turned about the sample axis (insertion.azimuth_deg):
// the slab is rotationally symmetric, so the force vector turns with the
// needle and the breaks stay. The fitted SH surfaces of the flat layers are
// rotationally symmetric too (their departure from flat, about 10 um off the
// axis, depends on the radius only), and the tip loads each force mesh's
// centre node along the normal, so the lattice's orientation does not enter:
// the runs agree to rounding.
TEST(ObliqueTuned, TheAzimuthTurnsTheForceVectorOnTheFittedSurfaces) {
  auto run_vectors = [](const Scene& scene, std::vector<Eigen::Vector3d>& forces) {
    RealtimeModel model = build_realtime_model(scene);
    const ScriptedTrajectory tr(scene.insertion);
    const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
    for (int i = 0; i * dt <= tr.duration(); ++i) forces.push_back(model.simulator->tick(tr.sample(i * dt)).force_on_needle_N);
    return model.simulator->puncture_events();
  };
  const Scene base = tuned_at(45.0, 1.0);
  std::vector<Eigen::Vector3d> f0;
  const std::vector<PunctureEvent> e0 = run_vectors(base, f0);
  ASSERT_EQ(e0.size(), 3u);
  for (double azimuth : {90.0, 200.0}) {
    Scene turned = base;
    turned.insertion.azimuth_deg = azimuth;
    std::vector<Eigen::Vector3d> fb;
    const std::vector<PunctureEvent> eb = run_vectors(turned, fb);
    ASSERT_EQ(eb.size(), 3u) << azimuth;
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(eb[k].layer, e0[k].layer);
      EXPECT_NEAR(eb[k].depth_m, e0[k].depth_m, 1e-12) << azimuth << " deg, layer " << e0[k].layer;
      EXPECT_NEAR(eb[k].surface_force_N, e0[k].surface_force_N, 1e-9 * e0[k].surface_force_N)
          << azimuth << " deg, layer " << e0[k].layer;
    }
    // The force vector turned back by the azimuth: its RMS difference from the run at 0 deg.
    const Eigen::Matrix3d back = Eigen::AngleAxisd(-azimuth * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    ASSERT_EQ(fb.size(), f0.size());
    double diff2 = 0.0, norm2 = 0.0;
    for (std::size_t i = 0; i < f0.size(); ++i) {
      diff2 += (back * fb[i] - f0[i]).squaredNorm();
      norm2 += f0[i].squaredNorm();
    }
    EXPECT_LT(std::sqrt(diff2 / norm2), 1e-12) << azimuth << " deg";
  }
}
