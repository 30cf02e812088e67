// insertion_angle.hpp: how far from the surface normal a scene may tilt the
// needle (Insertion::angle_deg; the inclined path is described in needle.hpp).
// Free of Eigen, so the scene reader can use it alone.
#pragma once

namespace puncture {

/// Largest insertion angle to the surface normal a scene may ask for (deg):
/// the clinical range (intravenous and arterial access at 15-45 deg) with a
/// margin; beyond it the needle grazes the surface (cos a < 1/2).
constexpr double kMaxInsertionAngleDeg = 60.0;

}  // namespace puncture
