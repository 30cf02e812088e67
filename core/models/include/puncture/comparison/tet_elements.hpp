// tet_elements.hpp: the linear tetrahedron (P1) pieces shared by the
// tensor-mass models: shape gradients, Cotin's linear stiffness tensors and
// the St Venant-Kirchhoff energy, forces and tangent of Picinbono's model.
//
// Conventions (SI): rest positions X_a, current positions x_a (m), a = 0..3;
// g_a = grad N_a (1/m), constant in the element; V the rest volume (m^3).
//   F = sum_a x_a g_a^T                       deformation gradient
//   E = (F^T F - I) / 2                       Green-Lagrange strain
//   W = V (lambda/2 tr(E)^2 + mu tr(E^2))     StVK energy (J)
//   S = lambda tr(E) I + 2 mu E               second Piola-Kirchhoff stress (Pa)
//   f_a = -dW/dx_a = -V F S g_a               elastic force on node a (N)
//   K_ab = d2W/dx_a dx_b = V [ (g_a . S g_b) I + lambda (F g_a)(F g_b)^T
//                              + mu (g_a . g_b) F F^T + mu (F g_b)(F g_a)^T ]
// At F = I (S = 0) K_ab reduces to the linear elastic stiffness tensor of
// Cotin et al. (2000):
//   K_ab = V [ lambda g_a g_b^T + mu g_b g_a^T + mu (g_a . g_b) I ].
#pragma once

#include <Eigen/Core>

namespace puncture::comparison {

using Matrix12d = Eigen::Matrix<double, 12, 12>;
using Matrix34d = Eigen::Matrix<double, 3, 4>;

struct LameParameters {
  double lambda_Pa = 0.0;
  double mu_Pa = 0.0;
};
/// lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)). Throws
/// std::invalid_argument for E <= 0 or nu outside (-1, 0.5).
LameParameters lame_from_young(double youngs_modulus_Pa, double poisson_ratio);

struct TetShape {
  Eigen::Matrix<double, 4, 3> grad;  ///< row a = g_a^T (1/m)
  double volume_m3 = 0.0;            ///< rest volume (> 0)
};
/// Shape gradients of the tetrahedron with rest vertices X (columns). Throws
/// std::invalid_argument for a degenerate or negatively oriented element.
TetShape tet_shape(const Matrix34d& rest);

/// F = sum_a x_a g_a^T.
Eigen::Matrix3d deformation_gradient(const TetShape& shape, const Matrix34d& x);

/// Linear stiffness block K_ab (3 x 3) of Cotin's tensor-mass model.
Eigen::Matrix3d linear_stiffness_block(const TetShape& shape, const LameParameters& lame, int a, int b);
/// The 12 x 12 element stiffness (node-major: rows 3a..3a+2).
Matrix12d linear_element_stiffness(const TetShape& shape, const LameParameters& lame);

/// StVK second Piola-Kirchhoff stress for the Green strain E.
Eigen::Matrix3d stvk_stress(const Eigen::Matrix3d& green_strain, const LameParameters& lame);
double stvk_energy_J(const TetShape& shape, const Matrix34d& x, const LameParameters& lame);
/// Forces f_a = -dW/dx_a = -V F S g_a (column a).
Matrix34d stvk_forces(const TetShape& shape, const Matrix34d& x, const LameParameters& lame);
/// Forces for a given total second Piola-Kirchhoff stress S: -V F S g_a.
Matrix34d forces_from_stress(const TetShape& shape, const Eigen::Matrix3d& F, const Eigen::Matrix3d& S);
/// Tangent K = d2W/dx2 (12 x 12, node-major), symmetric.
Matrix12d stvk_tangent(const TetShape& shape, const Matrix34d& x, const LameParameters& lame);

}  // namespace puncture::comparison
