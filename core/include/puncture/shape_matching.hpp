// shape_matching.hpp: goal positions of shape matching (Mueller et al. 2005),
// seed paper Eq. (6)-(7).
//
//   A   = sum_i M_i (p_i - p_cm)(p_i^0 - p_cm^0)^T          (3 x 3, kg m^2)
//   R   = rotational part of the polar decomposition A = R S
//   g_i = R (p_i^0 - p_cm^0) + p_cm
// with p_cm, p_cm^0 the mass-weighted centres of the current and rest
// positions. (The paper prints R = alpha / A with alpha = sqrt(A^T A); the
// intended R = A (A^T A)^{-1/2} is what we compute.)
//
// R is extracted robustly from the SVD A = U Sigma V^T as
//   R = U diag(1, 1, det(U V^T)) V^T,
// which is a proper rotation (det R = +1) for every A: reflected A (det < 0)
// gives the closest rotation, and degenerate A (rank 0, 1 or 2: all points
// equal, collinear or coplanar sets) still gives a finite rotation (R = I for
// A = 0). Non-finite input throws std::invalid_argument.
#pragma once

#include <Eigen/Core>

namespace puncture {

/// Closest proper rotation to A (det = +1), see above.
Eigen::Matrix3d rotation_of_polar_decomposition(const Eigen::Matrix3d& A);

/// Eq. (6): the moment matrix A. rest, current: 3 x n (m); masses: n (kg, > 0 in sum).
Eigen::Matrix3d shape_matching_moment(const Eigen::Matrix3Xd& rest, const Eigen::Matrix3Xd& current,
                                      const Eigen::VectorXd& masses);

/// Eq. (7): writes the goals g (3 x n, preallocated, m). No allocation.
/// Throws std::invalid_argument on size mismatch, zero total mass or non-finite input.
void shape_matching_goals(const Eigen::Matrix3Xd& rest, const Eigen::Matrix3Xd& current,
                          const Eigen::VectorXd& masses, Eigen::Matrix3Xd& goals);

}  // namespace puncture
