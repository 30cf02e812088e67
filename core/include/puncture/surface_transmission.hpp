// surface_transmission.hpp: how the deflection of one layer's surface shows
// on the surfaces below it (Effects::coupled_surfaces, see simulator.hpp).
//
// Model: an incompressible elastic half-space. A deflection field u(y) (m,
// > 0 into the tissue) imposed on its surface displaces the material at depth
// h (m) vertically by
//     u_h(x) = integral G_h(|x - y|) u(y) dA(y),
//     G_h(rho) = 3 h^3 / (2 pi (rho^2 + h^2)^(5/2))          (1/m^2)
// (Fourier transfer (1 + k h) exp(-k h); the integral of G_h over the plane is
// 1, so a uniform deflection passes unchanged; the shape of Boussinesq's
// vertical stress under a point load). By reciprocity it is also the surface
// deflection of a load buried at depth h relative to the same load on the
// surface.
// For an axisymmetric u(s) the angle is integrated in closed form:
//     g_h(rho, s) = integral_0^2pi G_h dtheta = (3 h^3 / pi) J,
//     J = integral_0^pi (A - B cos t)^(-5/2) dt
//       = (4/3) a^(-1/2) b^(-1) [(2 E(m) - K(m)) / (2 a) + E(m) / b],
//     A = rho^2 + s^2 + h^2, B = 2 rho s, a = A + B, b = A - B, m = 2 B / a,
// with K, E the complete elliptic integrals of parameter m
// (std::comp_ellint_1/2 take the modulus sqrt(m)).
//
// Functions (SI units; radii are distances from the needle axis):
//   boussinesq_kernel_per_m2(rho, h)             G_h(rho)
//   boussinesq_ring_kernel_per_m(rho, s, h)      g_h(rho, s) (1/m^2 x rad)
//   transmission_weights(profile_r, target_r, h) W (targets x profile points):
//       u_h(rho_i) = sum_j W(i, j) u_j for the piecewise-linear profile with
//       values u_j at profile_r[j] (profile_r[0] = 0, increasing; 0 beyond the
//       last radius); Gauss-Legendre in s, intervals cut to h / 4 or finer.
//   profile_value_at(profile_r, values, rho)     the same profile at rho
// transmission_weights throws std::invalid_argument for h <= 0, radii that do
// not start at 0 and increase, or negative target radii.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace puncture {

double boussinesq_kernel_per_m2(double rho_m, double depth_m);
double boussinesq_ring_kernel_per_m(double rho_m, double s_m, double depth_m);
Eigen::MatrixXd transmission_weights(const std::vector<double>& profile_radii_m,
                                     const std::vector<double>& target_radii_m, double depth_m);
double profile_value_at(const std::vector<double>& profile_radii_m, const double* values_m, double rho_m);

}  // namespace puncture
