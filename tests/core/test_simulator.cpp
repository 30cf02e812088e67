// PunctureSimulator: effects, contact rules and the hard cases (finite
// forces, bounded energy, graceful errors).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "puncture/simulator.hpp"
#include "table2_scene.hpp"

using namespace puncture;

namespace {

NeedleState at_depth(double depth_m, double v, double t) {
  NeedleState s;
  s.tip_position_m = Eigen::Vector3d(0, 0, -depth_m);
  s.axial_velocity_m_per_s = v;
  s.time_s = t;
  return s;
}

// Drives a scripted insertion and checks finite forces and bounded mesh
// energy on every tick. The bound: stored energy cannot exceed twice the
// largest static energy 1/2 k_eff z0^2 of the pressed layer seen so far.
struct RunSummary {
  double max_force_N = 0.0;
  double min_force_N = 0.0;
  double max_energy_ratio = 0.0;
};

RunSummary run_checked(PunctureSimulator& sim, const ScriptedTrajectory& tr, double dt) {
  RunSummary out;
  double static_energy_max = 0.0;
  for (int i = 0; i * dt <= tr.duration(); ++i) {
    const TickResult& r = sim.tick(tr.sample(i * dt));
    EXPECT_TRUE(std::isfinite(r.total_force_N));
    for (std::size_t k = 0; k < sim.layer_count(); ++k) {
      if (const ForceMesh* mesh = sim.force_mesh(k); mesh && r.layers[k].state == LayerState::Pressed) {
        const double z0 = r.layers[k].contact_deflection_m;
        static_energy_max = std::max(static_energy_max, 0.5 * mesh->static_stiffness_N_per_m() * z0 * z0);
      }
    }
    if (static_energy_max > 0.0)
      out.max_energy_ratio = std::max(out.max_energy_ratio, sim.mesh_energy_J() / static_energy_max);
    out.max_force_N = std::max(out.max_force_N, r.total_force_N);
    out.min_force_N = std::min(out.min_force_N, r.total_force_N);
  }
  return out;
}

}  // namespace

class DefaultInsertion : public ::testing::TestWithParam<const char*> {};

TEST_P(DefaultInsertion, ThreePuncturesInOrderWithFinitePositiveForces) {
  Scene scene = test::table2_scene(GetParam());
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  const ScriptedTrajectory tr(scene.insertion);
  const RunSummary run = run_checked(sim, tr, 1e-3);
  EXPECT_LT(run.max_energy_ratio, 2.0);
  const auto& ev = sim.puncture_events();
  ASSERT_EQ(ev.size(), 3u);
  const char* names[] = {"skin", "fat", "muscle"};
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(ev[k].layer, k);
    EXPECT_EQ(ev[k].layer_name, names[k]);
    EXPECT_TRUE(std::isfinite(ev[k].surface_force_N));
    // Plausible for an 18 G needle: 0.5-3 N at breakthrough.
    EXPECT_GT(ev[k].surface_force_N, 0.5);
    EXPECT_LT(ev[k].surface_force_N, 3.0);
    EXPECT_GE(ev[k].total_force_N, ev[k].surface_force_N);
    if (k > 0) {
      EXPECT_GT(ev[k].depth_m, ev[k - 1].depth_m);
      EXPECT_GT(ev[k].time_s, ev[k - 1].time_s);
    }
    // Each surface breaks before ~15 mm of indentation of its own.
    EXPECT_LT(ev[k].depth_m - scene.layer_top_depth_m(k), 15e-3);
  }
  EXPECT_GT(ev[0].depth_m, 1e-3);  // skin tents a few mm
  EXPECT_LT(ev[0].depth_m, 5e-3);
  // Thin skin pressed deeper than its thickness: the fat's rest surface does
  // not move without layer interaction, so the skin left between the tip and
  // it is squeezed to nothing and the fat is pressed from the tip at the
  // break, in the same tick (not after a cut through the skin's thickness).
  EXPECT_GT(ev[0].depth_m, scene.layers[0].thickness_m);
  EXPECT_NEAR(-sim.contact_point(1).position.z(), ev[0].depth_m, 1e-12);
  // The muscle was reached from above: its contact is on its surface.
  EXPECT_NEAR(sim.contact_point(2).position.z(), -scene.layer_top_depth_m(2), 1e-12);
  // Resumption brought the broken surfaces to their goals by the end.
  for (std::size_t k = 0; k < 3; ++k) {
    ASSERT_NE(sim.resumption(k), nullptr);
    EXPECT_EQ(sim.resumption(k)->recovery_factor(), 0.0);
    EXPECT_LT((sim.node_positions(k) - sim.resumption(k)->goals()).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_EQ(sim.node_rings(k).size(), static_cast<std::size_t>(sim.node_positions(k).cols()));
  }
  EXPECT_GT(run.max_force_N, 0.5);
  EXPECT_LT(run.min_force_N, 0.0);  // withdrawal through punctured layers
}

INSTANTIATE_TEST_SUITE_P(Integrators, DefaultInsertion, ::testing::Values("quasi_static", "explicit", "implicit"));

TEST(Simulator, EffectsThatAreOffAreNotBuilt) {
  Scene scene = test::table2_scene();
  scene.effects.surface_force = false;
  {
    PunctureSimulator sim(scene, test::plane_surfaces(scene));
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(sim.force_mesh(k), nullptr);
      EXPECT_EQ(sim.resumption(k), nullptr);
      EXPECT_EQ(sim.node_positions(k).cols(), 0);
    }
    // Without surface force a layer breaks when the tip passes its surface;
    // the force is then pure damping, Table 1 post-puncture.
    sim.tick(at_depth(-1e-4, 0.01, 0.0));
    const TickResult& r = sim.tick(at_depth(5e-3, 0.01, 0.001));
    EXPECT_EQ(r.layers[0].state, LayerState::Punctured);
    // The fat was reached with the tip already 4.2 mm below its top: its
    // contact starts at the tip, so it is not punctured yet.
    EXPECT_EQ(sim.puncture_events().size(), 1u);
    ASSERT_TRUE(sim.has_contact(1));
    EXPECT_NEAR(-sim.contact_point(1).position.z(), 5e-3, 1e-12);
    EXPECT_EQ(r.layers[1].state, LayerState::Untouched);
    EXPECT_NEAR(r.total_force_N, 3000.0 * 0.8e-3 * 0.01, 1e-12);
    const TickResult& r2 = sim.tick(at_depth(5.1e-3, 0.01, 0.002));
    EXPECT_EQ(sim.puncture_events().size(), 2u);
    EXPECT_EQ(r2.layers[1].state, LayerState::Punctured);
    EXPECT_NEAR(r2.total_force_N, (3000.0 * 0.8e-3 + 1000.0 * 4.3e-3) * 0.01, 1e-12);
  }
  scene = test::table2_scene();
  scene.effects.resumption = false;
  scene.effects.damping = false;
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  const ScriptedTrajectory tr(scene.insertion);
  for (int i = 0; i * 1e-3 <= tr.duration(); ++i) {
    const TickResult& r = sim.tick(tr.sample(i * 1e-3));
    for (const auto& l : r.layers) EXPECT_EQ(l.damping_force_N, 0.0);
  }
  EXPECT_EQ(sim.puncture_events().size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(sim.resumption(k), nullptr);
    EXPECT_NE(sim.force_mesh(k), nullptr);
  }
}

TEST(Simulator, NeedleReversalMidLayer) {
  Scene scene = test::table2_scene("implicit");
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  // Insert to 4 mm (skin broken at ~2.4 mm, fat pressed), back to 0.5 mm, in again to 4 mm.
  const double dt = 1e-3, v = 0.01;
  double depth = -0.5e-3, t = 0.0;
  auto step = [&](double vel) {
    depth += vel * dt;
    t += dt;
    const TickResult& r = sim.tick(at_depth(depth, vel, t));
    EXPECT_TRUE(std::isfinite(r.total_force_N));
    return r;
  };
  while (depth < 4e-3) step(v);
  ASSERT_EQ(sim.layer_state(0), LayerState::Punctured);
  ASSERT_EQ(sim.layer_state(1), LayerState::Pressed);
  const double fat_force_in = sim.last_result().layers[1].surface_force_N;
  EXPECT_GT(fat_force_in, 0.0);
  double fat_force_min = fat_force_in;
  while (depth > 0.5e-3) {
    const TickResult& r = step(-v);
    fat_force_min = std::min(fat_force_min, r.layers[1].surface_force_N);
    EXPECT_GE(r.layers[1].surface_force_N, 0.0);  // the blunt tip never pulls the surface
    EXPECT_LE(r.layers[0].damping_force_N, 0.0);  // withdrawal reverses the damping
  }
  // Above the fat contact: no surface force, the skin stays punctured, F = d_s h v.
  EXPECT_EQ(sim.layer_state(0), LayerState::Punctured);
  EXPECT_NEAR(sim.last_result().total_force_N, 3000.0 * depth * (-v), 1e-9);
  EXPECT_LT(fat_force_min, 1e-3 * fat_force_in);
  while (depth < 4e-3) step(v);
  // Back at the same depth, the fat mesh gives (about) the same force again.
  EXPECT_NEAR(sim.last_result().layers[1].surface_force_N, fat_force_in, 0.05 * fat_force_in);
  EXPECT_EQ(sim.puncture_events().size(), 1u);
}

TEST(Simulator, StaticNeedleConvergesToEquilibrium) {
  for (const char* integrator : {"explicit", "implicit"}) {
    Scene scene = test::table2_scene(integrator);
    PunctureSimulator sim(scene, test::plane_surfaces(scene));
    sim.tick(at_depth(-0.1e-3, 0.0, 0.0));  // contact on the skin surface
    for (int i = 1; i <= 3000; ++i) sim.tick(at_depth(1e-3, 0.0, i * 1e-3));  // speed 0, pressed 1 mm
    const TickResult& r = sim.last_result();
    EXPECT_EQ(r.layers[0].state, LayerState::Pressed);
    const double k_eff = sim.force_mesh(0)->static_stiffness_N_per_m();
    EXPECT_NEAR(r.total_force_N, k_eff * 1e-3, 1e-6 * k_eff * 1e-3) << integrator;
  }
}

TEST(Simulator, FastInsertionAtOneMetrePerSecond) {
  for (const char* integrator : {"quasi_static", "explicit", "implicit"}) {
    Scene scene = test::table2_scene(integrator);
    scene.insertion.speed_m_per_s = 1.0;
    scene.insertion.withdrawal_speed_m_per_s = 1.0;
    scene.insertion.dwell_s = 0.2;
    PunctureSimulator sim(scene, test::plane_surfaces(scene));
    const RunSummary run = run_checked(sim, ScriptedTrajectory(scene.insertion), 1e-3);
    EXPECT_LT(run.max_energy_ratio, 2.0) << integrator;
    ASSERT_EQ(sim.puncture_events().size(), 3u) << integrator;
    // Damping at 1 m/s through all three layers: (d_s h_s + d_f h_f + d_m h) v.
    EXPECT_GT(run.max_force_N, (3000.0 * 0.8e-3 + 1000.0 * 8.4e-3) * 1.0);
  }
}

TEST(Simulator, VeryStiffSpringsWithALargeStep) {
  for (const char* integrator : {"quasi_static", "explicit", "implicit"}) {
    Scene scene = test::table2_scene(integrator);
    scene.realtime.haptic_rate_Hz = 100.0;  // 10 ms step
    for (auto& l : scene.layers) {
      l.force_mesh.virtual_stiffness_N_per_m *= 1e4;
      l.force_mesh.surface_stiffness_N_per_m *= 1e4;
    }
    PunctureSimulator sim(scene, test::plane_surfaces(scene));
    const ForceMesh& skin = *sim.force_mesh(0);
    if (std::string(integrator) == "explicit") EXPECT_TRUE(skin.explicit_falls_back_to_implicit());
    const RunSummary run = run_checked(sim, ScriptedTrajectory(scene.insertion), 1e-2);
    EXPECT_LT(run.max_energy_ratio, 2.0) << integrator;
    EXPECT_EQ(sim.puncture_events().size(), 3u) << integrator;
  }
}

TEST(Simulator, OneRingAndThirtyTwoRings) {
  for (int w : {1, 32}) {
    Scene scene = test::table2_scene("implicit");
    for (auto& l : scene.layers) {
      l.force_mesh.rings_w = w;
      if (w == 32) {
        // A 4x finer lattice of about the same physical extent: k_s scaled by
        // 16 keeps the decay length L sqrt(k_s / K) of the deflection.
        l.force_mesh.spacing_L_m = 0.5e-3;
        l.force_mesh.surface_stiffness_N_per_m *= 16.0;
      }
    }
    scene.insertion.target_depth_m = 0.015;
    scene.insertion.dwell_s = 0.0;
    scene.insertion.speed_m_per_s = 0.05;
    scene.insertion.withdrawal_speed_m_per_s = 0.05;
    PunctureSimulator sim(scene, test::plane_surfaces(scene));
    EXPECT_EQ(sim.force_mesh(0)->node_count(), 1 + 3 * w * (w - 1));
    const RunSummary run = run_checked(sim, ScriptedTrajectory(scene.insertion), 1e-3);
    EXPECT_LT(run.max_energy_ratio, 2.0) << "w=" << w;
    EXPECT_GE(sim.puncture_events().size(), 1u) << "w=" << w;
    for (std::size_t k = 0; k < sim.puncture_events().size(); ++k) {
      // w = 1 is a single node: degenerate shape matching (A = 0) still gives finite positions.
      EXPECT_TRUE(sim.node_positions(k).allFinite());
    }
  }
}

TEST(Simulator, RejectsInconsistentInput) {
  Scene scene = test::table2_scene();
  auto surfaces = test::plane_surfaces(scene);
  surfaces.pop_back();
  EXPECT_THROW(PunctureSimulator(scene, std::move(surfaces)), std::invalid_argument);
  scene.realtime.integrator = "rk45";
  EXPECT_THROW(PunctureSimulator(scene, test::plane_surfaces(scene)), std::invalid_argument);
  scene = test::table2_scene();
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  NeedleState bad = at_depth(1e-3, 0.01, 0.0);
  bad.tip_position_m.z() = std::nan("");
  EXPECT_THROW(sim.tick(bad), std::invalid_argument);
  Scene empty;
  EXPECT_THROW(PunctureSimulator(empty, {}), std::invalid_argument);
}

TEST(Simulator, PunctureEventSplitsTheSurfaceForceByTerm) {
  // Quasi-static skin that breaks at a critical force. With stiffening in the
  // mesh, Eq. 5 on the mesh's deflections is the whole surface force (the
  // reaction at equilibrium); with a linear mesh and a stiffening tip spring,
  // the tip spring's share is g(z0) at the break, a2 z0^2 + a3 z0^3.
  for (const bool in_mesh : {true, false}) {
    Scene scene = test::table2_scene("quasi_static");
    Layer& skin = scene.layers[0];
    skin.force_law.breakthrough.kind = BreakthroughCriterion::Kind::CriticalForce;
    skin.force_law.breakthrough.critical_force_N = 0.5;
    if (in_mesh) {
      skin.force_mesh.surface_axial_stiffness_N_per_m = 400.0;
      skin.force_mesh.virtual_stiffening_m = 3e-3;
    } else {
      scene.effects.stiffening = true;
      skin.force_law.stiffening.quadratic_N_per_m2 = 2e3;
      skin.force_law.stiffening.cubic_N_per_m3 = 5e6;
    }
    PunctureSimulator sim(scene, test::plane_surfaces(scene));
    const ScriptedTrajectory tr(scene.insertion);
    for (int i = 0; i * 1e-3 <= tr.duration() && sim.puncture_events().empty(); ++i) sim.tick(tr.sample(i * 1e-3));
    ASSERT_FALSE(sim.puncture_events().empty()) << in_mesh;
    const PunctureEvent& e = sim.puncture_events().front();
    EXPECT_GE(e.surface_force_N, 0.5);
    if (in_mesh) {
      // The committed state is the step linearised at the last tick's deflection
      // (10 um of travel here): off equilibrium by O(dz^2).
      EXPECT_NEAR(e.eq5_force_N, e.mesh_reaction_N, 1e-4 * e.mesh_reaction_N);
      EXPECT_NEAR(e.eq5_force_N, e.surface_force_N, 1e-3 * e.surface_force_N);  // linearised step: O(dz^2)
      EXPECT_EQ(e.tip_stiffening_force_N, 0.0);
    } else {
      const double z0 = e.depth_m;
      EXPECT_NEAR(e.tip_stiffening_force_N, 2e3 * z0 * z0 + 5e6 * z0 * z0 * z0, 1e-12);
      EXPECT_NEAR(e.mesh_reaction_N + e.tip_stiffening_force_N, e.surface_force_N, 1e-9 * e.surface_force_N);
      EXPECT_LT(e.eq5_force_N, e.surface_force_N);
    }
  }
}
