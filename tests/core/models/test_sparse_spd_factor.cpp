// SparseSpdFactor (sparse_spd_factor.hpp): solutions against a dense solve of
// the same system, positive definite (CHOLMOD) and indefinite (the LDL^T
// fallback), refactorisation with new values on the analysed pattern; the
// calling thread's OpenMP setting is the same after a factorisation and a
// solve as before (CHOLMOD's regions are switched off only while it works).
// GammaFactorPool: which kept factorisation a gamma gets (the nearest within
// the reuse factor), the least recently used one replaced when full, clear()
// and a failed factorisation leave none behind.
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdlib>
#include <string>

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

TEST(SparseSpdFactor, SolvesA3dGridWhoseFactorHasLargeSupernodes) {
  // The 7-point Laplacian of a 14^3 grid, 3 dofs per node, plus 0.01 I: its
  // nested-dissection factor has dense separator blocks (the supernodal
  // factorisation's), solved in the factor's simplicial form; the residual
  // of several right-hand sides, and again after new values.
  const int n = 14;
  auto node = [n](int i, int j, int k) { return (i * n + j) * n + k; };
  auto grid = [&](double shift) {
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) {
          const int a = node(i, j, k);
          const int nb[3][3] = {{i + 1, j, k}, {i, j + 1, k}, {i, j, k + 1}};
          for (int d = 0; d < 3; ++d) t.emplace_back(3 * a + d, 3 * a + d, 6.0 + shift);
          for (const auto& m : nb) {
            if (m[0] >= n || m[1] >= n || m[2] >= n) continue;
            const int b = node(m[0], m[1], m[2]);
            for (int d = 0; d < 3; ++d) {
              t.emplace_back(3 * a + d, 3 * b + d, -1.0);
              t.emplace_back(3 * b + d, 3 * a + d, -1.0);
            }
          }
        }
    Eigen::SparseMatrix<double> A(3 * n * n * n, 3 * n * n * n);
    A.setFromTriplets(t.begin(), t.end());
    return A;
  };
  SparseSpdFactor f;
  for (const double shift : {0.01, 2.0}) {
    const Eigen::SparseMatrix<double> A = grid(shift);
    ASSERT_TRUE(f.factorize(A));
    EXPECT_EQ(f.fallbacks(), 0);
    EXPECT_GT(f.factor_nonzeros(), static_cast<std::size_t>(20 * A.rows()));  // fill-in: not a chain
    for (int seed = 1; seed <= 3; ++seed) {
      std::srand(static_cast<unsigned>(seed));
      const Eigen::VectorXd b = Eigen::VectorXd::Random(A.rows());
      const Eigen::VectorXd x = f.solve(b);
      EXPECT_LT((A * x - b).norm() / b.norm(), 1e-12) << "shift " << shift << ", seed " << seed;
    }
  }
}

TEST(SparseSpdFactor, ModelRunsGoOneAtATimeOnlyOnABlasThatIsNotSafeFromTwoThreads) {
  EXPECT_NE(concurrent_solver_limit_for("openblas-serial").find("not safe to call from two threads"), std::string::npos);
  EXPECT_EQ(concurrent_solver_limit_for("reference BLAS"), "");
  EXPECT_EQ(concurrent_solver_limit_for("openblas-pthread"), "");
  EXPECT_EQ(concurrent_solver_limit_for(""), "");
  // This process's BLAS decides: two threads unless it is the serial OpenBLAS.
  EXPECT_EQ(concurrent_solver_threads(2), concurrent_solver_limit().empty() ? 2 : 1);
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

/// The Newton-matrix family of a chain: I + gamma^2 K (K the chain Laplacian).
Eigen::SparseMatrix<double> newton_matrix(double gamma) {
  Eigen::SparseMatrix<double> A = chain_matrix(30, 0.0) * (gamma * gamma);
  for (int i = 0; i < A.rows(); ++i) A.coeffRef(i, i) += 1.0;
  return A;
}

TEST(GammaFactorPool, GivesTheNearestKeptFactorisationWithinTheReuseFactor) {
  GammaFactorPool pool(5.0, 2);
  EXPECT_EQ(pool.find(1.0), nullptr);
  const SparseSpdFactor* one = pool.factorize(1.0, newton_matrix(1.0));
  ASSERT_NE(one, nullptr);
  EXPECT_LT(relative_error_against_dense(*one, newton_matrix(1.0)), 1e-12);
  EXPECT_EQ(pool.find(4.9), one);
  EXPECT_EQ(pool.find(0.21), one);
  EXPECT_EQ(pool.find(5.1), nullptr);
  EXPECT_EQ(pool.find(0.19), nullptr);
  const SparseSpdFactor* four = pool.factorize(4.0, newton_matrix(4.0));
  ASSERT_NE(four, nullptr);
  EXPECT_NE(four, one);
  EXPECT_LT(relative_error_against_dense(*four, newton_matrix(4.0)), 1e-12);
  EXPECT_EQ(pool.find(2.5), four);  // ratio 1.6 to 4, 2.5 to 1
  EXPECT_EQ(pool.find(1.5), one);
  // Full (capacity 2): the least recently used (4, last found before 1.5) is replaced.
  const SparseSpdFactor* hundred = pool.factorize(100.0, newton_matrix(100.0));
  ASSERT_NE(hundred, nullptr);
  EXPECT_EQ(hundred, four);  // its slot
  EXPECT_EQ(pool.find(1.0), one);
  EXPECT_EQ(pool.find(4.0), one);  // 4 is gone: 1 is within the factor
  EXPECT_EQ(pool.find(90.0), hundred);
  EXPECT_LT(relative_error_against_dense(*pool.find(100.0), newton_matrix(100.0)), 1e-12);
}

TEST(GammaFactorPool, ClearAndFailedFactorisationsLeaveNoneBehind) {
  GammaFactorPool pool(5.0, 3);
  ASSERT_NE(pool.factorize(1.0, newton_matrix(1.0)), nullptr);
  const std::size_t memory = pool.factor_nonzeros();
  EXPECT_GT(memory, 0u);
  pool.clear();
  EXPECT_EQ(pool.find(1.0), nullptr);
  EXPECT_EQ(pool.factor_nonzeros(), memory);  // the slot keeps its memory for the next one
  // A singular matrix (a zero row and column): neither Cholesky nor LDL^T.
  Eigen::SparseMatrix<double> singular = newton_matrix(2.0);
  for (Eigen::Index j = 0; j < singular.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(singular, j); it; ++it)
      if (it.row() == 0 || it.col() == 0) it.valueRef() = 0.0;
  EXPECT_EQ(pool.factorize(2.0, singular), nullptr);
  EXPECT_EQ(pool.find(2.0), nullptr);
  EXPECT_THROW(GammaFactorPool(1.0, 2), std::invalid_argument);
  EXPECT_THROW(GammaFactorPool(5.0, 0), std::invalid_argument);
}

}  // namespace
}  // namespace puncture::comparison
