// layered_half_space.cpp: Burmister layered system by layer stiffness
// matrices in the Hankel domain; see layered_half_space.hpp.
#include "puncture/comparison/layered_half_space.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "puncture/comparison/boussinesq.hpp"
#include "puncture/sh/gauss_legendre.hpp"

namespace puncture::comparison {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Face tractions from face displacements of one layer at wavenumber k:
/// [t_x top, t_z top, t_x bottom, t_z bottom] = K [U top, W top, U bottom, W bottom]
/// (tractions applied ON the layer, z downward).
Eigen::Matrix4d layer_stiffness(const ElasticLayer& layer, double k) {
  const double E = layer.youngs_modulus_Pa, nu = layer.poisson_ratio, h = layer.thickness_m;
  const double mu = E / (2 * (1 + nu)), lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  const double kappa = 3 - 4 * nu, L = lambda + 2 * mu;
  Eigen::Matrix4d Phi, Psi;  // rows: U0, W0, Uh, Wh / tractions; columns: a1, D1, a2, D2
  // Solution 1 (s = -1) at depth z, its tractions S_x, S_z (per unit a or D).
  auto sol1 = [&](double z, Eigen::Vector4d& a_col, Eigen::Vector4d& d_col) {
    const double e = std::exp(-k * z);
    // [U, W, S_x, S_z] for a = 1 and for D = 1
    a_col << e, e, mu * k * (-2.0) * e, k * (-2 * mu) * e;
    d_col << k * z * e, (kappa + k * z) * e, mu * k * (-(kappa - 1) - 2 * k * z) * e,
        k * (L * (1 - kappa) - 2 * mu * k * z) * e;
  };
  // Solution 2 (s = +1) at z' = z - h.
  auto sol2 = [&](double zp, Eigen::Vector4d& a_col, Eigen::Vector4d& d_col) {
    const double e = std::exp(k * zp);
    a_col << e, -e, mu * k * 2.0 * e, k * (-2 * mu) * e;
    d_col << -k * zp * e, (-kappa + k * zp) * e, mu * k * ((kappa - 1) - 2 * k * zp) * e,
        k * (L * (1 - kappa) + 2 * mu * k * zp) * e;
  };
  Eigen::Vector4d a1_top, d1_top, a1_bot, d1_bot, a2_top, d2_top, a2_bot, d2_bot;
  sol1(0.0, a1_top, d1_top);
  sol1(h, a1_bot, d1_bot);
  sol2(-h, a2_top, d2_top);
  sol2(0.0, a2_bot, d2_bot);
  const Eigen::Vector4d cols_top[4] = {a1_top, d1_top, a2_top, d2_top};
  const Eigen::Vector4d cols_bot[4] = {a1_bot, d1_bot, a2_bot, d2_bot};
  for (int c = 0; c < 4; ++c) {
    Phi(0, c) = cols_top[c][0];
    Phi(1, c) = cols_top[c][1];
    Phi(2, c) = cols_bot[c][0];
    Phi(3, c) = cols_bot[c][1];
    Psi(0, c) = -cols_top[c][2];  // top face normal -z: t = -sigma_.z
    Psi(1, c) = -cols_top[c][3];
    Psi(2, c) = cols_bot[c][2];   // bottom face normal +z
    Psi(3, c) = cols_bot[c][3];
  }
  return Psi * Phi.inverse();
}

}  // namespace

LayeredHalfSpace::LayeredHalfSpace(std::vector<ElasticLayer> layers, double max_radius_m)
    : layers_(std::move(layers)), max_radius_m_(max_radius_m) {
  if (layers_.empty()) throw std::invalid_argument("LayeredHalfSpace: no layers");
  for (std::size_t i = 0; i < layers_.size(); ++i) {
    const ElasticLayer& l = layers_[i];
    if (!(l.thickness_m > 0) || !(l.youngs_modulus_Pa > 0) || !(l.poisson_ratio > -1 && l.poisson_ratio < 0.5))
      throw std::invalid_argument("LayeredHalfSpace: layer " + std::to_string(i) +
                                  " needs thickness > 0, E > 0 and -1 < nu < 0.5");
  }
  if (!(max_radius_m > 0)) throw std::invalid_argument("LayeredHalfSpace: max_radius_m must be > 0");
  const ElasticLayer& top = layers_.front();
  const double c_top = 2 * (1 - top.poisson_ratio * top.poisson_ratio) / top.youngs_modulus_Pa;
  const double k_max = 30.0 / top.thickness_m;
  const double panel = 0.5 * kPi / max_radius_m_;
  const int panels = std::max(8, static_cast<int>(std::ceil(k_max / panel)));
  Eigen::VectorXd gx, gw;
  gauss_legendre(8, gx, gw, GaussLegendreValues::Table16Digits);
  const double width = k_max / panels;
  for (int p = 0; p < panels; ++p)
    for (int q = 0; q < 8; ++q) {
      const double k = width * (p + 0.5 + 0.5 * gx[q]);
      nodes_.push_back(k);
      weights_.push_back(0.5 * width * gw[q] * (compliance(k) - c_top / k));
    }
}

double LayeredHalfSpace::compliance(double k) const {
  if (!(k > 0)) throw std::invalid_argument("LayeredHalfSpace::compliance: k must be > 0");
  const int n = static_cast<int>(layers_.size());
  const int dofs = 2 * n;  // interfaces 0..n-1 (the base n is fixed)
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(dofs + 2, dofs + 2);
  for (int i = 0; i < n; ++i) K.block<4, 4>(2 * i, 2 * i) += layer_stiffness(layers_[static_cast<std::size_t>(i)], k);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dofs);
  f[1] = 1.0;  // unit normal traction (downward) at the surface
  const Eigen::VectorXd d = K.topLeftCorner(dofs, dofs).partialPivLu().solve(f);
  return d[1];
}

std::vector<double> LayeredHalfSpace::annulus_spectrum(double r1, double r2) const {
  std::vector<double> spectrum(nodes_.size());
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const double k = nodes_[i];
    spectrum[i] =
        weights_[i] * (r2 * std::cyl_bessel_j(1.0, k * r2) - (r1 > 0 ? r1 * std::cyl_bessel_j(1.0, k * r1) : 0.0));
  }
  return spectrum;
}

double LayeredHalfSpace::remainder_displacement(const std::vector<double>& spectrum, double r) const {
  if (spectrum.size() != nodes_.size()) throw std::invalid_argument("LayeredHalfSpace: spectrum of the wrong size");
  double u = 0.0;
  for (std::size_t i = 0; i < nodes_.size(); ++i) u += spectrum[i] * std::cyl_bessel_j(0.0, nodes_[i] * r);
  return u;
}

double LayeredHalfSpace::disc_displacement(double a, double r) const { return annulus_displacement(0.0, a, r); }

double LayeredHalfSpace::annulus_displacement(double r1, double r2, double r) const {
  if (!(r2 > r1) || r1 < 0 || r < 0) throw std::invalid_argument("LayeredHalfSpace: need 0 <= r1 < r2 and r >= 0");
  const ElasticLayer& top = layers_.front();
  double u = love_uniform_disc_uz_m(1.0, r2, r, top.youngs_modulus_Pa, top.poisson_ratio);
  if (r1 > 0) u -= love_uniform_disc_uz_m(1.0, r1, r, top.youngs_modulus_Pa, top.poisson_ratio);
  return u + remainder_displacement(annulus_spectrum(r1, r2), r);
}

}  // namespace puncture::comparison
