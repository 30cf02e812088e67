#include "puncture/shape_matching.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <stdexcept>

namespace puncture {

Eigen::Matrix3d rotation_of_polar_decomposition(const Eigen::Matrix3d& A) {
  if (!A.allFinite()) throw std::invalid_argument("shape matching: moment matrix A is not finite");
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  // Singular values are sorted decreasingly: flipping the last axis changes
  // the smallest one, which gives the closest rotation to A.
  D(2, 2) = (U * V.transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return U * D * V.transpose();
}

namespace {

void check(const Eigen::Matrix3Xd& rest, const Eigen::Matrix3Xd& current, const Eigen::VectorXd& masses) {
  if (rest.cols() != current.cols() || rest.cols() != masses.size())
    throw std::invalid_argument("shape matching: rest, current and masses must have the same number of nodes");
  if (!(masses.sum() > 0.0)) throw std::invalid_argument("shape matching: total mass must be positive");
  if (!rest.allFinite() || !current.allFinite() || !masses.allFinite())
    throw std::invalid_argument("shape matching: non-finite positions or masses");
}

// Mass-weighted centres p_cm^0 (rest) and p_cm (current), m. No allocation.
void centres_of_mass(const Eigen::Matrix3Xd& rest, const Eigen::Matrix3Xd& current, const Eigen::VectorXd& masses,
                     Eigen::Vector3d& cm0, Eigen::Vector3d& cm) {
  cm0.setZero();
  cm.setZero();
  for (Eigen::Index i = 0; i < rest.cols(); ++i) {
    cm0 += masses[i] * rest.col(i);
    cm += masses[i] * current.col(i);
  }
  const double mass = masses.sum();
  cm0 /= mass;
  cm /= mass;
}

}  // namespace

Eigen::Matrix3d shape_matching_moment(const Eigen::Matrix3Xd& rest, const Eigen::Matrix3Xd& current,
                                      const Eigen::VectorXd& masses) {
  check(rest, current, masses);
  Eigen::Vector3d cm, cm0;
  centres_of_mass(rest, current, masses, cm0, cm);
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  for (Eigen::Index i = 0; i < rest.cols(); ++i)
    A.noalias() += masses[i] * (current.col(i) - cm) * (rest.col(i) - cm0).transpose();
  return A;
}

void shape_matching_goals(const Eigen::Matrix3Xd& rest, const Eigen::Matrix3Xd& current,
                          const Eigen::VectorXd& masses, Eigen::Matrix3Xd& goals) {
  if (goals.cols() != rest.cols()) throw std::invalid_argument("shape matching: goals must be preallocated to 3 x n");
  const Eigen::Matrix3d R = rotation_of_polar_decomposition(shape_matching_moment(rest, current, masses));
  Eigen::Vector3d cm, cm0;
  centres_of_mass(rest, current, masses, cm0, cm);
  for (Eigen::Index i = 0; i < rest.cols(); ++i) goals.col(i) = R * (rest.col(i) - cm0) + cm;
}

}  // namespace puncture
