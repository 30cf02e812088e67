// sparse_spd_factor.hpp: the sparse direct solver of the volumetric
// comparison models' implicit integrator (its Newton matrix; the static
// relaxation keeps Eigen's LDL^T, see volumetric_model.hpp).
//
// In:  a sparse symmetric matrix A (n x n, both triangles stored; only the
//      lower one is read), factorised again whenever its values change; its
//      pattern is analysed once (a new pattern needs a new SparseSpdFactor).
// Out: x = A^-1 b (n).
//
// CHOLMOD's supernodal Cholesky A = L L^T (SuiteSparse; fill-reducing
// ordering: the best of AMD and METIS nested dissection): on the
// comparison meshes, whose plan levels couple through the whole disc, a
// factorisation takes about a third of the time of Eigen's simplicial LDL^T.
// CHOLMOD's own OpenMP regions (4 threads as Debian builds it) are switched
// off on the calling thread while it factorises and solves (measured faster
// on 2 cores; see sparse_spd_factor.cpp).
// Where A is not positive definite (a tangent under strong compression, a
// law whose tangent is not exact), Eigen's simplicial LDL^T is used for that
// factorisation instead; factorize() returns false only if that fails too.
#pragma once

#include <cstddef>
#include <memory>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace puncture::comparison {

class SparseSpdFactor {
 public:
  SparseSpdFactor();
  ~SparseSpdFactor();
  SparseSpdFactor(const SparseSpdFactor&) = delete;
  SparseSpdFactor& operator=(const SparseSpdFactor&) = delete;

  /// Factorises A (analysing its pattern on the first call). False if A
  /// could not be factorised.
  bool factorize(const Eigen::SparseMatrix<double>& A);
  /// x = A^-1 b with the last successful factorisation.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;

  bool analysed() const;
  /// Non-zeros of the factor L (for memory estimates).
  std::size_t factor_nonzeros() const;
  /// Factorisations that needed the LDL^T fallback.
  long fallbacks() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace puncture::comparison
