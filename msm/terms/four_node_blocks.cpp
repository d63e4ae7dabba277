#include "msm/terms/four_node_blocks.hpp"

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

void FourNodeTerm::set_elements(std::vector<std::array<int, 4>> elements) {
  elements_ = std::move(elements);
  pattern_ = four_node_block_pattern(num_dofs(), elements_);
  slots_ = slots_in(pattern_);
}

std::array<Vec3, 4> FourNodeTerm::corners(const VectorXd& x, std::size_t k) const {
  const auto& e = elements_[k];
  return {x.segment<3>(3 * e[0]), x.segment<3>(3 * e[1]), x.segment<3>(3 * e[2]),
          x.segment<3>(3 * e[3])};
}

double FourNodeTerm::energy(const VectorXd& x) const {
  double e = 0.0;
  for (std::size_t k = 0; k < elements_.size(); ++k) e += element_energy(k, corners(x, k));
  return e;
}

void FourNodeTerm::add_gradient(const VectorXd& x, VectorXd& g) const {
  for (std::size_t k = 0; k < elements_.size(); ++k) {
    const Vec12 gk = element_gradient(k, corners(x, k));
    for (int a = 0; a < 4; ++a) g.segment<3>(3 * elements_[k][a]) += gk.segment<3>(3 * a);
  }
}

void FourNodeTerm::gradient(const VectorXd& x, VectorXd& g) const {
  g.setZero(num_dofs());
  add_gradient(x, g);
}

std::vector<int> FourNodeTerm::slots_in(const SparseMatrix& pattern) const {
  return four_node_block_slots(pattern, elements_);
}

void FourNodeTerm::add_hessian(const VectorXd& x, double* values, const std::vector<int>& slots,
                               bool project_psd) const {
  const int* s = slots.data();
  for (std::size_t k = 0; k < elements_.size(); ++k) {
    add_four_node_block(element_hessian(k, corners(x, k), project_psd), s, values);
  }
}

void FourNodeTerm::hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const {
  H = pattern_;
  std::fill(H.valuePtr(), H.valuePtr() + H.nonZeros(), 0.0);
  add_hessian(x, H.valuePtr(), slots_, project_psd);
}

}  // namespace vessel::msm
