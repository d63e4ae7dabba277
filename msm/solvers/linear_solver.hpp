#pragma once
/// Sparse symmetric positive-definite solves with CHOLMOD (through Eigen's CholmodSupport),
/// reusing the symbolic factorisation while the matrix pattern stays the same.
#include <Eigen/CholmodSupport>
#include <memory>

#include "meshes/solver_threads.hpp"
#include "msm/model/form.hpp"

namespace vessel::msm {

// The solvers' threading (set_solver_threads): meshes/solver_threads.hpp.

namespace detail {
/// Eigen's CHOLMOD wrapper, opened up for cholmod_solve2 (the factor and the common object are
/// protected members of Eigen::CholmodBase).
class CholmodFactor : public Eigen::CholmodDecomposition<SparseMatrix, Eigen::Lower> {
 public:
  [[nodiscard]] cholmod_factor* factor() const { return m_cholmodFactor; }
  [[nodiscard]] cholmod_common& common() const {
    return const_cast<CholmodFactor*>(this)->cholmod();  // Eigen's accessor is non-const only
  }
};
}  // namespace detail

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
  /// x = A⁻¹b into the caller's vector (resized to n). cholmod_solve2 with this solver's kept
  /// solution and workspace arrays: once warmed up no allocation per solve, where Eigen's solve
  /// allocates and frees the solution and CHOLMOD's workspace on every call. Not for concurrent
  /// calls on one solver.
  void solve_into(const VectorXd& b, VectorXd& x) const;
  /// Solves for several right-hand sides (the columns of B) in one CHOLMOD call.
  [[nodiscard]] Eigen::MatrixXd solve_columns(const Eigen::MatrixXd& B) const;
  /// Numbers stored in the factor L (supernodal: with the zeros of supernode amalgamation), what
  /// each triangular sweep of a solve reads; 0 before the first analysis.
  [[nodiscard]] double factor_entries() const;
  [[nodiscard]] int symbolic_analyses() const { return analyses_; }
  [[nodiscard]] int numeric_factorisations() const { return factorisations_; }
  [[nodiscard]] double last_regularisation() const { return mu_; }
  /// Wall-clock seconds spent in numeric factorisations (and symbolic analyses) so far.
  [[nodiscard]] double factorisation_seconds() const { return seconds_; }

 private:
  detail::CholmodFactor llt_;
  mutable cholmod_dense* x_ = nullptr;  ///< cholmod_solve2's solution, kept between solves
  mutable cholmod_dense* y_ = nullptr;  ///< and its workspace
  mutable cholmod_dense* e_ = nullptr;
  Eigen::Index pattern_rows_ = -1;
  Eigen::Index pattern_nonzeros_ = -1;
  int analyses_ = 0;
  int factorisations_ = 0;
  double mu_ = 0.0;
  double seconds_ = 0.0;
};

}  // namespace vessel::msm
