// fixed_pattern_ldlt.hpp (internal to puncture_core): P A P^T = L D L^T of a
// sparse symmetric positive definite n x n matrix A whose pattern stays fixed
// while its values change (the tangent of a nonlinear force mesh).
//
// analyse(n, lower): the pattern, as the (row, col) entries of A's lower
//   triangle (row >= col; every diagonal entry must be listed). The fill-
//   reducing ordering P and the pattern of L come from Eigen's SimplicialLDLT
//   (AMD) once; everything factorize() and solve() need is allocated here.
// factorize(values): values[e] is A's entry for lower entry e (the order given
//   to analyse). Up-looking numeric LDLT on the fixed pattern (the algorithm
//   of Eigen's SimplicialLDLT, Davis 2006 Sec. 4.8), no allocation. Returns
//   false when a pivot is not positive and finite (A not SPD): the factors
//   are then unusable.
// solve(b, x): x = A^-1 b (size n each, distinct), no allocation.
#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

namespace puncture::detail {

class FixedPatternLdlt {
 public:
  void analyse(int n, const std::vector<std::pair<int, int>>& lower_entries);
  bool factorize(const double* values);
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const;
  int size() const { return n_; }

 private:
  int n_ = 0;
  std::vector<int> perm_;  ///< permuted index of original index k: perm_[k]
  // A's lower entries by permuted row k: the entries (k, i), i <= k, of P A P^T.
  std::vector<int> a_row_start_, a_col_, a_entry_;
  // L (strictly lower, unit diagonal) column-wise, rows ascending.
  std::vector<int> l_col_start_, l_row_;
  std::vector<double> l_val_;
  // The pattern of row k of L: columns i < k ascending, with the position of L(k, i) in column i.
  std::vector<int> l_rowpat_start_, l_rowpat_col_, l_rowpat_pos_;
  std::vector<double> d_;
  mutable std::vector<double> y_;
};

}  // namespace puncture::detail
