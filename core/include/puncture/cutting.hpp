// cutting.hpp: the cutting force of a punctured layer (Effects::cutting,
// ForceLaw::cutting_force_N and cutting_release_m in scene.hpp).
//
// After a layer breaks, the needle tip advances a crack through it until it
// reaches the next layer's surface. Advancing the crack by ds costs the
// fracture energy G_c w ds (w: cut width, about the needle diameter 2R), so
// the needle feels the constant cutting force
//     C = G_c w                         (N; e.g. 1.1 kJ/m^2 x 1.27 mm = 1.4 N)
// while the tip is at the crack front. The front is the deepest point the
// tip has reached in the layer (s_front, measured along the needle axis);
// when the tip backs off by r = s_front - s_tip >= 0 the force falls
// linearly to 0 over the release distance r_c (the crack tip region unloads
// elastically; this keeps the force continuous when a device jitters):
//     F_cut = C max(0, 1 - r / r_c)
// Re-inserting into an existing crack costs nothing until the tip is back
// within r_c of the front. Withdrawal: F_cut = 0 once r >= r_c.
#pragma once

#include <algorithm>

namespace puncture {

/// F_cut (N) for cutting force C (N), release distance r_c (m > 0), front and
/// tip positions along the needle axis (m, larger = deeper).
inline double cutting_force_N(double cutting_force_N, double release_m, double front_m, double tip_m) {
  const double r = std::max(0.0, front_m - tip_m);
  return cutting_force_N * std::max(0.0, 1.0 - r / release_m);
}

}  // namespace puncture
