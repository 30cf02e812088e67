#include "fixed_pattern_ldlt.hpp"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace puncture::detail {

void FixedPatternLdlt::analyse(int n, const std::vector<std::pair<int, int>>& lower_entries) {
  if (n < 1) throw std::invalid_argument("FixedPatternLdlt: size must be >= 1");
  n_ = n;
  // A diagonally dominant matrix of the pattern gives Eigen's ordering and the symbolic pattern of L
  // (Eigen stores every symbolic entry of L, zero or not).
  std::vector<int> degree(n, 0);
  std::vector<bool> has_diagonal(n, false);
  for (const auto& [r, c] : lower_entries) {
    if (r < c || r < 0 || r >= n || c < 0) throw std::invalid_argument("FixedPatternLdlt: entry outside the lower triangle");
    if (r == c) has_diagonal[r] = true;
    else ++degree[r], ++degree[c];
  }
  for (int i = 0; i < n; ++i)
    if (!has_diagonal[i]) throw std::invalid_argument("FixedPatternLdlt: every diagonal entry must be in the pattern");
  std::vector<Eigen::Triplet<double>> t;
  for (const auto& [r, c] : lower_entries) {
    if (r == c) t.emplace_back(r, r, degree[r] + 1.0);
    else t.emplace_back(r, c, -1.0), t.emplace_back(c, r, -1.0);
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(A);
  if (ldlt.info() != Eigen::Success) throw std::runtime_error("FixedPatternLdlt: symbolic analysis failed");
  perm_.resize(n);
  for (int k = 0; k < n; ++k) perm_[k] = ldlt.permutationP().indices()[k];

  Eigen::SparseMatrix<double> Lm = ldlt.matrixL();
  Lm.makeCompressed();
  l_col_start_.assign(1, 0);
  l_row_.clear();
  std::vector<std::vector<std::pair<int, int>>> row_pattern(n);  // row k: (column i, position)
  for (int j = 0; j < n; ++j) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(Lm, j); it; ++it)
      if (it.row() > j) {
        row_pattern[it.row()].push_back({j, static_cast<int>(l_row_.size())});
        l_row_.push_back(static_cast<int>(it.row()));
      }
    l_col_start_.push_back(static_cast<int>(l_row_.size()));
  }
  for (int j = 0; j < n; ++j)
    if (!std::is_sorted(l_row_.begin() + l_col_start_[j], l_row_.begin() + l_col_start_[j + 1]))
      throw std::runtime_error("FixedPatternLdlt: the rows of a column of L are not ascending");
  l_val_.assign(l_row_.size(), 0.0);
  l_rowpat_start_.assign(1, 0);
  l_rowpat_col_.clear();
  l_rowpat_pos_.clear();
  for (int k = 0; k < n; ++k) {
    std::sort(row_pattern[k].begin(), row_pattern[k].end());
    for (const auto& [i, p] : row_pattern[k]) l_rowpat_col_.push_back(i), l_rowpat_pos_.push_back(p);
    l_rowpat_start_.push_back(static_cast<int>(l_rowpat_col_.size()));
  }

  // A's entries in the permuted lower triangle, grouped by permuted row.
  std::vector<std::vector<std::pair<int, int>>> a_rows(n);  // row k: (column i <= k, entry e)
  for (std::size_t e = 0; e < lower_entries.size(); ++e) {
    const int pr = perm_[lower_entries[e].first], pc = perm_[lower_entries[e].second];
    a_rows[std::max(pr, pc)].push_back({std::min(pr, pc), static_cast<int>(e)});
  }
  a_row_start_.assign(1, 0);
  a_col_.clear();
  a_entry_.clear();
  for (int k = 0; k < n; ++k) {
    for (const auto& [i, e] : a_rows[k]) a_col_.push_back(i), a_entry_.push_back(e);
    a_row_start_.push_back(static_cast<int>(a_col_.size()));
  }
  d_.assign(n, 0.0);
  y_.assign(n, 0.0);
}

bool FixedPatternLdlt::factorize(const double* values) {
  // Row k of L solves L(0:k, 0:k) D l = A(0:k, k): y holds A's row k, then the
  // columns i of row k's pattern are eliminated in ascending order.
  for (int k = 0; k < n_; ++k) {
    for (int q = a_row_start_[k]; q < a_row_start_[k + 1]; ++q) y_[a_col_[q]] += values[a_entry_[q]];
    double d = y_[k];
    y_[k] = 0.0;
    for (int q = l_rowpat_start_[k]; q < l_rowpat_start_[k + 1]; ++q) {
      const int i = l_rowpat_col_[q];
      const int p_ki = l_rowpat_pos_[q];
      const double yi = y_[i];
      y_[i] = 0.0;
      for (int p = l_col_start_[i]; p < p_ki; ++p) y_[l_row_[p]] -= l_val_[p] * yi;
      const double l_ki = yi / d_[i];
      d -= l_ki * yi;
      l_val_[p_ki] = l_ki;
    }
    if (!(d > 0.0) || !std::isfinite(d)) {
      std::fill(y_.begin(), y_.end(), 0.0);
      return false;
    }
    d_[k] = d;
  }
  return true;
}

void FixedPatternLdlt::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  for (int k = 0; k < n_; ++k) x[perm_[k]] = b[k];
  for (int j = 0; j < n_; ++j) {
    const double xj = x[j];
    for (int p = l_col_start_[j]; p < l_col_start_[j + 1]; ++p) x[l_row_[p]] -= l_val_[p] * xj;
  }
  for (int j = 0; j < n_; ++j) x[j] /= d_[j];
  for (int j = n_ - 1; j >= 0; --j) {
    double s = x[j];
    for (int p = l_col_start_[j]; p < l_col_start_[j + 1]; ++p) s -= l_val_[p] * x[l_row_[p]];
    x[j] = s;
  }
  // x now holds P x_true: undo the permutation in y_ (scratch) and copy back.
  for (int k = 0; k < n_; ++k) y_[k] = x[perm_[k]];
  for (int k = 0; k < n_; ++k) x[k] = y_[k];
  std::fill(y_.begin(), y_.end(), 0.0);
}

}  // namespace puncture::detail
