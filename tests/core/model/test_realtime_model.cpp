// The real-time model assembled from scene files: the default scene (Table 2)
// punctures skin, fat and muscle in this order along the scripted insertion.
#include <gtest/gtest.h>

#include <cmath>

#include "puncture/model/realtime_model.hpp"
#include "puncture/scene_io.hpp"

namespace puncture {
namespace {

Scene default_scene() { return load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json"); }

TEST(RealtimeModel, LayerDiscsStackDownwardFromTheSkin) {
  const Scene s = default_scene();
  double top = 0.0;
  for (std::size_t k = 0; k < s.layers.size(); ++k) {
    const LayerDisc d = layer_disc(s, k);
    EXPECT_DOUBLE_EQ(d.top_z_m, top);
    EXPECT_NEAR(d.top_z_m - d.bottom_z_m, s.layers[k].thickness_m, 1e-15);
    EXPECT_DOUBLE_EQ(d.radius_m, 0.5 * s.sample.diameter_m);
    top = d.bottom_z_m;
  }
  EXPECT_NEAR(-top, s.total_thickness_m(), 1e-15);
}

TEST(RealtimeModel, SurfacesAreFittedAtTheSceneDegree) {
  Scene s = default_scene();
  s.realtime.sh_degree = 12;
  const RealtimeModel m = build_realtime_model(s);
  ASSERT_EQ(m.surfaces.size(), s.layers.size());
  for (std::size_t k = 0; k < s.layers.size(); ++k) {
    EXPECT_EQ(m.fits[k].degree, 12);
    // The top face of each fitted disc is flat to a small fraction of the layer thickness.
    EXPECT_LT(m.fits[k].top_face_max_error_m, 0.01 * s.layers[k].thickness_m);
    // The needle axis hits each top surface at the layer's top depth.
    double t = 0;
    SurfacePoint hit;
    ASSERT_TRUE(m.surfaces[k]->intersect_ray(Eigen::Vector3d(0, 0, 0.01), -Eigen::Vector3d::UnitZ(), t, hit));
    EXPECT_NEAR(hit.position.z(), -s.layer_top_depth_m(k), 0.01 * s.layers[k].thickness_m);
    EXPECT_GT(hit.normal.z(), 0.999);
  }
}

TEST(RealtimeModel, DefaultScenePuncturesSkinFatMuscleInOrder) {
  const Scene s = default_scene();
  RealtimeModel m = build_realtime_model(s);
  int frames = 0;
  const ScriptedRunResult run =
      run_scripted_insertion(m, s, [&](const PunctureSimulator&, const TickResult&, int) { ++frames; });
  ASSERT_EQ(run.events.size(), 3u);
  const char* names[] = {"skin", "fat", "muscle"};
  double previous_depth = 0.0;
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(run.events[k].layer_name, names[k]);
    EXPECT_EQ(run.events[k].layer, static_cast<int>(k));
    // Each layer breaks below its own top surface, deeper than the one above.
    EXPECT_GT(run.events[k].depth_m, s.layer_top_depth_m(k));
    EXPECT_GT(run.events[k].depth_m, previous_depth);
    EXPECT_LT(run.events[k].depth_m, s.insertion.target_depth_m);
    EXPECT_GT(run.events[k].surface_force_N, 0.0);
    EXPECT_TRUE(std::isfinite(run.events[k].total_force_N));
    previous_depth = run.events[k].depth_m;
  }
  // One tick per haptic step over the whole trajectory, frames at the visual rate.
  const double duration = ScriptedTrajectory(s.insertion).duration();
  EXPECT_NEAR(static_cast<double>(run.ticks.size()), duration * s.realtime.haptic_rate_Hz + 1, 1.0);
  EXPECT_NEAR(frames, duration * s.realtime.frame_rate_Hz + 1, 1.0);
  // After withdrawal every layer is still punctured and only damping acted inside.
  for (const LayerTickResult& l : run.ticks.back().layers) EXPECT_EQ(l.state, LayerState::Punctured);
  for (const TickResult& t : run.ticks) ASSERT_TRUE(std::isfinite(t.total_force_N));
}

}  // namespace
}  // namespace puncture

namespace puncture {
namespace {

TEST(RealtimeModel, PunctureEventForceIsTheNeedleForceJustBeforeTheBreak) {
  // The physical force law: each layer below the skin is met at the tip and
  // pressed while the crack above is still cut, so the force at its break
  // holds that cutting force (and the shaft forces above), not its surface
  // force alone. The event's total and cutting force must be the needle's on
  // the tick before the break, within one tick of travel (the rupture release
  // of the layers above, cutting.hpp, falls a little in that tick).
  const Scene s = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default_force_law.json");
  RealtimeModel m = build_realtime_model(s);
  const ScriptedRunResult run = run_scripted_insertion(m, s);
  ASSERT_EQ(run.events.size(), s.layers.size());
  int with_cutting = 0;
  for (const PunctureEvent& e : run.events) {
    std::size_t i = 0;
    while (i < run.ticks.size() && run.ticks[i].time_s < e.time_s) ++i;
    ASSERT_GT(i, 0u);
    const TickResult& before = run.ticks[i - 1];
    EXPECT_NEAR(e.total_force_N, before.total_force_N, 0.02 * before.total_force_N + 0.01) << e.layer_name;
    EXPECT_NEAR(e.cutting_force_N, before.cutting_force_N, 0.02 * before.cutting_force_N + 1e-9) << e.layer_name;
    with_cutting += e.cutting_force_N > 0.0;
  }
  EXPECT_GE(with_cutting, 1) << "no layer broke while the crack above was cut: the test checks nothing new";
}

}  // namespace
}  // namespace puncture
