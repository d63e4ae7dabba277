#include "msm/model/four_node_blocks.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>

namespace vessel::msm {

int pattern_slot(const SparseMatrix& pattern, int row, int col) {
  const int* inner = pattern.innerIndexPtr();
  const int* begin = inner + pattern.outerIndexPtr()[col];
  const int* end = inner + pattern.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(begin, end, row);
  return it != end && *it == row ? static_cast<int>(it - inner) : -1;
}

SparseMatrix four_node_block_pattern(int dofs, const std::vector<std::array<int, 4>>& elements) {
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<std::size_t>(dofs) + elements.size() * 144);
  for (int i = 0; i < dofs; ++i) t.emplace_back(i, i, 0.0);
  for (const auto& e : elements)
    for (int a : e)
      for (int b : e)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) t.emplace_back(3 * a + i, 3 * b + j, 0.0);
  SparseMatrix pattern(dofs, dofs);
  pattern.setFromTriplets(t.begin(), t.end());
  pattern.makeCompressed();
  return pattern;
}

std::vector<int> four_node_block_slots(const SparseMatrix& pattern,
                                       const std::vector<std::array<int, 4>>& elements) {
  std::vector<int> slots;
  slots.reserve(elements.size() * 144);
  for (const auto& e : elements)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            slots.push_back(pattern_slot(pattern, 3 * e[a] + i, 3 * e[b] + j));
          }
  return slots;
}

void add_four_node_block(const Mat12& B, const int*& slot, double* values) {
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) values[*slot++] += B(3 * a + i, 3 * b + j);
}

Mat12 psd_projection(const Mat12& B) {
  const Eigen::SelfAdjointEigenSolver<Mat12> eig(B);
  const Vec12 lambda = eig.eigenvalues().cwiseMax(0.0);
  return eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace vessel::msm
