// block_sparse.hpp: a sparse 3N x 3N matrix whose pattern is the node
// adjacency of a mesh (3 x 3 blocks for every pair of nodes that share an
// element, and the diagonal blocks), for tangent stiffness assembly.
//
// In:  N nodes, the node pairs (a, b) that couple (either order; duplicates
//      allowed).
// Out: NodeBlockMatrix: an Eigen column-major sparse matrix with the full
//      pattern (values zero), add_block(a, b, 3 x 3) in O(log degree),
//      set_zero() keeping the pattern.
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace puncture::comparison {

class NodeBlockMatrix {
 public:
  NodeBlockMatrix() = default;
  NodeBlockMatrix(int node_count, const std::vector<std::pair<int, int>>& coupled_pairs);

  /// values(3a + i, 3b + j) += block(i, j); (a, b) must be in the pattern.
  void add_block(int a, int b, const Eigen::Matrix3d& block);
  void set_zero();
  int node_count() const { return node_count_; }
  /// Neighbours of node b (sorted, b included).
  const std::vector<int>& neighbours(int b) const { return neighbours_[static_cast<std::size_t>(b)]; }

  Eigen::SparseMatrix<double>& matrix() { return matrix_; }
  const Eigen::SparseMatrix<double>& matrix() const { return matrix_; }

 private:
  int node_count_ = 0;
  std::vector<std::vector<int>> neighbours_;
  Eigen::SparseMatrix<double> matrix_;
};

}  // namespace puncture::comparison
