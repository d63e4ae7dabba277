#pragma once
/// Dense eigenvalue helpers for the rod stability and frequency tests (small N only).
#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>
#include <boost/math/tools/roots.hpp>
#include <vector>

namespace vessel::msm::rods::test {

/// Indices of the dofs that are not held and (if `mass` is given) carry mass.
inline std::vector<int> free_dofs(const std::vector<char>& fixed, const Eigen::VectorXd& mass = {}) {
  std::vector<int> free;
  for (int i = 0; i < static_cast<int>(fixed.size()); ++i) {
    if (!fixed[i] && (mass.size() == 0 || mass[i] > 0.0)) free.push_back(i);
  }
  return free;
}

inline Eigen::MatrixXd restrict(const Eigen::SparseMatrix<double>& A, const std::vector<int>& dofs) {
  const Eigen::MatrixXd dense(A);
  Eigen::MatrixXd R(dofs.size(), dofs.size());
  for (std::size_t a = 0; a < dofs.size(); ++a) {
    for (std::size_t b = 0; b < dofs.size(); ++b) R(a, b) = dense(dofs[a], dofs[b]);
  }
  return R;
}

inline double smallest_eigenvalue(const Eigen::SparseMatrix<double>& H, const std::vector<char>& fixed) {
  const Eigen::MatrixXd R = restrict(H, free_dofs(fixed));
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (R + R.transpose()),
                                                        Eigen::EigenvaluesOnly)
      .eigenvalues()[0];
}

/// Smallest λ of K v = λ M v (lumped M) on the free, massive dofs.
inline double smallest_generalised_eigenvalue(const Eigen::SparseMatrix<double>& K,
                                              const Eigen::VectorXd& mass,
                                              const std::vector<char>& fixed) {
  const std::vector<int> dofs = free_dofs(fixed, mass);
  Eigen::MatrixXd R = restrict(K, dofs);
  for (std::size_t a = 0; a < dofs.size(); ++a) {
    for (std::size_t b = 0; b < dofs.size(); ++b) {
      R(a, b) /= std::sqrt(mass[dofs[a]] * mass[dofs[b]]);
    }
  }
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (R + R.transpose()),
                                                        Eigen::EigenvaluesOnly)
      .eigenvalues()[0];
}

/// The root of f between a and b (f changes sign there), to 1e-13 relative.
template <class F>
double find_sign_change(const F& f, double a, double b) {
  boost::math::tools::eps_tolerance<double> tol(44);
  std::uintmax_t iterations = 200;
  const auto r = boost::math::tools::toms748_solve(f, a, b, tol, iterations);
  return 0.5 * (r.first + r.second);
}

}  // namespace vessel::msm::rods::test

namespace vessel::msm::rods::test {

/// An orthonormal basis of the null space of J restricted to `dofs` (columns).
inline Eigen::MatrixXd null_space(const Eigen::SparseMatrix<double>& J, const std::vector<int>& dofs) {
  const Eigen::MatrixXd dense(J);
  Eigen::MatrixXd Jr(dense.rows(), dofs.size());
  for (std::size_t a = 0; a < dofs.size(); ++a) Jr.col(a) = dense.col(dofs[a]);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Jr, Eigen::ComputeFullV);
  const double tol = 1e-12 * svd.singularValues()[0];
  int rank = 0;
  for (Eigen::Index k = 0; k < svd.singularValues().size(); ++k) rank += svd.singularValues()[k] > tol;
  return svd.matrixV().rightCols(static_cast<Eigen::Index>(dofs.size()) - rank);
}

/// Smallest eigenvalue of Zᵀ H Z on the free dofs, Z the null space of the constraints J.
inline double smallest_constrained_eigenvalue(const Eigen::SparseMatrix<double>& H,
                                              const Eigen::SparseMatrix<double>& J,
                                              const std::vector<char>& fixed) {
  const std::vector<int> dofs = free_dofs(fixed);
  const Eigen::MatrixXd Z = null_space(J, dofs);
  const Eigen::MatrixXd R = Z.transpose() * restrict(H, dofs) * Z;
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (R + R.transpose()),
                                                        Eigen::EigenvaluesOnly)
      .eigenvalues()[0];
}

/// Smallest λ of Zᵀ K Z v = λ Zᵀ M Z v (free dofs, Z the null space of J).
inline double smallest_constrained_generalised(const Eigen::SparseMatrix<double>& K,
                                               const Eigen::VectorXd& mass,
                                               const Eigen::SparseMatrix<double>& J,
                                               const std::vector<char>& fixed) {
  const std::vector<int> dofs = free_dofs(fixed);
  const Eigen::MatrixXd Z = null_space(J, dofs);
  Eigen::MatrixXd Kr = Z.transpose() * restrict(K, dofs) * Z;
  Eigen::VectorXd m(dofs.size());
  for (std::size_t a = 0; a < dofs.size(); ++a) m[a] = mass[dofs[a]];
  Eigen::MatrixXd Mr = Z.transpose() * m.asDiagonal() * Z;
  // The inverse problem Mr v = μ Kr v: its largest μ = 1/λ_min is accurate relative to itself,
  // where λ_min of (Kr, Mr) would be lost under the stiff penalty's eigenvalues.
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (Mr + Mr.transpose()),
                                                                0.5 * (Kr + Kr.transpose()),
                                                                Eigen::EigenvaluesOnly);
  return 1.0 / eig.eigenvalues().maxCoeff();
}

}  // namespace vessel::msm::rods::test
