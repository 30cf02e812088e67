// The needle at an angle to the surface normal (needle.hpp, simulator.hpp):
// the inclined scripted path, the tip's load resolved along the contact
// normal and across the needle, the shaft inside each layer along the
// inclined axis, and the hard cases (grazing angle, reversal and withdrawal
// along the inclined path, an entry near the edge of a force mesh laid
// elsewhere).
//
// The independent values: the path's geometry in closed form, and the axial
// run at the normal speed v cos a. Along a flat surface the tip at angle a
// moving at v presses the surface exactly as the axial needle at v cos a does
// (the force mesh sees only the penetration along the normal), so until the
// first puncture the mesh's load must agree tick by tick; the needle feels it
// as F cos a along its axis and F sin a across it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "puncture/simulator.hpp"
#include "table2_scene.hpp"

using namespace puncture;

namespace {

constexpr double kDeg = M_PI / 180.0;

Scene table2_at(double angle_deg, double speed_m_per_s) {
  Scene s = test::table2_scene();
  s.insertion.angle_deg = angle_deg;
  s.insertion.speed_m_per_s = speed_m_per_s;
  s.insertion.withdrawal_speed_m_per_s = speed_m_per_s;
  s.insertion.target_depth_m = 0.02;
  s.insertion.dwell_s = 0.1;
  return s;
}

/// The force's components: along -d it is the axial force, across d the lateral one.
void expect_vector_consistent(const TickResult& r, const Eigen::Vector3d& d) {
  const Eigen::Vector3d& f = r.force_on_needle_N;
  const double scale = 1e-12 * (1.0 + std::abs(r.total_force_N));
  EXPECT_NEAR(-f.dot(d), r.total_force_N, scale);
  EXPECT_NEAR((f - f.dot(d) * d).norm(), r.lateral_force_N, scale);
  const Eigen::Vector3d arm = r.path_depth_m * d;
  EXPECT_NEAR((r.torque_about_entry_N_m - arm.cross(f)).norm(), 0.0, scale * (1.0 + std::abs(r.path_depth_m)));
}

/// A scripted trajectory of `in` is refused with an error naming `key` (whose bad value is `value`).
void expect_refused(const Insertion& in, const std::string& key, double value) {
  try {
    ScriptedTrajectory tr(in);
    ADD_FAILURE() << key << " = " << value << " was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(ObliqueTrajectory, FollowsTheInclinedLineThroughTheOrigin) {
  Insertion in;
  in.start_height_m = 2e-3;
  in.speed_m_per_s = 0.01;
  in.target_depth_m = 0.02;
  in.dwell_s = 0.5;
  in.withdrawal_speed_m_per_s = 0.02;
  in.angle_deg = 30.0;
  const ScriptedTrajectory tr(in);
  const double c = std::cos(30.0 * kDeg), s = std::sin(30.0 * kDeg);
  const Eigen::Vector3d d(s, 0.0, -c);
  EXPECT_NEAR((tr.direction() - d).norm(), 0.0, 1e-15);
  // Start height and target depth are vertical; the path is 1 / cos a as long.
  const double path = 0.022 / c;
  EXPECT_NEAR(tr.insertion_end_s(), path / 0.01, 1e-12);
  EXPECT_NEAR(tr.duration(), path / 0.01 + 0.5 + path / 0.02, 1e-12);

  const NeedleState start = tr.sample(0.0);
  EXPECT_NEAR(start.tip_position_m.z(), 2e-3, 1e-15);
  EXPECT_NEAR(start.tip_position_m.x(), -2e-3 * s / c, 1e-15);
  const NeedleState entry = tr.sample(2e-3 / c / 0.01);  // at the origin
  EXPECT_NEAR(entry.tip_position_m.norm(), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(entry.axial_velocity_m_per_s, 0.01);
  EXPECT_NEAR((entry.direction - d).norm(), 0.0, 1e-15);
  const NeedleState mid = tr.sample(1.0);  // 10 mm past the start along the needle
  EXPECT_NEAR((mid.tip_position_m - (0.01 - 2e-3 / c) * d).norm(), 0.0, 1e-15);
  EXPECT_NEAR(mid.axial_position_m(), 0.01 - 2e-3 / c, 1e-15);
  const NeedleState target = tr.sample(tr.insertion_end_s() + 0.25);
  EXPECT_NEAR(target.depth_m(), 0.02, 1e-15);
  EXPECT_NEAR(target.tip_position_m.x(), 0.02 * s / c, 1e-15);
  EXPECT_EQ(target.axial_velocity_m_per_s, 0.0);
  // Withdrawing along the same line.
  const NeedleState back = tr.sample(tr.withdrawal_start_s() + 0.25);
  EXPECT_NEAR(back.axial_position_m(), 0.02 / c - 0.005, 1e-15);
  EXPECT_NEAR(back.tip_position_m.y(), 0.0, 0.0);
  EXPECT_NEAR(back.tip_position_m.x() * c + back.tip_position_m.z() * s, 0.0, 1e-15);  // on the line
  EXPECT_DOUBLE_EQ(back.axial_velocity_m_per_s, -0.02);
  EXPECT_NEAR(tr.sample(1e3).tip_position_m.z(), 2e-3, 1e-15);
}

TEST(ObliqueTrajectory, AnglesBeyondTheLimitAreRefusedNamingTheKey) {
  Insertion in;
  in.angle_deg = kMaxInsertionAngleDeg;
  EXPECT_NO_THROW(ScriptedTrajectory{in});
  for (double bad : {kMaxInsertionAngleDeg + 1.0, -1.0, std::nan("")}) {
    in.angle_deg = bad;
    expect_refused(in, "insertion.angle_deg", bad);
  }
}

TEST(ObliqueTrajectory, TheAzimuthTurnsTheLineAboutTheSampleAxis) {
  Insertion in;
  in.start_height_m = 2e-3;
  in.target_depth_m = 0.02;
  in.angle_deg = 40.0;
  const double s = std::sin(40.0 * kDeg), c = std::cos(40.0 * kDeg);
  for (double azimuth : {0.0, 90.0, 135.0, 300.0}) {
    in.azimuth_deg = azimuth;
    const ScriptedTrajectory tr(in);
    const double b = azimuth * kDeg;
    const Eigen::Vector3d d(s * std::cos(b), s * std::sin(b), -c);
    EXPECT_NEAR((tr.direction() - d).norm(), 0.0, 1e-15) << azimuth;
    const NeedleState target = tr.sample(tr.insertion_end_s());
    EXPECT_NEAR(target.depth_m(), 0.02, 1e-15) << azimuth;
    // 20 mm tan a off the axis, towards the azimuth.
    EXPECT_NEAR(std::hypot(target.tip_position_m.x(), target.tip_position_m.y()), 0.02 * s / c, 1e-15) << azimuth;
    EXPECT_NEAR(target.tip_position_m.x() * std::sin(b) - target.tip_position_m.y() * std::cos(b), 0.0, 1e-15)
        << azimuth;
  }
  // At 0 deg the azimuth names no direction: the needle runs along the sample axis.
  in.angle_deg = 0.0;
  in.azimuth_deg = 123.0;
  EXPECT_EQ(ScriptedTrajectory(in).direction(), Eigen::Vector3d(0.0, 0.0, -1.0));
  for (double bad : {360.0, -1.0, std::nan("")}) {
    in.azimuth_deg = bad;
    expect_refused(in, "insertion.azimuth_deg", bad);
  }
}

// The flat slab is rotationally symmetric about its axis, so the insertion at
// azimuth b is the one at azimuth 0 turned by b: the force vector and the
// moment turn with it, the scalar outputs stay. The force meshes' hexagonal
// lattice keeps its orientation in the scene frame, but the tip loads its
// centre node along the normal, so on planes the lattice's orientation does
// not enter: the runs agree to rounding at every azimuth (on the fitted SH
// surfaces, tests/core/model/test_oblique_tuned.cpp).
class ObliqueAzimuth : public ::testing::TestWithParam<double> {};

TEST_P(ObliqueAzimuth, TurnsTheForceVectorWithTheNeedle) {
  const double azimuth = GetParam();
  const Scene base = table2_at(30.0, 0.01);
  Scene turned = base;
  turned.insertion.azimuth_deg = azimuth;
  PunctureSimulator sim_0(base, test::plane_surfaces(base));
  PunctureSimulator sim_b(turned, test::plane_surfaces(turned));
  const ScriptedTrajectory tr_0(base.insertion), tr_b(turned.insertion);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(azimuth * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  double peak = 0.0, worst_relative = 0.0;
  int compared = 0;
  for (int i = 0; i * 1e-3 <= tr_0.duration(); ++i) {
    const NeedleState n0 = tr_0.sample(i * 1e-3), nb = tr_b.sample(i * 1e-3);
    const TickResult& r0 = sim_0.tick(n0);
    const TickResult& rb = sim_b.tick(nb);
    expect_vector_consistent(rb, nb.direction);
    ASSERT_EQ(sim_0.puncture_events().size(), sim_b.puncture_events().size()) << "t = " << i * 1e-3;
    peak = std::max(peak, std::abs(r0.total_force_N));
    const double scale = 1e-3 + std::abs(r0.total_force_N);
    worst_relative = std::max(worst_relative, std::abs(rb.total_force_N - r0.total_force_N) / scale);
    worst_relative = std::max(worst_relative, (rb.force_on_needle_N - turn * r0.force_on_needle_N).norm() / scale);
    worst_relative = std::max(worst_relative, (rb.torque_about_entry_N_m - turn * r0.torque_about_entry_N_m).norm() /
                                                  (scale * (1e-3 + std::abs(r0.path_depth_m))));
    ++compared;
  }
  EXPECT_GT(peak, 0.5);
  EXPECT_GT(compared, 1000);
  ASSERT_EQ(sim_b.puncture_events().size(), sim_0.puncture_events().size());
  for (std::size_t k = 0; k < sim_0.puncture_events().size(); ++k) {
    const PunctureEvent& e0 = sim_0.puncture_events()[k];
    const PunctureEvent& eb = sim_b.puncture_events()[k];
    EXPECT_EQ(eb.layer, e0.layer);
    EXPECT_NEAR(eb.depth_m, e0.depth_m, 1e-12) << e0.layer_name;
    EXPECT_NEAR(eb.surface_force_N, e0.surface_force_N, 1e-12 * e0.surface_force_N) << e0.layer_name;
  }
  EXPECT_LT(worst_relative, 1e-12) << "azimuth " << azimuth;
}

INSTANTIATE_TEST_SUITE_P(Azimuths, ObliqueAzimuth, ::testing::Values(45.0, 90.0, 180.0, 301.0));

class ObliquePress : public ::testing::TestWithParam<double> {};

// Until the skin breaks, the needle at a and speed v loads the skin's mesh as
// the axial needle at v cos a does; the needle feels F cos a along its axis
// and F sin a across it, and the skin breaks at the same depth under the same load.
TEST_P(ObliquePress, LoadsTheSurfaceAlongItsNormalAndFeelsItResolved) {
  const double angle = GetParam(), v = 0.01;
  const double c = std::cos(angle * kDeg), s = std::sin(angle * kDeg);
  const Scene oblique = table2_at(angle, v);
  const Scene axial = table2_at(0.0, v * c);
  PunctureSimulator sim_a(oblique, test::plane_surfaces(oblique));
  PunctureSimulator sim_0(axial, test::plane_surfaces(axial));
  const ScriptedTrajectory tr_a(oblique.insertion), tr_0(axial.insertion);
  ASSERT_NEAR(tr_a.insertion_end_s(), tr_0.insertion_end_s(), 1e-12);
  const double dt = 1e-3;
  double peak_surface = 0.0;
  int compared = 0;
  for (int i = 0; i * dt < tr_a.insertion_end_s(); ++i) {
    const NeedleState na = tr_a.sample(i * dt), n0 = tr_0.sample(i * dt);
    const TickResult& ra = sim_a.tick(na);
    const TickResult& r0 = sim_0.tick(n0);
    expect_vector_consistent(ra, na.direction);
    if (!sim_a.puncture_events().empty() || !sim_0.puncture_events().empty()) break;  // both break in this tick
    ASSERT_NEAR(ra.depth_m, r0.depth_m, 1e-12);
    ASSERT_NEAR(ra.surface_force_N, r0.surface_force_N, 1e-9 * (1.0 + r0.surface_force_N)) << "t = " << i * dt;
    EXPECT_NEAR(ra.total_force_N, r0.surface_force_N * c, 1e-9 * (1.0 + r0.surface_force_N));
    EXPECT_NEAR(ra.lateral_force_N, r0.surface_force_N * s, 1e-9 * (1.0 + r0.surface_force_N));
    EXPECT_NEAR(ra.path_depth_m, ra.depth_m / c, 1e-15);
    // The moment about the entry point: path depth x lateral force, about the y axis (the needle tilts in x-z).
    EXPECT_NEAR(std::abs(ra.torque_about_entry_N_m.y()), std::max(0.0, ra.path_depth_m) * ra.lateral_force_N,
                1e-12);
    peak_surface = std::max(peak_surface, r0.surface_force_N);
    ++compared;
  }
  EXPECT_GT(compared, 100);
  EXPECT_GT(peak_surface, 0.5);  // the skin was pressed to its break
  ASSERT_EQ(sim_a.puncture_events().size(), 1u);
  ASSERT_EQ(sim_0.puncture_events().size(), 1u);
  const PunctureEvent& ea = sim_a.puncture_events()[0];
  const PunctureEvent& e0 = sim_0.puncture_events()[0];
  EXPECT_EQ(ea.layer_name, "skin");
  EXPECT_NEAR(ea.time_s, e0.time_s, 1e-12);
  EXPECT_NEAR(ea.depth_m, e0.depth_m, 1e-12);
  EXPECT_NEAR(ea.surface_force_N, e0.surface_force_N, 1e-9 * e0.surface_force_N);
  EXPECT_NEAR(ea.total_force_N - ea.cutting_force_N, e0.surface_force_N * c, 1e-9 * e0.surface_force_N);
}

INSTANTIATE_TEST_SUITE_P(Angles, ObliquePress, ::testing::Values(15.0, 30.0, 45.0, 60.0));

// The rupture release (cutting.hpp) lets go of the load the tip carried at a
// break beyond the cutting force, over the release length: the force along the
// needle is continuous through the break. At an angle that load is the axial
// part F cos a of the surface force, not F itself (which would make the force
// along the needle jump by F (1 - cos a) at the break).
TEST_P(ObliquePress, TheForceAlongTheNeedleIsContinuousThroughABreak) {
  const double angle = GetParam();
  Scene scene = table2_at(angle, 0.01);
  scene.effects.cutting = true;
  for (Layer& l : scene.layers) {
    l.force_law.cutting_force_N = 0.1;  // below every break's load: the release carries the rest
    l.force_law.rupture_release_m = 1e-3;
  }
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  const ScriptedTrajectory tr(scene.insertion);
  double before = 0.0;
  for (int i = 0; i * 1e-3 < tr.insertion_end_s(); ++i) {
    const TickResult& r = sim.tick(tr.sample(i * 1e-3));
    if (!sim.puncture_events().empty()) {
      const PunctureEvent& skin = sim.puncture_events()[0];
      ASSERT_GT(skin.surface_force_N, 0.5);
      // The shaft's damping d h v starts with the break (h = 0.8 mm / cos a): it is not the tip's load.
      EXPECT_NEAR(r.total_force_N - r.friction_force_N, before, 0.01 * before) << "the skin's break at " << angle
                                                                                 << " deg";
      return;
    }
    before = r.total_force_N;
  }
  FAIL() << "the skin did not break";
}

// The whole scripted insertion at the largest angle the limits allow: every
// layer punctured in order, met where the inclined path crosses it, the shaft
// inside each punctured layer 1 / cos a as long as its thickness, forces finite
// and the force vector consistent with its parts on every tick, the
// withdrawal along the inclined path with the shaft friction reversed.
TEST(ObliqueInsertion, GrazingAngleRunsTheWholeTrajectory) {
  const double angle = kMaxInsertionAngleDeg, v = 0.01;
  const double c = std::cos(angle * kDeg), t = std::tan(angle * kDeg);
  Scene scene = table2_at(angle, v);
  scene.sample.diameter_m = 0.12;  // the path reaches 20 mm tan 60 = 35 mm off the axis
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  const ScriptedTrajectory tr(scene.insertion);
  const double dt = 1e-3;
  bool checked_skin_shaft = false, saw_reversed_friction = false;
  double max_force = 0.0;
  for (int i = 0; i * dt <= tr.duration(); ++i) {
    const NeedleState n = tr.sample(i * dt);
    const TickResult& r = sim.tick(n);
    ASSERT_TRUE(std::isfinite(r.total_force_N) && r.force_on_needle_N.allFinite()) << "t = " << i * dt;
    expect_vector_consistent(r, n.direction);
    max_force = std::max(max_force, r.total_force_N);
    if (!checked_skin_shaft && r.layers[0].state == LayerState::Punctured && r.depth_m > scene.layers[0].thickness_m) {
      EXPECT_NEAR(r.layers[0].shaft_length_m, scene.layers[0].thickness_m / c, 1e-12);
      checked_skin_shaft = true;
    }
    if (n.axial_velocity_m_per_s < 0.0 && r.depth_m > 1e-3 && r.total_force_N < 0.0) {
      saw_reversed_friction = true;
      EXPECT_EQ(r.lateral_force_N, 0.0);  // no surface is pressed on the way out
    }
  }
  EXPECT_TRUE(checked_skin_shaft);
  EXPECT_TRUE(saw_reversed_friction);
  EXPECT_LT(max_force, 50.0);
  const auto& ev = sim.puncture_events();
  ASSERT_GE(ev.size(), 2u);  // at least skin and fat (the muscle's top lies at 9.2 mm)
  for (std::size_t k = 0; k < ev.size(); ++k) EXPECT_EQ(ev[k].layer, static_cast<int>(k));
  for (std::size_t k = 0; k < sim.layer_count(); ++k) {
    // Each layer's mesh was laid where the inclined path crosses its top; the
    // contact lies on the path (at the crossing, or at the tip for a layer met
    // below its rest surface as the layer above broke).
    const double top = scene.layer_top_depth_m(k);
    EXPECT_NEAR(sim.force_mesh(k)->rest_positions().col(0).x(), top * t, 1e-9) << sim.layer_name(k);
    const Eigen::Vector3d& p = sim.contact_point(k).position;
    EXPECT_NEAR(p.x(), -p.z() * t, 1e-9) << sim.layer_name(k);
    EXPECT_GE(-p.z(), top - 1e-12) << sim.layer_name(k);
  }
}

// A needle inserted at an angle to mid-fat and pulled back along its path:
// the tip leaves the fat's mesh and the skin, every force stays finite, the
// fat's contact is released and the next touch lays its mesh anew.
TEST(ObliqueInsertion, ReversalMidLayerAtAnAngle) {
  const double angle = 30.0;
  Scene scene = table2_at(angle, 0.01);
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  const Eigen::Vector3d d = insertion_direction(scene.insertion);
  const double c = -d.z();
  auto needle_at = [&](double path_m, double v, double time) {
    NeedleState n;
    n.tip_position_m = path_m * d;
    n.direction = d;
    n.axial_velocity_m_per_s = v;
    n.time_s = time;
    return n;
  };
  const double dt = 1e-3;
  double time = 0.0, path = -1e-3;
  // In until the fat has been pressed for 1 mm along the needle (100 ticks), then back out.
  int pressed_ticks = 0;
  for (; pressed_ticks < 100 && path < 0.02 / c; path += 1e-5, time += dt) {
    sim.tick(needle_at(path, 0.01, time));
    if (sim.layer_state(1) == LayerState::Pressed) ++pressed_ticks;
  }
  ASSERT_EQ(sim.layer_state(0), LayerState::Punctured);
  ASSERT_EQ(sim.layer_state(1), LayerState::Pressed);
  for (; path > -1e-3; path -= 1e-5, time += dt) {
    const NeedleState n = needle_at(path, -0.01, time);
    const TickResult& r = sim.tick(n);
    ASSERT_TRUE(std::isfinite(r.total_force_N) && r.force_on_needle_N.allFinite());
    expect_vector_consistent(r, d);
  }
  EXPECT_EQ(sim.layer_state(1), LayerState::Untouched);  // the tip is back above the fat's surface
  for (int i = 0; i < 2000; ++i, time += dt) sim.tick(needle_at(-1e-3, 0.0, time));
  EXPECT_LT(sim.force_mesh(1)->deflections_m().cwiseAbs().maxCoeff(), 1e-6);  // relaxed
}

// A mesh laid where one insertion met the skin; a second needle, at an angle,
// meets the skin near that mesh's edge. The mesh (at rest) is laid anew
// around the new contact point, and the load is that of a fresh contact.
TEST(ObliqueInsertion, EntryNearTheEdgeOfAMeshLaidElsewhere) {
  Scene scene = table2_at(0.0, 0.01);
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  const double dt = 1e-3;
  double time = 0.0;
  auto tick = [&](const Eigen::Vector3d& tip, const Eigen::Vector3d& d, double v) {
    NeedleState n;
    n.tip_position_m = tip;
    n.direction = d;
    n.axial_velocity_m_per_s = v;
    n.time_s = time;
    time += dt;
    return sim.tick(n);
  };
  const Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();
  // Press the skin 0.2 mm on the axis, lift off and let it relax.
  for (int i = 0; i <= 20; ++i) tick(Eigen::Vector3d(0, 0, -1e-5 * i), down, 0.01);
  for (int i = 20; i >= -20; --i) tick(Eigen::Vector3d(0, 0, -1e-5 * i), down, -0.01);
  for (int i = 0; i < 3000; ++i) tick(Eigen::Vector3d(0, 0, 1e-3), down, 0.0);
  ASSERT_FALSE(sim.has_contact(0));
  const ForceMesh& mesh = *sim.force_mesh(0);
  const double radius = (mesh.rings() - 1) * scene.layers[0].force_mesh.spacing_L_m;
  // The second needle at 45 deg enters 0.9 of the mesh's radius off its centre.
  const double angle = 45.0 * kDeg;
  const Eigen::Vector3d d(std::sin(angle), 0.0, -std::cos(angle));
  const Eigen::Vector3d entry(0.9 * radius, 0.0, 0.0);
  double first_force = -1.0;
  for (int i = -20; i <= 20; ++i) {
    const TickResult& r = tick(entry + 1e-5 * i * d, d, 0.01);
    ASSERT_TRUE(r.force_on_needle_N.allFinite());
    if (i == 20) first_force = r.surface_force_N;
  }
  ASSERT_TRUE(sim.has_contact(0));
  EXPECT_NEAR((sim.contact_point(0).position - entry).norm(), 0.0, 1e-9);
  EXPECT_NEAR((mesh.rest_positions().col(0) - entry).norm(), 0.0, 1e-9);
  // The same press (0.2 mm along the needle, 0.141 mm along the normal) on fresh tissue.
  Scene fresh_scene = scene;
  PunctureSimulator fresh(fresh_scene, test::plane_surfaces(fresh_scene));
  double fresh_force = -1.0;
  for (int i = -20; i <= 20; ++i) {
    NeedleState n;
    n.tip_position_m = entry + 1e-5 * i * d;
    n.direction = d;
    n.axial_velocity_m_per_s = 0.01;
    n.time_s = dt * (i + 20);
    fresh_force = fresh.tick(n).surface_force_N;
  }
  EXPECT_GT(fresh_force, 0.0);
  EXPECT_NEAR(first_force, fresh_force, 1e-9 * fresh_force);
}

// A layer that breaks within a few ticks of a contact off the scene's line
// (its force mesh laid anew in the tangent plane, kLayoutNodesPerTick nodes
// projected per tick) does not project the rest of its layout in the break's
// tick: its recovery starts towards the layout projected so far and its goals
// follow the projection until the layout is complete.
TEST(ObliqueInsertion, ABreakBeforeTheLayoutIsCompleteRecoversTowardsTheProjectedLayout) {
  Scene scene = table2_at(0.0, 0.01);  // meshes laid on the sample axis at construction
  scene.effects.resumption = true;
  scene.layers[1].force_law.breakthrough.kind = BreakthroughCriterion::Kind::CriticalForce;
  scene.layers[1].force_law.breakthrough.critical_force_N = 0.02;  // the fat breaks within ticks of its contact
  scene.layers[1].force_mesh.rings_w = 8;                          // 169 nodes: 42 ticks to project them
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  const double angle = 30.0 * kDeg;
  const Eigen::Vector3d d(std::sin(angle), 0.0, -std::cos(angle));
  const int fat_nodes = sim.force_mesh(1)->node_count();
  double time = 0.0, path = -1e-3;
  int break_tick = -1;
  for (int i = 0; i < 20000 && break_tick < 0; ++i, path += 1e-5, time += 1e-3) {
    NeedleState n;
    n.tip_position_m = path * d;
    n.direction = d;
    n.axial_velocity_m_per_s = 0.01;
    n.time_s = time;
    sim.tick(n);
    if (sim.layer_state(1) == LayerState::Punctured) break_tick = i;
  }
  ASSERT_GE(break_tick, 0) << "the fat did not break";
  const ForceMesh& fat = *sim.force_mesh(1);
  const SurfaceResumption& recovery = *sim.resumption(1);
  ASSERT_TRUE(fat.layout_pending()) << "the fat's layout was completed at its break";
  EXPECT_LT(fat.pending_nodes(), fat_nodes);
  EXPECT_TRUE(recovery.active());
  EXPECT_NEAR((recovery.goals() - fat.rest_positions()).cwiseAbs().maxCoeff(), 0.0, 1e-15);
  // Hold the needle; the projection goes on at kLayoutNodesPerTick nodes per tick.
  NeedleState hold;
  hold.tip_position_m = path * d;
  hold.direction = d;
  for (int i = 0; i < fat_nodes / kLayoutNodesPerTick + 10; ++i, time += 1e-3) {
    hold.time_s = time;
    sim.tick(hold);
  }
  EXPECT_FALSE(fat.layout_pending());
  EXPECT_TRUE(recovery.active());  // not reset by the completed layout
  EXPECT_NEAR((recovery.goals() - fat.rest_positions()).cwiseAbs().maxCoeff(), 0.0, 1e-15);
  EXPECT_TRUE(recovery.positions().allFinite());
}
