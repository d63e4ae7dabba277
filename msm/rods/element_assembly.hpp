#pragma once
/// Scatter of per-element energies, gradients and Hessians (from Jet<N>) into global vectors and
/// a sparse matrix with an x-independent pattern; optional projection of each element block onto
/// the positive semi-definite cone.
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>
#include <array>
#include <vector>

#include "msm/rods/jet.hpp"

namespace vessel::msm::rods {

template <int N, bool S>
void scatter_gradient(const Jet<N, S>& e, const std::array<int, N>& dofs, Eigen::VectorXd& g) {
  for (int a = 0; a < N; ++a) g[dofs[a]] += e.g[a];
}

template <int N>
void scatter_hessian(const Jet<N>& e, const std::array<int, N>& dofs, bool project_psd,
                     std::vector<Eigen::Triplet<double>>& triplets) {
  Eigen::Matrix<double, N, N> h = 0.5 * (e.h + e.h.transpose());
  if (project_psd) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig(h);
    Eigen::Matrix<double, N, 1> lambda = eig.eigenvalues().cwiseMax(0.0);
    h = eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
  }
  for (int a = 0; a < N; ++a) {
    for (int b = 0; b < N; ++b) triplets.emplace_back(dofs[a], dofs[b], h(a, b));
  }
}

/// Variables 0..N−1 of a Jet<N> from the entries of x at `dofs` (Second = false: gradients only).
template <int N, bool Second = true>
std::array<Jet<N, Second>, N> jet_inputs(const Eigen::VectorXd& x, const std::array<int, N>& dofs) {
  std::array<Jet<N, Second>, N> q;
  for (int a = 0; a < N; ++a) q[a] = Jet<N, Second>::variable(x[dofs[a]], a);
  return q;
}

template <int N>
std::array<double, N> double_inputs(const Eigen::VectorXd& x, const std::array<int, N>& dofs) {
  std::array<double, N> q;
  for (int a = 0; a < N; ++a) q[a] = x[dofs[a]];
  return q;
}

}  // namespace vessel::msm::rods
