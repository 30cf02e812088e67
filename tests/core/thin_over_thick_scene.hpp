// thin_over_thick_scene.hpp (test helper): a thin layer over a thick one on
// planes, and a needle descending through them one 1 ms tick at a time.
#pragma once

#include <vector>

#include "puncture/needle.hpp"
#include "puncture/scene.hpp"
#include "table2_scene.hpp"

namespace puncture::test {

/// A thin upper layer "a" (1 mm, breaks at 1 N, about 1.5 mm deep: below the
/// rest surface of the thick layer "b" under it, which is then met at the tip)
/// over "b" (20 mm, breaks at b_critical_N); quasi-static meshes, 20 ms
/// resumption, no damping.
inline Scene thin_over_thick(bool coupled, double b_critical_N = 1e3) {
  Scene s;
  s.name = "thin_over_thick";
  s.layers.push_back(table2_layer("a", 1e-3, 200.0, 0.0, 8, 1e-3, 100.0, 1.0, 0.05));
  s.layers.push_back(table2_layer("b", 20e-3, 200.0, 0.0, 6, 1e-3, 100.0, 1.0, 0.05));
  for (Layer& l : s.layers) {
    l.force_law.breakthrough.kind = BreakthroughCriterion::Kind::CriticalForce;
    l.force_law.breakthrough.critical_force_N = 1e3;
    l.resumption_time_s = 0.02;
  }
  s.layers[0].force_law.breakthrough.critical_force_N = 1.0;
  s.layers[1].force_law.breakthrough.critical_force_N = b_critical_N;
  s.realtime.integrator = "quasi_static";
  s.effects.damping = false;
  s.effects.coupled_surfaces = coupled;
  return s;
}

/// The needle going down at 10 mm/s from 0.5 mm above the first surface, one state per 1 ms tick.
inline std::vector<NeedleState> descent(int ticks) {
  std::vector<NeedleState> states;
  for (int i = 0; i < ticks; ++i) {
    NeedleState n;
    n.time_s = i * 1e-3;
    n.tip_position_m = Eigen::Vector3d(0.0, 0.0, 0.5e-3 - 0.01 * n.time_s);
    n.axial_velocity_m_per_s = 0.01;
    states.push_back(n);
  }
  return states;
}

}  // namespace puncture::test
