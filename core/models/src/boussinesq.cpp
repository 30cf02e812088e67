// boussinesq.cpp: half-space closed forms; see boussinesq.hpp.
#include "puncture/comparison/boussinesq.hpp"

#include <cmath>
#include <stdexcept>

namespace puncture::comparison {

namespace {
constexpr double kPi = 3.14159265358979323846;
void check_material(double E, double nu) {
  if (!(E > 0.0) || !(nu > -1.0 && nu < 0.5)) throw std::invalid_argument("half-space: need E > 0 and -1 < nu < 0.5");
}
}  // namespace

double boussinesq_uz_m(double P, double r, double z, double E, double nu) {
  check_material(E, nu);
  const double rho = std::hypot(r, z);
  if (!(rho > 0.0)) throw std::invalid_argument("boussinesq_uz_m: singular at the load point");
  return P * (1.0 + nu) / (2.0 * kPi * E) * (z * z / (rho * rho * rho) + 2.0 * (1.0 - nu) / rho);
}

double boussinesq_surface_uz_m(double P, double r, double E, double nu) {
  check_material(E, nu);
  if (!(r > 0.0)) throw std::invalid_argument("boussinesq_surface_uz_m: singular at the load point");
  return P * (1.0 - nu * nu) / (kPi * E * r);
}

double love_uniform_disc_uz_m(double p, double a, double r, double E, double nu) {
  check_material(E, nu);
  if (!(a > 0.0) || r < 0.0) throw std::invalid_argument("love_uniform_disc_uz_m: need a > 0 and r >= 0");
  const double c = 4.0 * (1.0 - nu * nu) * p / (kPi * E);
  if (r <= a) return c * a * std::comp_ellint_2(r / a);
  const double k = a / r;
  return c * r * (std::comp_ellint_2(k) - (1.0 - k * k) * std::comp_ellint_1(k));
}

double sneddon_flat_punch_force_N(double delta, double a, double E, double nu) {
  check_material(E, nu);
  return 2.0 * a * E * delta / (1.0 - nu * nu);
}

double flat_punch_surface_uz_m(double delta, double a, double r) {
  return r <= a ? delta : 2.0 * delta / kPi * std::asin(a / r);
}

}  // namespace puncture::comparison
