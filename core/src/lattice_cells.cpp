#include "lattice_cells.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <utility>

namespace puncture::detail {

namespace {

/// One round of colour refinement: a node's new colour is its colour and the
/// sorted colours of its neighbours, numbered by first node. Returns the count.
int refine(const HexLattice& lattice, std::vector<int>& colour) {
  const int n = lattice.node_count();
  std::map<std::vector<int>, int> ids;
  std::vector<int> next(n), signature;
  for (int i = 0; i < n; ++i) {
    signature.assign(1, colour[i]);
    for (int k = lattice.neighbour_offsets[i]; k < lattice.neighbour_offsets[i + 1]; ++k)
      signature.push_back(colour[lattice.neighbours[k]]);
    std::sort(signature.begin() + 1, signature.end());
    next[i] = ids.emplace(signature, static_cast<int>(ids.size())).first->second;
  }
  colour.swap(next);
  return static_cast<int>(ids.size());
}

}  // namespace

LatticeCells equitable_cells(const HexLattice& lattice) {
  const int n = lattice.node_count();
  LatticeCells cells;
  cells.cell_of.assign(n, 1);
  if (n == 0) return cells;
  cells.cell_of[0] = 0;
  int count = n > 1 ? 2 : 1;
  for (;;) {
    const int refined = refine(lattice, cells.cell_of);
    if (refined == count) break;
    count = refined;
  }
  cells.size.assign(count, 0);
  cells.representative.assign(count, -1);
  for (int i = 0; i < n; ++i) {
    const int a = cells.cell_of[i];
    if (cells.representative[a] < 0) cells.representative[a] = i;
    ++cells.size[a];
  }
  // Equitable: every node of a cell has its representative's neighbour count in every cell.
  std::map<std::pair<int, int>, int> edges;  // (a, b), a < b -> springs
  std::vector<int> counts(count), want(count);
  for (int i = 0; i < n; ++i) {
    const int a = cells.cell_of[i];
    std::fill(counts.begin(), counts.end(), 0);
    for (int k = lattice.neighbour_offsets[i]; k < lattice.neighbour_offsets[i + 1]; ++k) {
      const int b = cells.cell_of[lattice.neighbours[k]];
      ++counts[b];
      if (a < b) ++edges[{a, b}];
    }
    if (i == cells.representative[a]) continue;
    std::fill(want.begin(), want.end(), 0);
    const int r = cells.representative[a];
    for (int k = lattice.neighbour_offsets[r]; k < lattice.neighbour_offsets[r + 1]; ++k)
      ++want[cells.cell_of[lattice.neighbours[k]]];
    if (counts != want) throw std::logic_error("lattice cells: the partition is not equitable");
  }
  for (const auto& [ab, m] : edges) cells.pairs.push_back({ab.first, ab.second, m});
  return cells;
}

}  // namespace puncture::detail
