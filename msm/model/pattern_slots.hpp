#pragma once
/// Where a term's Hessian entries go in a fixed sparse pattern (compressed column storage), so
/// that each assembly writes values in place instead of building triplets.
#include <array>
#include <vector>

#include "msm/model/form.hpp"

namespace vessel::msm {

/// The index into pattern.valuePtr() of entry (row, col), or −1 if the pattern lacks it.
int pattern_slot(const SparseMatrix& pattern, int row, int col);

/// For each element of four nodes (a tet, a hinge), the 144 slots of its 12×12 block in the
/// order node pairs (a, b), then components (i, j): the block's entry (3a + i, 3b + j).
std::vector<int> four_node_block_slots(const SparseMatrix& pattern,
                                       const std::vector<std::array<int, 4>>& elements);

}  // namespace vessel::msm
