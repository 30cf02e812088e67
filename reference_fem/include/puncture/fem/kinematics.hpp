// kinematics.hpp: finite-strain kinematics shared by the 3D solver
// (finite_strain_solver.cc) and the axisymmetric solver
// (axisymmetric_solver.cc).
//
// In:  the deformation gradient F (3x3, dimensionless) and the gradient G of a
//      vector test (shape) function (3x3, per m of its nodal value); for the
//      axisymmetric helpers, the 2D (R, Z) gradients of u_R, u_Z (or of one
//      shape function), the value of u_R (m) or of the shape function, and
//      the radius R (m) of the point.
// Out: the right Cauchy-Green tensor C = F^T F, the variation of the
//      Green-Lagrange strain dE = sym(F^T G), whether a symmetric tensor is
//      finite, and the 3x3 displacement / shape-function gradients of the
//      meridian plane in the order (R, Z, theta) with the hoop entry u_R / R
//      (Holzapfel 2000, Sec. 2).
#pragma once

#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

#include <cmath>

namespace puncture::fem {

/// C = F^T F (symmetric).
inline dealii::SymmetricTensor<2, 3> right_cauchy_green(const dealii::Tensor<2, 3>& F) {
  dealii::SymmetricTensor<2, 3> C;
  for (unsigned a = 0; a < 3; ++a)
    for (unsigned b = a; b < 3; ++b) {
      double s = 0.0;
      for (unsigned i = 0; i < 3; ++i) s += F[i][a] * F[i][b];
      C[a][b] = s;
    }
  return C;
}

/// F^T G, symmetrised: the variation of the Green-Lagrange strain.
inline dealii::SymmetricTensor<2, 3> strain_variation(const dealii::Tensor<2, 3>& F,
                                                      const dealii::Tensor<2, 3>& G) {
  dealii::SymmetricTensor<2, 3> dE;
  for (unsigned a = 0; a < 3; ++a)
    for (unsigned b = a; b < 3; ++b) {
      double s = 0.0;
      for (unsigned i = 0; i < 3; ++i) s += F[i][a] * G[i][b] + G[i][a] * F[i][b];
      dE[a][b] = 0.5 * s;
    }
  return dE;
}

/// True if every entry of a symmetric tensor is finite.
inline bool all_finite(const dealii::SymmetricTensor<2, 3>& t) {
  for (unsigned a = 0; a < 3; ++a)
    for (unsigned b = a; b < 3; ++b)
      if (!std::isfinite(t[a][b])) return false;
  return true;
}

/// Axisymmetric: 3x3 gradient (R, Z, theta) of a vector shape function of
/// component c (0: R, 1: Z) with value N and 2D gradient g at radius R; the
/// hoop entry N/R for c = R.
inline dealii::Tensor<2, 3> axisymmetric_shape_gradient(unsigned c, double N, const dealii::Tensor<1, 2>& g,
                                                        double R) {
  dealii::Tensor<2, 3> G;
  G[c][0] = g[0];
  G[c][1] = g[1];
  if (c == 0) G[2][2] = N / R;
  return G;
}

/// Axisymmetric: displacement gradient H (3x3, R Z theta) at a point from the
/// 2D gradients of u_R, u_Z and the value of u_R at radius R; F = I + H.
inline dealii::Tensor<2, 3> axisymmetric_displacement_gradient(const dealii::Tensor<1, 2>& grad_ur,
                                                               const dealii::Tensor<1, 2>& grad_uz, double ur,
                                                               double R) {
  dealii::Tensor<2, 3> H;
  H[0][0] = grad_ur[0];
  H[0][1] = grad_ur[1];
  H[1][0] = grad_uz[0];
  H[1][1] = grad_uz[1];
  H[2][2] = ur / R;
  return H;
}

}  // namespace puncture::fem
