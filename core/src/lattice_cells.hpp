// lattice_cells.hpp (internal to puncture_core): the cells of the force
// mesh's lattice on which a stiffening mesh's state stays constant.
//
// The coarsest equitable partition of the lattice graph in which the contact
// node is a cell of its own (colour refinement, Weisfeiler-Leman): every node
// of a cell A has the same number n_AB of neighbours in each cell B. For the
// hexagonal ring lattice loaded at its centre these are the orbits of its
// six-fold rotations and reflections (one cell per node of a twelfth of the
// lattice). A force mesh's step equations treat every node alike (the same
// mass, damping and springs; the needle loads the contact node only), so a
// state that is constant on the cells stays so through a step: every node's
// residual and every Newton step of the step solve are then constant on the
// cells, and the step can be solved on the cells (ForceMesh, stiffening).
//
// Cells are numbered by their first node (node 0 is cell 0); `pairs` lists
// every pair of distinct adjacent cells (a < b) with edges = |A| n_AB =
// |B| n_BA, the number of lattice springs between them.
#pragma once

#include <vector>

#include "puncture/hex_lattice.hpp"

namespace puncture::detail {

struct LatticeCells {
  struct Pair {
    int a = 0, b = 0;  ///< cells, a < b
    int edges = 0;     ///< springs between the two cells
  };
  std::vector<int> cell_of;         ///< per node
  std::vector<int> representative;  ///< per cell: its first node
  std::vector<int> size;            ///< per cell: its number of nodes
  std::vector<Pair> pairs;          ///< adjacent distinct cells, ascending (a, b)
  int count() const { return static_cast<int>(size.size()); }
};

/// The cells of `lattice` (see the header). Throws std::logic_error if the
/// refinement does not end in an equitable partition.
LatticeCells equitable_cells(const HexLattice& lattice);

}  // namespace puncture::detail
