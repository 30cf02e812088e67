// sparse_spd_factor.cpp: CHOLMOD supernodal Cholesky (solved in simplicial
// form) with Eigen's simplicial LDL^T as the fallback; see sparse_spd_factor.hpp.
#include "puncture/comparison/sparse_spd_factor.hpp"

#include <omp.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>

#include "puncture/io/provenance.hpp"

namespace puncture::comparison {

namespace {

/// CHOLMOD as Debian builds it (SuiteSparse 5.12, CHOLMOD_OMP_NUM_THREADS 4)
/// runs parts of its supernodal factorisation in OpenMP regions of 4 threads,
/// whatever the machine has. On the 2-core reference machine that costs more
/// than it gains (linear tensor-mass run of the tuned slab, 84
/// factorisations, three pairs of runs on 2026-12-02: 67-83 s with them,
/// 53-62 s without; the same curves; results/comparison/README.md point 7),
/// and more again when two models factorise at once. The regions' thread count is
/// fixed by a clause, so they are switched off (max active levels 0) on the
/// calling thread for the factorisation, and the thread's setting restored.
class SerialOpenMpRegions {
 public:
  SerialOpenMpRegions() : levels_(omp_get_max_active_levels()) { omp_set_max_active_levels(0); }
  ~SerialOpenMpRegions() { omp_set_max_active_levels(levels_); }
  SerialOpenMpRegions(const SerialOpenMpRegions&) = delete;
  SerialOpenMpRegions& operator=(const SerialOpenMpRegions&) = delete;

 private:
  int levels_;
};

}  // namespace

std::string concurrent_solver_limit_for(const std::string& blas_library) {
  return blas_library == "openblas-serial"
             ? "the BLAS is Debian's serial OpenBLAS (openblas-serial), which is not safe to call from two threads at "
               "once: the comparison models run one at a time (the threaded libopenblas0-pthread or the reference "
               "BLAS lets them run two at a time)"
             : "";
}

std::string concurrent_solver_limit() {
  static const std::string reason = concurrent_solver_limit_for(io::blas_library());
  return reason;
}

int concurrent_solver_threads(int wanted) { return concurrent_solver_limit().empty() ? wanted : 1; }

struct SparseSpdFactor::Impl {
  cholmod_common common;
  cholmod_factor* symbolic = nullptr;  ///< the supernodal analysis (no values), copied for each factorisation
  cholmod_factor* factor = nullptr;    ///< the last factorisation, turned simplicial for the solves
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  bool ldlt_analysed = false;
  bool use_ldlt = false;  ///< the last factorisation is the fallback's
  long fallbacks = 0;

  Impl() {
    cholmod_start(&common);
    common.supernodal = CHOLMOD_SUPERNODAL;
    common.final_asis = 1;
    // Not positive definite is an expected outcome here (the fallback
    // follows): no messages from CHOLMOD's error handler.
    common.print = 0;
    common.error_handler = nullptr;
  }
  ~Impl() {
    cholmod_free_factor(&factor, &common);
    cholmod_free_factor(&symbolic, &common);
    cholmod_finish(&common);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
};

SparseSpdFactor::SparseSpdFactor() : impl_(std::make_unique<Impl>()) {}
SparseSpdFactor::~SparseSpdFactor() = default;

bool SparseSpdFactor::factorize(const Eigen::SparseMatrix<double>& A) {
  Impl& s = *impl_;
  const SerialOpenMpRegions serial;
  // A view of A (no copy) whose lower triangle CHOLMOD reads; it does not write to it.
  cholmod_sparse view = Eigen::viewAsCholmod(A);
  view.stype = -1;
  if (!s.symbolic) s.symbolic = cholmod_analyze(&view, &s.common);
  // The supernodal factorisation (dense BLAS kernels on the supernodes), then
  // the same L in simplicial form: a solve with one right-hand side is then
  // two sweeps over L's columns instead of a dense triangular solve and
  // matrix-vector product per supernode (BLAS level 2). A small gain on the
  // default slab with two runs side by side, a loss on the small slab alone
  // (results/comparison/README.md, "Solves in simplicial form").
  cholmod_free_factor(&s.factor, &s.common);
  s.factor = s.symbolic ? cholmod_copy_factor(s.symbolic, &s.common) : nullptr;
  s.use_ldlt = !s.factor || !cholmod_factorize(&view, s.factor, &s.common) || s.common.status != CHOLMOD_OK ||
               s.factor->minor != s.factor->n ||
               !cholmod_change_factor(CHOLMOD_REAL, true, false, true, true, s.factor, &s.common);
  if (!s.use_ldlt) return true;
  cholmod_free_factor(&s.factor, &s.common);
  ++s.fallbacks;
  if (!s.ldlt_analysed) {
    s.ldlt.analyzePattern(A);
    s.ldlt_analysed = true;
  }
  s.ldlt.factorize(A);
  return s.ldlt.info() == Eigen::Success;
}

Eigen::VectorXd SparseSpdFactor::solve(const Eigen::VectorXd& b) const {
  Impl& s = *impl_;
  if (s.use_ldlt) return s.ldlt.solve(b);
  const SerialOpenMpRegions serial;
  cholmod_dense rhs = Eigen::viewAsCholmod(const_cast<Eigen::VectorXd&>(b));
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, s.factor, &rhs, &s.common);
  if (!x) return Eigen::VectorXd::Constant(b.size(), std::numeric_limits<double>::quiet_NaN());
  Eigen::VectorXd out = Eigen::Map<const Eigen::VectorXd>(static_cast<const double*>(x->x), b.size());
  cholmod_free_dense(&x, &s.common);
  return out;
}

bool SparseSpdFactor::analysed() const { return impl_->symbolic != nullptr; }

std::size_t SparseSpdFactor::factor_nonzeros() const {
  if (impl_->use_ldlt) return static_cast<std::size_t>(impl_->ldlt.matrixL().nestedExpression().nonZeros());
  return impl_->factor ? impl_->factor->nzmax : 0;
}

long SparseSpdFactor::fallbacks() const { return impl_->fallbacks; }

GammaFactorPool::GammaFactorPool(double reuse_factor, int capacity)
    : log_reuse_(std::log(reuse_factor)), capacity_(static_cast<std::size_t>(capacity)) {
  if (!(reuse_factor > 1.0) || capacity < 1)
    throw std::invalid_argument("GammaFactorPool: reuse factor must exceed 1 and capacity be at least 1");
}

const SparseSpdFactor* GammaFactorPool::find(double gamma) {
  Slot* best = nullptr;
  double best_distance = log_reuse_;
  for (const auto& slot : slots_) {
    if (!slot->valid) continue;
    const double distance = std::abs(std::log(gamma / slot->gamma));
    if (distance < best_distance) {
      best_distance = distance;
      best = slot.get();
    }
  }
  if (!best) return nullptr;
  best->last_use = ++uses_;
  return &best->factor;
}

const SparseSpdFactor* GammaFactorPool::factorize(double gamma, const Eigen::SparseMatrix<double>& A) {
  Slot* target = nullptr;
  for (const auto& slot : slots_)
    if (!slot->valid) {
      target = slot.get();
      break;
    }
  if (!target && slots_.size() < capacity_) {
    slots_.push_back(std::make_unique<Slot>());
    target = slots_.back().get();
  }
  if (!target) {
    target = slots_.front().get();
    for (const auto& slot : slots_)
      if (slot->last_use < target->last_use) target = slot.get();
  }
  target->valid = target->factor.factorize(A);
  target->gamma = gamma;
  target->last_use = ++uses_;
  return target->valid ? &target->factor : nullptr;
}

void GammaFactorPool::clear() {
  for (const auto& slot : slots_) slot->valid = false;
}

std::size_t GammaFactorPool::factor_nonzeros() const {
  std::size_t n = 0;
  for (const auto& slot : slots_) n += slot->factor.factor_nonzeros();
  return n;
}

long GammaFactorPool::fallbacks() const {
  long n = 0;
  for (const auto& slot : slots_) n += slot->factor.fallbacks();
  return n;
}

}  // namespace puncture::comparison
