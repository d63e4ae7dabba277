#pragma once
/// Sparse symmetric positive-definite solves with CHOLMOD (through Eigen's CholmodSupport),
/// reusing the symbolic factorisation while the matrix pattern stays the same.
#include <Eigen/CholmodSupport>
#include <memory>

#include "msm/model/form.hpp"

namespace vessel::msm {

class CholmodSolver {
 public:
  CholmodSolver();
  ~CholmodSolver();
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;
  /// Factorises A (symmetric, lower triangle read). The symbolic analysis is done once per
  /// pattern (nonzero count and dimension). If A is not positive definite, retries with
  /// A + μ·max(diag(A), 1e-3·mean|diag(A)|) for growing μ (1e-10 … 1e-2) and records μ; throws std::runtime_error if even
  /// that fails.
  void factorize(const SparseMatrix& A);
  /// Factorises A without regularisation; false if A is not positive definite.
  [[nodiscard]] bool try_factorize(const SparseMatrix& A);
  [[nodiscard]] VectorXd solve(const VectorXd& b) const;
  [[nodiscard]] int symbolic_analyses() const { return analyses_; }
  [[nodiscard]] int numeric_factorisations() const { return factorisations_; }
  [[nodiscard]] double last_regularisation() const { return mu_; }
  /// Wall-clock seconds spent in numeric factorisations (and symbolic analyses) so far.
  [[nodiscard]] double factorisation_seconds() const { return seconds_; }

 private:
  Eigen::CholmodDecomposition<SparseMatrix, Eigen::Lower> llt_;
  Eigen::Index pattern_rows_ = -1;
  Eigen::Index pattern_nonzeros_ = -1;
  int analyses_ = 0;
  int factorisations_ = 0;
  double mu_ = 0.0;
  double seconds_ = 0.0;
};

}  // namespace vessel::msm
