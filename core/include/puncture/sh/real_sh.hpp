// real_sh.hpp: real spherical harmonics Y_lm on the unit sphere (seed paper
// Eq. 1-2), evaluated pole-safely with values and tangential gradients.
//
// Convention
//   * Terms: 0 <= l <= degree, -l <= m <= l (the paper's |m| < l is a typo),
//     flat index sh_index(l, m) = l*l + l + m, count (degree + 1)^2.
//   * Orthonormal on the unit sphere: integral of Y_lm Y_l'm' dOmega = delta.
//   * With the complex Y_l^m of Eq. (1) INCLUDING the Condon-Shortley phase
//     (-1)^m of Eq. (2) (the convention of std::sph_legendre):
//         m = 0:  Y_l0 = Y_l^0
//         m > 0:  Y_lm = sqrt(2) (-1)^m Re Y_l^m   ~ cos(m phi)
//         m < 0:  Y_lm = sqrt(2) (-1)^m Im Y_l^|m| ~ sin(|m| phi)
//     i.e. the real basis itself carries NO Condon-Shortley phase:
//     Y_11 = sqrt(3 / 4pi) x, Y_1-1 = sqrt(3 / 4pi) y, Y_10 = sqrt(3 / 4pi) z.
//   * theta is the polar angle from +z, phi the azimuth from +x:
//     u = (sin theta cos phi, sin theta sin phi, cos theta).
//
// Evaluation (pole-safe). At a unit vector u = (x, y, z):
//     Y_lm(u) = q_l^|m|(z) * {Re, Im}((x + i y)^|m|)     (times sqrt(2) for m != 0)
// where q_l^m = N_lm P_l^m / sin^m(theta) is a polynomial in z of degree l - m,
// computed by the fully normalised three-term recurrence (no factorials; stable
// well beyond l = 64). Values and the gradient on the sphere are therefore
// regular at the poles: the tangential gradient is (I - u u^T) grad F of the
// polynomial extension F(x, y, z) above.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace puncture {

/// Flat index of term (l, m), -l <= m <= l.
inline int sh_index(int l, int m) { return l * l + l + m; }
/// Number of terms of a basis of maximum degree `degree`.
inline int sh_count(int degree) { return (degree + 1) * (degree + 1); }

/// u = (sin theta cos phi, sin theta sin phi, cos theta).
Eigen::Vector3d unit_vector_from_angles(double theta, double phi);

/// The real SH basis up to a fixed degree. Evaluation does not allocate and
/// is thread-safe (the object holds only precomputed recurrence factors).
class RealSHBasis {
 public:
  /// degree >= 0; throws std::invalid_argument otherwise.
  explicit RealSHBasis(int degree);

  int degree() const { return degree_; }
  int count() const { return sh_count(degree_); }

  /// values[sh_index(l, m)] = Y_lm(u). u need not be unit (it is normalised;
  /// u = 0 throws std::invalid_argument). `values` holds count() doubles.
  void evaluate(const Eigen::Vector3d& u, double* values) const;

  /// Values and tangential gradients (gradient on the unit sphere, a vector
  /// tangent at u, units 1/rad): tangential_gradient[3 * k + {0, 1, 2}] =
  /// (x, y, z) components for term k (a column-major 3 x count matrix).
  void evaluate_with_gradient(const Eigen::Vector3d& u, double* values,
                              double* tangential_gradient) const;

  /// Order-limited variants: only terms with |m| <= max_order are written
  /// (the others are left untouched). For expansions known to contain low
  /// orders only (e.g. axisymmetric surfaces), at a fraction of the cost.
  void evaluate(const Eigen::Vector3d& u, double* values, int max_order) const;
  void evaluate_with_gradient(const Eigen::Vector3d& u, double* values,
                              double* tangential_gradient, int max_order) const;

 private:
  template <bool kWithGradient>
  void evaluate_impl(const Eigen::Vector3d& u, double* values, double* gradient,
                     int max_order) const;

  int degree_;
  std::vector<double> a_;     ///< a_lm = sqrt((4l^2 - 1) / (l^2 - m^2)), at sh_index(l, m), m >= 0
  std::vector<double> b_;     ///< b_lm = sqrt(((l-1)^2 - m^2) / (4 (l-1)^2 - 1))
  std::vector<double> diag_;  ///< q_mm / q_{m-1,m-1} = sqrt((2m + 1) / (2m))
};

/// Convenience (allocates): Y_lm at polar angle theta and azimuth phi (rad).
double real_sh(int l, int m, double theta, double phi);

}  // namespace puncture
