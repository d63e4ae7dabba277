#include "msm/dynamics/natural_frequencies.hpp"

#include <Eigen/Eigenvalues>
#include <Spectra/SymEigsShiftSolver.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "meshes/foundation/errors.hpp"
#include "msm/linalg/linear_solver.hpp"

namespace vessel::msm {

namespace {

/// y = (A − σI)⁻¹ x = S⁻¹ (K − σM)⁻¹ S⁻¹ x with S = M^{-1/2}, i.e. sqrt_mass ∘ (K − σM)⁻¹
/// (sqrt_mass ∘ x): Spectra's shift-invert operator. The factorisation is made by the caller for
/// the one shift used (set_shift only checks it is that shift).
struct ShiftInvertOp {
  using Scalar = double;
  const CholmodSolver* solver;
  const VectorXd* sqrt_mass;
  double sigma;
  [[nodiscard]] Eigen::Index rows() const { return sqrt_mass->size(); }
  [[nodiscard]] Eigen::Index cols() const { return sqrt_mass->size(); }
  void set_shift(const double& s) {
    if (s != sigma) throw std::logic_error("natural_frequencies: factorised for another shift");
  }
  void perform_op(const double* x, double* y) const {
    const VectorXd b = sqrt_mass->cwiseProduct(Eigen::Map<const VectorXd>(x, rows()));
    Eigen::Map<VectorXd>(y, rows()) = sqrt_mass->cwiseProduct(solver->solve(b));
  }
};

}  // namespace

NaturalFrequencies natural_frequencies(const Problem& p, const NaturalFrequencyOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  NaturalFrequencies out;
  const int n = p.num_dofs();
  std::vector<int> index(static_cast<std::size_t>(n), -1);
  int nf = 0;
  for (int i = 0; i < n; ++i) {
    if (!p.fixed[i]) index[i] = nf++;
  }
  out.free_dofs = nf;
  if (o.count < 1 || o.count >= nf) {
    throw InputError("natural frequencies: expected 1 <= modes < free dofs (" +
                     std::to_string(nf) + "), got " + std::to_string(o.count));
  }
  VectorXd sqrt_mass(nf);
  for (int i = 0; i < n; ++i) {
    if (index[i] < 0) continue;
    if (!(p.mass[i] > 0.0)) {
      throw InputError("natural frequencies: free dof " + std::to_string(i) +
                       " has no positive mass (" + std::to_string(p.mass[i]) + " kg)");
    }
    sqrt_mass[index[i]] = std::sqrt(p.mass[i]);
  }
  // K at rest on the free dofs (exact Hessian: springs and every other term of the Form).
  SparseMatrix K;
  p.form->hessian(p.rest, K, false);
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<std::size_t>(K.nonZeros()));
  double mean_diag = 0.0;  // mean K_ii/m_i: the scale of ω²
  for (int k = 0; k < K.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(K, k); it; ++it) {
      const int i = index[it.row()], j = index[it.col()];
      if (i < 0 || j < 0) continue;
      t.emplace_back(i, j, it.value());
      if (i == j) mean_diag += it.value() / (sqrt_mass[i] * sqrt_mass[i]);
    }
  }
  mean_diag /= nf;
  SparseMatrix Kff(nf, nf);
  Kff.setFromTriplets(t.begin(), t.end());
  const double zero_level = 1e-8 * mean_diag;

  VectorXd lambda;  // ω², ascending, count of them
  Eigen::MatrixXd y;
  if (nf <= o.dense_max_dofs) {
    // A = S K S densely; Eigen sorts the eigenvalues ascending.
    const VectorXd inv = sqrt_mass.cwiseInverse();
    const Eigen::MatrixXd A = inv.asDiagonal() * Eigen::MatrixXd(Kff) * inv.asDiagonal();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (A + A.transpose()));
    lambda = es.eigenvalues().head(o.count);
    y = es.eigenvectors().leftCols(o.count);
  } else {
    out.shift = -o.relative_shift * mean_diag;
    SparseMatrix shifted = Kff;
    for (int i = 0; i < nf; ++i) shifted.coeffRef(i, i) -= out.shift * sqrt_mass[i] * sqrt_mass[i];
    CholmodSolver solver;
    if (!solver.try_factorize(shifted)) {
      throw std::runtime_error(
          "natural frequencies: K - sigma M is not positive definite (sigma = " +
          std::to_string(out.shift) + " (rad/s)^2): the Hessian at rest is not positive "
          "semi-definite");
    }
    ShiftInvertOp op{&solver, &sqrt_mass, out.shift};
    const int ncv = std::min(nf, std::max(2 * o.count + 1, 20));
    Spectra::SymEigsShiftSolver<ShiftInvertOp> eigs(op, o.count, ncv, out.shift);
    eigs.init();
    // Largest |1/(λ − σ)| is the λ nearest σ: the lowest; returned sorted ascending in λ.
    eigs.compute(Spectra::SortRule::LargestMagn, o.max_iterations, o.tolerance,
                 Spectra::SortRule::SmallestAlge);
    if (eigs.info() != Spectra::CompInfo::Successful) {
      throw std::runtime_error("natural frequencies: shift-invert Lanczos (Spectra) did not "
                               "converge in " + std::to_string(o.max_iterations) + " restarts");
    }
    lambda = eigs.eigenvalues();
    y = eigs.eigenvectors();
    out.iterations = static_cast<int>(eigs.num_iterations());
  }
  out.shapes = Eigen::MatrixXd::Zero(n, o.count);
  for (int e = 0; e < o.count; ++e) {
    const double w2 = std::max(lambda[e], 0.0);
    if (lambda[e] <= zero_level) ++out.mechanisms;
    out.omega.push_back(std::sqrt(w2));
    out.frequencies_hz.push_back(std::sqrt(w2) / (2.0 * std::numbers::pi));
    // φ = S y is M-orthonormal when y is orthonormal.
    for (int i = 0; i < n; ++i) {
      if (index[i] >= 0) out.shapes(i, e) = y(index[i], e) / sqrt_mass[index[i]];
    }
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace vessel::msm
