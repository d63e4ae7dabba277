#pragma once
/// Preconditioned conjugate gradients (Hestenes & Stiefel 1952; Saad 2003, "Iterative Methods for
/// Sparse Linear Systems", Algorithm 9.1) for a symmetric positive-definite sparse matrix, started
/// from the caller's guess (warm start). The iterative alternative to CholmodSolver where a
/// factor is too large to stream within the time budget (implicit-euler-rest-pcg,
/// integrators.hpp).
#include <Eigen/SparseCore>
#include <string>
#include <vector>

#include "msm/form/form.hpp"

namespace vessel::msm {

enum class PcgPreconditioner {
  jacobi,        ///< diag(A)⁻¹
  block_jacobi,  ///< the inverse of each node's 3×3 diagonal block (dofs 3i … 3i+2)
};

/// "jacobi" or "block-jacobi"; InputError otherwise.
PcgPreconditioner parse_pcg_preconditioner(const std::string& name);

struct PcgOptions {
  /// Stop when ‖b − A x‖₂ ≤ tolerance · ‖b‖₂ (the unpreconditioned residual, recomputed from A
  /// at the end so that round-off in the recurrence cannot pass it).
  double tolerance = 1e-6;
  int max_iterations = 10'000;
  PcgPreconditioner preconditioner = PcgPreconditioner::block_jacobi;
};

struct PcgResult {
  int iterations = 0;
  double relative_residual = 0.0;  ///< ‖b − A x‖ / ‖b‖ at the end (0 for b = 0)
  bool converged = false;
  bool negative_curvature = false;  ///< stopped where pᵀAp ≤ 0: A is not positive definite
};

/// The vectors one CG solve works in, kept by a caller that solves often.
struct PcgWorkspace {
  VectorXd r, z, p, q;
};

/// Preconditioned CG on a symmetric operator: `apply(v, out)` sets out = A v, `precondition(r,
/// z)` sets z = M⁻¹ r for a symmetric positive-definite M. Solves A x = b from the x given
/// (resized to zero if its size is wrong) until ‖b − A x‖₂ ≤ tolerance · ‖b‖₂ (the true
/// residual, recomputed from A at the end so that round-off in the recurrence cannot pass it),
/// at most max_iterations; stops early, negative_curvature set, where pᵀAp ≤ 0.
template <class Apply, class Precondition>
PcgResult conjugate_gradients(const Apply& apply, const Precondition& precondition,
                              const VectorXd& b, VectorXd& x, double tolerance, int max_iterations,
                              PcgWorkspace& w) {
  const Eigen::Index n = b.size();
  if (x.size() != n) x = VectorXd::Zero(n);
  PcgResult res;
  const double bnorm = b.norm();
  if (bnorm == 0.0) {
    x.setZero();
    res.converged = true;
    return res;
  }
  const double target = tolerance * bnorm;
  apply(x, w.q);
  w.r = b - w.q;
  double rnorm = w.r.norm();
  precondition(w.r, w.z);
  w.p = w.z;
  double rz = w.r.dot(w.z);
  bool fresh = true;  // r is b − A x computed from A, not from the recurrence
  while (true) {
    if (rnorm <= target) {
      if (fresh) break;
      // Confirm with the true residual (the recurrence drifts by round-off); restart if it fails.
      apply(x, w.q);
      w.r = b - w.q;
      rnorm = w.r.norm();
      fresh = true;
      if (rnorm <= target) break;
      precondition(w.r, w.z);
      w.p = w.z;
      rz = w.r.dot(w.z);
    }
    if (res.iterations >= max_iterations) break;
    apply(w.p, w.q);
    const double pq = w.p.dot(w.q);
    if (!(pq > 0.0)) {  // not positive definite along p (or a breakdown): stop, report
      res.negative_curvature = true;
      break;
    }
    const double alpha = rz / pq;
    x.noalias() += alpha * w.p;
    w.r.noalias() -= alpha * w.q;
    rnorm = w.r.norm();
    fresh = false;
    ++res.iterations;
    precondition(w.r, w.z);
    const double rz_next = w.r.dot(w.z);
    w.p = w.z + (rz_next / rz) * w.p;
    rz = rz_next;
  }
  res.relative_residual = rnorm / bnorm;
  res.converged = rnorm <= target;
  return res;
}

class PcgSolver {
 public:
  /// Keeps A (symmetric, both triangles stored, as `Form::hessian` and `apply_dirichlet` give
  /// it; pass an rvalue to move it in) and builds the preconditioner. std::runtime_error if a
  /// diagonal entry or block is not positive definite.
  void compute(SparseMatrix A, const PcgOptions& options);
  /// Solves A x = b from the x given (resized to zero if its size is wrong). Does not throw on
  /// non-convergence: the caller reads `converged`.
  PcgResult solve(const VectorXd& b, VectorXd& x) const;
  /// y = A x, as Aᵀx (A is symmetric): Eigen then walks the compressed columns as rows, each
  /// entry of y one gathered dot product, without scattered stores.
  void multiply(const VectorXd& x, VectorXd& y) const;
  [[nodiscard]] const PcgOptions& options() const { return options_; }
  [[nodiscard]] Eigen::Index rows() const { return A_.rows(); }
  [[nodiscard]] Eigen::Index nonzeros() const { return A_.nonZeros(); }

 private:
  void precondition(const VectorXd& r, VectorXd& z) const;

  SparseMatrix A_;
  PcgOptions options_;
  VectorXd inverse_diagonal_;  ///< jacobi
  std::vector<double> inverse_blocks_;  ///< block_jacobi: 9 per node, row-major
  mutable PcgWorkspace work_;
};

}  // namespace vessel::msm
