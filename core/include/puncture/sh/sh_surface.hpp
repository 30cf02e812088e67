// sh_surface.hpp: surfaces given by SH expansions (seed paper Eq. 3 and 4).
//
//   RadialSHSurface (Eq. 4):      X(u) = r(u) u,  r(u) = sum_k c_k Y_k(u)       (star-shaped)
//   ParametricSHSurface (Eq. 3):  X(u) = sum_k C_k Y_k(u), C: count x 3 (x, y, z columns)
//
// u is a direction on the unit sphere (normalised on entry). Positions are in
// the units of the coefficients (m in this project). Tangent derivatives are
// with respect to arc length on the unit sphere (m per rad).
//
// Evaluation writes into a caller-owned SHWorkspace and does not allocate; the
// overloads without a workspace allocate one (convenient, not for the haptic tick).
#pragma once

#include <Eigen/Core>

#include "puncture/contact_surface.hpp"
#include "puncture/sh/real_sh.hpp"
#include "puncture/sh/sh_fit.hpp"

namespace puncture {

/// Largest |m| among the non-zero coefficient rows (0 for an all-zero set).
int highest_order(const Eigen::MatrixXd& coefficients, int degree);

/// Scratch space for one evaluation: basis values and tangential gradients.
struct SHWorkspace {
  explicit SHWorkspace(int count) : values(count), gradient(3, count) {}
  Eigen::VectorXd values;    ///< Y_k(u), count
  Eigen::Matrix3Xd gradient; ///< tangential gradient of Y_k, 3 x count
};

/// Right-handed orthonormal tangent frame (e1, e2) at unit u: e1 x e2 = u.
/// Regular everywhere (the helper axis switches away from u).
void sphere_tangent_frame(const Eigen::Vector3d& u, Eigen::Vector3d& e1, Eigen::Vector3d& e2);

class RadialSHSurface {
 public:
  /// coefficients: count = (degree + 1)^2 entries.
  RadialSHSurface(int degree, Eigen::VectorXd coefficients);
  /// Least-squares fit of r from directions (n x 3) and radii (n); see sh_fit.hpp.
  static RadialSHSurface fit(int degree, const Eigen::MatrixX3d& directions,
                             const Eigen::VectorXd& radii, SHFitReport* report = nullptr);

  int degree() const { return basis_.degree(); }
  const RealSHBasis& basis() const { return basis_; }
  const Eigen::VectorXd& coefficients() const { return coefficients_; }
  /// Largest |m| with a non-zero coefficient; evaluation runs over |m| <= this only.
  int max_order() const { return max_order_; }
  SHWorkspace make_workspace() const { return SHWorkspace(basis_.count()); }

  double radius(const Eigen::Vector3d& u, SHWorkspace& ws) const;
  Eigen::Vector3d position(const Eigen::Vector3d& u, SHWorkspace& ws) const;
  /// Position and unit outward normal n = (r u - grad r) / |r u - grad r|.
  /// Throws std::domain_error where r <= 0 (not a star-shaped surface there).
  SurfacePoint evaluate(const Eigen::Vector3d& u, SHWorkspace& ws) const;

  Eigen::Vector3d position(const Eigen::Vector3d& u) const;
  SurfacePoint evaluate(const Eigen::Vector3d& u) const;

 private:
  RealSHBasis basis_;
  Eigen::VectorXd coefficients_;
  int max_order_ = 0;
};

class ParametricSHSurface {
 public:
  /// coefficients: count x 3.
  ParametricSHSurface(int degree, Eigen::MatrixX3d coefficients);
  /// Least-squares fit of X from directions (n x 3) and positions (n x 3).
  static ParametricSHSurface fit(int degree, const Eigen::MatrixX3d& directions,
                                 const Eigen::MatrixX3d& positions, SHFitReport* report = nullptr);

  int degree() const { return basis_.degree(); }
  const RealSHBasis& basis() const { return basis_; }
  const Eigen::MatrixX3d& coefficients() const { return coefficients_; }
  /// Largest |m| with a non-zero coefficient row; evaluation runs over |m| <= this
  /// only (exactly zero rows cost nothing, e.g. for axisymmetric surfaces).
  int max_order() const { return max_order_; }
  SHWorkspace make_workspace() const { return SHWorkspace(basis_.count()); }

  Eigen::Vector3d position(const Eigen::Vector3d& u, SHWorkspace& ws) const;
  /// Position X(u) and the 3 x 3 Jacobian J with dX = J t for any tangent t
  /// of the unit sphere at u (J u = 0).
  void position_and_jacobian(const Eigen::Vector3d& u, SHWorkspace& ws, Eigen::Vector3d& position,
                             Eigen::Matrix3d& jacobian) const;
  /// Derivatives of X along the tangent directions t1, t2 (components along
  /// u are ignored): d_i = J t_i.
  void tangent_derivatives(const Eigen::Vector3d& u, const Eigen::Vector3d& t1,
                           const Eigen::Vector3d& t2, SHWorkspace& ws, Eigen::Vector3d& d1,
                           Eigen::Vector3d& d2) const;
  /// Position and unit normal n = (J e1) x (J e2) / |...| with (e1, e2, u)
  /// right-handed: the orientation carried over from the sphere's outward
  /// normal (outward for an orientation-preserving map). Pole-safe. Throws
  /// std::domain_error where the map is singular (|J e1 x J e2| ~ 0).
  SurfacePoint evaluate(const Eigen::Vector3d& u, SHWorkspace& ws) const;

  Eigen::Vector3d position(const Eigen::Vector3d& u) const;
  SurfacePoint evaluate(const Eigen::Vector3d& u) const;

 private:
  RealSHBasis basis_;
  Eigen::MatrixX3d coefficients_;
  int max_order_ = 0;
};

/// Unit normal from a Jacobian J at u (as ParametricSHSurface::evaluate);
/// returns false (n untouched) where |J e1 x J e2| <= tiny * |J|^2.
bool normal_from_jacobian(const Eigen::Vector3d& u, const Eigen::Matrix3d& jacobian,
                          Eigen::Vector3d& normal);

}  // namespace puncture
