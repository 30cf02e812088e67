// block_sparse.cpp: node-block sparse pattern; see block_sparse.hpp.
#include "puncture/comparison/block_sparse.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace puncture::comparison {

NodeBlockMatrix::NodeBlockMatrix(int node_count, const std::vector<std::pair<int, int>>& pairs)
    : node_count_(node_count), neighbours_(static_cast<std::size_t>(node_count)) {
  if (node_count < 0) throw std::invalid_argument("NodeBlockMatrix: negative node count");
  for (int a = 0; a < node_count; ++a) neighbours_[static_cast<std::size_t>(a)].push_back(a);
  for (const auto& [a, b] : pairs) {
    if (a < 0 || b < 0 || a >= node_count || b >= node_count)
      throw std::invalid_argument("NodeBlockMatrix: node pair (" + std::to_string(a) + ", " + std::to_string(b) +
                                  ") outside [0, " + std::to_string(node_count) + ")");
    neighbours_[static_cast<std::size_t>(a)].push_back(b);
    neighbours_[static_cast<std::size_t>(b)].push_back(a);
  }
  Eigen::Index nnz = 0;
  for (auto& list : neighbours_) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    nnz += 9 * static_cast<Eigen::Index>(list.size());
  }
  const Eigen::Index n = 3 * static_cast<Eigen::Index>(node_count);
  matrix_.resize(n, n);
  Eigen::VectorXi per_column(n);
  for (int b = 0; b < node_count; ++b)
    for (int j = 0; j < 3; ++j)
      per_column[3 * b + j] = 3 * static_cast<int>(neighbours_[static_cast<std::size_t>(b)].size());
  matrix_.reserve(per_column);
  for (int b = 0; b < node_count; ++b)
    for (int j = 0; j < 3; ++j)
      for (int a : neighbours_[static_cast<std::size_t>(b)])
        for (int i = 0; i < 3; ++i) matrix_.insert(3 * a + i, 3 * b + j) = 0.0;
  matrix_.makeCompressed();
  (void)nnz;
}

void NodeBlockMatrix::add_block(int a, int b, const Eigen::Matrix3d& block) {
  const std::vector<int>& list = neighbours_[static_cast<std::size_t>(b)];
  const auto it = std::lower_bound(list.begin(), list.end(), a);
  if (it == list.end() || *it != a)
    throw std::logic_error("NodeBlockMatrix::add_block: node pair outside the pattern");
  const Eigen::Index position = 3 * static_cast<Eigen::Index>(it - list.begin());
  const int* outer = matrix_.outerIndexPtr();
  double* values = matrix_.valuePtr();
  for (int j = 0; j < 3; ++j) {
    double* column = values + outer[3 * b + j] + position;
    column[0] += block(0, j);
    column[1] += block(1, j);
    column[2] += block(2, j);
  }
}

void NodeBlockMatrix::set_zero() {
  std::fill(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros(), 0.0);
}

}  // namespace puncture::comparison
