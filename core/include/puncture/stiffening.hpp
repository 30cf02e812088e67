// stiffening.hpp: strain-stiffening of the virtual spring under the needle tip
// (Effects::stiffening, StiffeningLaw in scene.hpp).
//
// The contact node's virtual spring carries, besides its linear K z, the
// extra force g(z) (N) at deflection z (m, >= 0 into the tissue):
//   Polynomial:   g(z) = a2 z^2 + a3 z^3                         (a2 N/m^2, a3 N/m^3, >= 0)
//   Exponential:  g(z) = k_e z_s (exp(z / z_s) - 1 - z / z_s)    (k_e N/m >= 0, z_s m > 0)
// Both vanish with their slope at z = 0 (the small-strain stiffness is the
// mesh's own) and are convex and increasing for z > 0, so a force-deflection
// law stays monotone. With a quasi-static mesh of static stiffness S the
// pressing force is F(z) = S z + g(z): F = a1 z + a2 z^2 is the polynomial
// law with K chosen for S = a1 and a3 = 0. For z <= 0: g = 0.
// stiffening_energy_J is the integral of g from 0 to z (J).
#pragma once

#include "puncture/scene.hpp"

namespace puncture {

double stiffening_force_N(const StiffeningLaw& law, double deflection_m);
/// dg/dz (N/m), >= 0.
double stiffening_stiffness_N_per_m(const StiffeningLaw& law, double deflection_m);
double stiffening_energy_J(const StiffeningLaw& law, double deflection_m);

}  // namespace puncture
