// boussinesq.hpp: closed forms of the elastic half-space (Boussinesq 1885,
// Love 1929, Sneddon 1965) used by the boundary-element comparison model and
// its tests. Homogeneous isotropic half-space z >= 0 (depth), Young's modulus
// E (Pa), Poisson ratio nu; loads push INTO the half-space and displacements
// are positive in that direction (m).
#pragma once

namespace puncture::comparison {

/// Vertical displacement at depth z >= 0 and radial distance r from a point
/// force P (N) on the surface (Boussinesq):
///   u_z = P (1 + nu) / (2 pi E) [ z^2 / rho^3 + 2 (1 - nu) / rho ],  rho = sqrt(r^2 + z^2).
double boussinesq_uz_m(double force_N, double r_m, double depth_m, double youngs_modulus_Pa, double poisson_ratio);
/// Its surface value P (1 - nu^2) / (pi E r).
double boussinesq_surface_uz_m(double force_N, double r_m, double youngs_modulus_Pa, double poisson_ratio);

/// Surface displacement at radius r under a uniform pressure p (Pa) on the disc
/// of radius a (Love 1929; Johnson, Contact Mechanics, Eq. 3.13):
///   r <= a:  4 (1 - nu^2) p a / (pi E) E(r / a)
///   r >  a:  4 (1 - nu^2) p r / (pi E) [ E(a / r) - (1 - a^2 / r^2) K(a / r) ]
/// with K, E the complete elliptic integrals of modulus k.
double love_uniform_disc_uz_m(double pressure_Pa, double disc_radius_m, double r_m, double youngs_modulus_Pa,
                              double poisson_ratio);

/// Rigid flat punch of radius a pressed by delta (Sneddon): force 2 a E delta / (1 - nu^2).
double sneddon_flat_punch_force_N(double indentation_m, double punch_radius_m, double youngs_modulus_Pa,
                                  double poisson_ratio);
/// Its surface profile: delta for r <= a, (2 delta / pi) asin(a / r) outside.
double flat_punch_surface_uz_m(double indentation_m, double punch_radius_m, double r_m);

}  // namespace puncture::comparison
