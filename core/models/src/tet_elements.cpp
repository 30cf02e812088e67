// tet_elements.cpp: P1 tetrahedron shape gradients, linear (Cotin) and StVK
// (Picinbono) element quantities; formulas in tet_elements.hpp.
#include "puncture/comparison/tet_elements.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace puncture::comparison {

LameParameters lame_from_young(double E, double nu) {
  if (!(E > 0.0) || !(nu > -1.0 && nu < 0.5))
    throw std::invalid_argument("lame_from_young: need E > 0 and -1 < nu < 0.5 (got E = " + std::to_string(E) +
                                ", nu = " + std::to_string(nu) + ")");
  return {E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), E / (2.0 * (1.0 + nu))};
}

TetShape tet_shape(const Matrix34d& X) {
  Eigen::Matrix3d D;
  D.col(0) = X.col(1) - X.col(0);
  D.col(1) = X.col(2) - X.col(0);
  D.col(2) = X.col(3) - X.col(0);
  const double det = D.determinant();
  const double scale = D.colwise().norm().prod();
  if (!(det > 1e-12 * scale))
    throw std::invalid_argument("tet_shape: degenerate or negatively oriented tetrahedron (det " + std::to_string(det) +
                                ")");
  const Eigen::Matrix3d Dinv = D.inverse();  // rows: grad of the barycentric coordinates 1..3
  TetShape s;
  s.grad.row(1) = Dinv.row(0);
  s.grad.row(2) = Dinv.row(1);
  s.grad.row(3) = Dinv.row(2);
  s.grad.row(0) = -(Dinv.row(0) + Dinv.row(1) + Dinv.row(2));
  s.volume_m3 = det / 6.0;
  return s;
}

Eigen::Matrix3d deformation_gradient(const TetShape& shape, const Matrix34d& x) { return x * shape.grad; }

Eigen::Matrix3d linear_stiffness_block(const TetShape& shape, const LameParameters& lame, int a, int b) {
  const Eigen::Vector3d ga = shape.grad.row(a).transpose(), gb = shape.grad.row(b).transpose();
  return shape.volume_m3 * (lame.lambda_Pa * ga * gb.transpose() + lame.mu_Pa * gb * ga.transpose() +
                            lame.mu_Pa * ga.dot(gb) * Eigen::Matrix3d::Identity());
}

Matrix12d linear_element_stiffness(const TetShape& shape, const LameParameters& lame) {
  Matrix12d K;
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) K.block<3, 3>(3 * a, 3 * b) = linear_stiffness_block(shape, lame, a, b);
  return K;
}

Eigen::Matrix3d stvk_stress(const Eigen::Matrix3d& E, const LameParameters& lame) {
  return lame.lambda_Pa * E.trace() * Eigen::Matrix3d::Identity() + 2.0 * lame.mu_Pa * E;
}

namespace {
Eigen::Matrix3d green_strain(const Eigen::Matrix3d& F) {
  return 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
}
}  // namespace

double stvk_energy_J(const TetShape& shape, const Matrix34d& x, const LameParameters& lame) {
  const Eigen::Matrix3d E = green_strain(deformation_gradient(shape, x));
  const double tr = E.trace();
  return shape.volume_m3 * (0.5 * lame.lambda_Pa * tr * tr + lame.mu_Pa * (E * E).trace());
}

Matrix34d forces_from_stress(const TetShape& shape, const Eigen::Matrix3d& F, const Eigen::Matrix3d& S) {
  // f_a = -V F S g_a for every a at once: -V P G^T with G^T = grad^T (3 x 4).
  return -shape.volume_m3 * (F * S) * shape.grad.transpose();
}

Matrix34d stvk_forces(const TetShape& shape, const Matrix34d& x, const LameParameters& lame) {
  const Eigen::Matrix3d F = deformation_gradient(shape, x);
  return forces_from_stress(shape, F, stvk_stress(green_strain(F), lame));
}

Matrix12d stvk_tangent(const TetShape& shape, const Matrix34d& x, const LameParameters& lame) {
  const Eigen::Matrix3d F = deformation_gradient(shape, x);
  const Eigen::Matrix3d S = stvk_stress(green_strain(F), lame);
  const Eigen::Matrix3d FFt = F * F.transpose();
  Eigen::Matrix<double, 3, 4> Fg = F * shape.grad.transpose();  // column a = F g_a
  const Eigen::Matrix4d gg = shape.grad * shape.grad.transpose();
  const Eigen::Matrix4d gSg = shape.grad * S * shape.grad.transpose();
  Matrix12d K;
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      K.block<3, 3>(3 * a, 3 * b) =
          shape.volume_m3 * (gSg(a, b) * Eigen::Matrix3d::Identity() + lame.lambda_Pa * Fg.col(a) * Fg.col(b).transpose() +
                             lame.mu_Pa * gg(a, b) * FFt + lame.mu_Pa * Fg.col(b) * Fg.col(a).transpose());
  return K;
}

}  // namespace puncture::comparison
