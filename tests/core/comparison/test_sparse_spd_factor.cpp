// SparseSpdFactor (sparse_spd_factor.hpp): solutions against a dense solve of
// the same system, positive definite (CHOLMOD) and indefinite (the LDL^T
// fallback), refactorisation with new values on the analysed pattern; the
// calling thread's OpenMP setting is the same after a factorisation and a
// solve as before (CHOLMOD's regions are switched off only while it works).
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include "puncture/comparison/sparse_spd_factor.hpp"

namespace puncture::comparison {
namespace {

/// A 3-dof-per-node Laplacian of a 1-D chain of n nodes plus shift * I.
Eigen::SparseMatrix<double> chain_matrix(int n, double shift) {
  std::vector<Eigen::Triplet<double>> t;
  for (int a = 0; a < n; ++a)
    for (int d = 0; d < 3; ++d) {
      const int i = 3 * a + d;
      t.emplace_back(i, i, (a == 0 || a == n - 1 ? 1.0 : 2.0) + shift + 0.1 * d);
      if (a + 1 < n) {
        t.emplace_back(i, i + 3, -1.0);
        t.emplace_back(i + 3, i, -1.0);
      }
    }
  Eigen::SparseMatrix<double> A(3 * n, 3 * n);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

double relative_error_against_dense(const SparseSpdFactor& f, const Eigen::SparseMatrix<double>& A) {
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 2.0);
  const Eigen::VectorXd dense = Eigen::MatrixXd(A).fullPivLu().solve(b);
  return (f.solve(b) - dense).norm() / dense.norm();
}

TEST(SparseSpdFactor, SolvesPositiveDefiniteSystemsByCholesky) {
  SparseSpdFactor f;
  EXPECT_FALSE(f.analysed());
  const Eigen::SparseMatrix<double> A = chain_matrix(40, 0.5);
  ASSERT_TRUE(f.factorize(A));
  EXPECT_TRUE(f.analysed());
  EXPECT_LT(relative_error_against_dense(f, A), 1e-12);
  EXPECT_EQ(f.fallbacks(), 0);
  EXPECT_GE(f.factor_nonzeros(), static_cast<std::size_t>(A.rows()));
  // New values on the same pattern.
  const Eigen::SparseMatrix<double> B = chain_matrix(40, 3.0);
  ASSERT_TRUE(f.factorize(B));
  EXPECT_LT(relative_error_against_dense(f, B), 1e-12);
}

TEST(SparseSpdFactor, IndefiniteSystemsFallBackToLdlt) {
  SparseSpdFactor f;
  // shift -0.05: the chain Laplacian's smallest eigenvalue is 0, so the
  // matrix has negative eigenvalues (and no zero one: it stays solvable).
  const Eigen::SparseMatrix<double> A = chain_matrix(40, -0.05);
  ASSERT_LT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Eigen::MatrixXd(A)).eigenvalues().minCoeff(), 0.0);
  ASSERT_TRUE(f.factorize(A));
  EXPECT_EQ(f.fallbacks(), 1);
  EXPECT_LT(relative_error_against_dense(f, A), 1e-9);
  // Positive definite again: back to the Cholesky factor.
  const Eigen::SparseMatrix<double> B = chain_matrix(40, 1.0);
  ASSERT_TRUE(f.factorize(B));
  EXPECT_EQ(f.fallbacks(), 1);
  EXPECT_LT(relative_error_against_dense(f, B), 1e-12);
}

TEST(SparseSpdFactor, LeavesTheCallingThreadsOpenMpSettingAsItFoundIt) {
  const int before = omp_get_max_active_levels();
  omp_set_max_active_levels(before == 2 ? 3 : 2);
  const int set = omp_get_max_active_levels();
  SparseSpdFactor f;
  const Eigen::SparseMatrix<double> A = chain_matrix(400, 0.5);
  ASSERT_TRUE(f.factorize(A));
  EXPECT_EQ(omp_get_max_active_levels(), set);
  EXPECT_LT(relative_error_against_dense(f, A), 1e-12);
  EXPECT_EQ(omp_get_max_active_levels(), set);
  omp_set_max_active_levels(before);
}

}  // namespace
}  // namespace puncture::comparison
