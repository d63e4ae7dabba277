#pragma once
/// What the model terms on four nodes (a tet's volume term, a hinge's bending term) share: the
/// 12×12 blocks of their Hessians, where those blocks go in a fixed sparse pattern (compressed
/// column storage, so each assembly writes values in place), and the per-element projection that
/// keeps Newton's matrix positive semi-definite.
#include <array>
#include <vector>

#include "msm/model/form.hpp"

namespace vessel::msm {

using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

/// The index into pattern.valuePtr() of entry (row, col), or −1 if the pattern lacks it.
int pattern_slot(const SparseMatrix& pattern, int row, int col);

/// The pattern of the diagonal of `dofs` unknowns and every element's 12×12 block (values 0).
SparseMatrix four_node_block_pattern(int dofs, const std::vector<std::array<int, 4>>& elements);

/// For each element, the 144 slots of its 12×12 block in the order node pairs (a, b), then
/// components (i, j): the block's entry (3a + i, 3b + j).
std::vector<int> four_node_block_slots(const SparseMatrix& pattern,
                                       const std::vector<std::array<int, 4>>& elements);

/// Adds block B at the next 144 slots (in four_node_block_slots' order) and advances `slot`.
void add_four_node_block(const Mat12& B, const int*& slot, double* values);

/// B with its negative eigenvalues set to zero (the nearest PSD matrix in the Frobenius norm).
Mat12 psd_projection(const Mat12& B);

}  // namespace vessel::msm
