// Table 1 of the seed paper, row by row, against its closed form with the
// Table 2 thicknesses and damping coefficients.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "puncture/puncture_force.hpp"
#include "puncture/simulator.hpp"
#include "table2_scene.hpp"

using namespace puncture;

TEST(PunctureForce, ShaftLengthInLayer) {
  // Layer from 0.8 mm to 9.2 mm depth.
  EXPECT_EQ(shaft_length_in_layer_m(0.5e-3, 0.8e-3, 8.4e-3), 0.0);
  EXPECT_NEAR(shaft_length_in_layer_m(3.0e-3, 0.8e-3, 8.4e-3), 2.2e-3, 1e-15);
  EXPECT_NEAR(shaft_length_in_layer_m(20e-3, 0.8e-3, 8.4e-3), 8.4e-3, 1e-15);
  EXPECT_EQ(puncture_damping_force_N(3000.0, 1e-3, -0.01), -0.03);
}

TEST(PunctureForce, Table1RowByRow) {
  Scene scene = test::table2_scene("quasi_static");
  // A skin that breaks at ~0.5 mm, shallower than its 0.8 mm thickness, so that
  // the skin post-puncture row (tip inside the skin, fat not yet reached) occurs.
  scene.layers[0].force_mesh.deformed_threshold_m = 2e-6;
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  // Table 2 values in SI, written out independently of the scene.
  const double hs = 0.8e-3, hf = 8.4e-3;
  const double ds = 3000.0, df = 1000.0, dm = 3000.0;

  // Insert at 10 mm/s from 1 mm above the skin to 20 mm (2100 ticks), then
  // withdraw at 10 mm/s to 15 mm: every row of Table 1 is visited.
  std::array<int, 6> visited{};  // skin pre/post, fat pre/post, muscle pre/post
  const double dt = 1e-3, v_in = 0.01;
  double depth = -1e-3;
  for (int i = 0; i < 2600; ++i) {
    const double v = i < 2100 ? v_in : -v_in;
    depth += v * dt;
    NeedleState needle;
    needle.tip_position_m = Eigen::Vector3d(0, 0, -depth);
    needle.axial_velocity_m_per_s = v;
    needle.time_s = i * dt;
    const TickResult& r = sim.tick(needle);
    const LayerState skin = r.layers[0].state, fat = r.layers[1].state, muscle = r.layers[2].state;
    double expected = 0.0;
    if (skin != LayerState::Punctured) {
      expected = r.layers[0].surface_force_N;  // F = F_s
      ++visited[0];
    } else if (fat != LayerState::Punctured) {
      if (depth < hs) {
        expected = ds * depth * v;  // skin post-puncture, h inside the skin
        ++visited[1];
      } else {
        expected = r.layers[1].surface_force_N + ds * hs * v;  // F = F_f + d_s h_s v
        ++visited[2];
      }
    } else if (muscle != LayerState::Punctured) {
      if (depth < hs + hf) {
        expected = (df * (depth - hs) + ds * hs) * v;  // fat post-puncture
        ++visited[3];
      } else {
        expected = r.layers[2].surface_force_N + (ds * hs + df * hf) * v;  // F = F_m + (d_s h_s + d_f h_f) v
        ++visited[4];
      }
    } else {
      expected = (ds * hs + df * hf + dm * (depth - hs - hf)) * v;  // muscle post-puncture
      ++visited[5];
    }
    ASSERT_NEAR(r.total_force_N, expected, 1e-12) << "tick " << i << " depth " << depth;
    // Surface forces come from the force mesh of the pressed layer only.
    for (std::size_t k = 0; k < 3; ++k) {
      if (r.layers[k].state == LayerState::Pressed) {
        ASSERT_GT(r.layers[k].surface_force_N, 0.0);
        ASSERT_NEAR(r.layers[k].surface_force_N, sim.force_mesh(k)->contact_reaction_N(), 1e-12);
      } else {
        ASSERT_EQ(r.layers[k].surface_force_N, 0.0);
      }
    }
  }
  for (int row = 0; row < 6; ++row) EXPECT_GT(visited[row], 0) << "Table 1 row " << row << " never visited";
  // Withdrawal reverses the damping force and leaves the layers punctured.
  EXPECT_LT(sim.last_result().total_force_N, 0.0);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(sim.layer_state(k), LayerState::Punctured);
}

TEST(PunctureForce, OnlyTheFirstIntactLayerIsReachable) {
  Scene scene = test::table2_scene("quasi_static");
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  NeedleState needle;
  needle.tip_position_m = Eigen::Vector3d(0, 0, 0.1e-3);  // above the skin: contact on the skin surface
  needle.axial_velocity_m_per_s = 0.01;
  sim.tick(needle);
  needle.tip_position_m = Eigen::Vector3d(0, 0, -1.5e-3);  // below the fat top, skin still intact
  needle.time_s = 1e-3;
  const TickResult& r = sim.tick(needle);
  EXPECT_EQ(r.layers[0].state, LayerState::Pressed);
  EXPECT_EQ(r.layers[1].state, LayerState::Untouched);
  EXPECT_EQ(r.layers[2].state, LayerState::Untouched);
  EXPECT_EQ(r.layers[1].surface_force_N + r.layers[1].damping_force_N, 0.0);
  EXPECT_FALSE(sim.has_contact(1));
}
