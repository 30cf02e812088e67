// sparse_spd_factor.hpp: the sparse direct solver of the volumetric
// comparison models' implicit integrator (its Newton matrix, and the static
// relaxation after a contact jump; the quasi-static mode keeps Eigen's LDL^T,
// see volumetric_model.hpp), and the pool of its factorisations by gamma.
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
// L is then turned into CHOLMOD's simplicial form for the solves (one
// right-hand side each: the integrator's preconditioner), which sweep L's
// columns instead of calling a dense triangular solve and matrix-vector
// product (BLAS level 2) per supernode.
// CHOLMOD's own OpenMP regions (4 threads as Debian builds it) are switched
// off on the calling thread while it factorises and solves (measured faster
// on 2 cores; see sparse_spd_factor.cpp).
// Where A is not positive definite (a tangent under strong compression, a
// law whose tangent is not exact), Eigen's simplicial LDL^T is used for that
// factorisation instead; factorize() returns false only if that fails too.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace puncture::comparison {

/// Threads of this process that may factorise and solve at the same time
/// (the comparison's model runs side by side): `wanted`, or 1 when the BLAS
/// loaded is Debian's serial OpenBLAS (openblas-serial), built without locks
/// around its work buffers: with two threads calling it the volumetric
/// joint-identification test gave a different fit in 3 of 27 runs, never
/// with the reference BLAS or the threaded OpenBLAS (results/comparison/README.md).
int concurrent_solver_threads(int wanted);
/// Why concurrent_solver_threads limits to 1 (empty when it does not): that
/// of the loaded BLAS, and that of a BLAS named as io::blas_library() names it.
std::string concurrent_solver_limit();
std::string concurrent_solver_limit_for(const std::string& blas_library);

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

/// Factorisations of a one-parameter family of matrices A(gamma), kept for
/// several gamma: the implicit integrator's Newton matrix
/// (1 + gamma alpha) M + (gamma^2 + gamma beta) K, whose gamma (the BDF step
/// times its coefficient) ramps up over several decades after every restart
/// (a contact change, a puncture) and falls again after failed steps, passing
/// the same values again and again. A factorisation made with a gamma within
/// `reuse_factor` of the one asked for is used as the preconditioner (the
/// preconditioned spectrum stays within [1/f^2, f^2]; GMRES absorbs the
/// rest).
///
/// In:  gamma > 0 (s) and, to factorise, A(gamma) (as SparseSpdFactor).
/// Out: a factorisation, or nullptr. At most `capacity` are kept (the least
///      recently used is replaced); clear() drops them all (a new tangent or
///      mesh) and keeps each slot's pattern analysis and memory.
class GammaFactorPool {
 public:
  GammaFactorPool(double reuse_factor, int capacity);
  /// The kept factorisation whose gamma is nearest this one (in ratio),
  /// if within the reuse factor; nullptr otherwise.
  const SparseSpdFactor* find(double gamma);
  /// Factorises A(gamma) into a free slot or the least recently used one;
  /// nullptr if A could not be factorised (that slot is then free).
  const SparseSpdFactor* factorize(double gamma, const Eigen::SparseMatrix<double>& A);
  void clear();
  /// Non-zeros of every slot's factor (the pool's memory, kept after clear()).
  std::size_t factor_nonzeros() const;
  /// Factorisations that needed the LDL^T fallback, over every slot.
  long fallbacks() const;

 private:
  struct Slot {
    SparseSpdFactor factor;
    double gamma = 0.0;
    bool valid = false;
    long last_use = 0;
  };
  double log_reuse_;
  std::size_t capacity_;
  long uses_ = 0;
  std::vector<std::unique_ptr<Slot>> slots_;
};

}  // namespace puncture::comparison
