#pragma once
/// Sparse symmetric positive-definite solves with CHOLMOD (through Eigen's CholmodSupport),
/// reusing the symbolic factorisation while the matrix pattern stays the same.
#include <Eigen/CholmodSupport>
#include <memory>
#include <vector>

#include "meshes/foundation/solver_threads.hpp"
#include "msm/form/form.hpp"

namespace vessel::msm {

// The solvers' threading (set_solver_threads): meshes/foundation/solver_threads.hpp.

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
class SupernodalTreeSolve;  // linear_solver.cpp
}  // namespace detail

class CholmodSolver {
 public:
  CholmodSolver();
  ~CholmodSolver();
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;
  /// Factorises A (symmetric, lower triangle read). The symbolic analysis is done once per
  /// pattern (the same rows and nonzero positions as the last analysed matrix). If A is not
  /// positive definite, retries with A + μ·max(diag(A), 1e-3·mean|diag(A)|) for growing μ (1e-10 …
  /// 1e-2) and records μ; throws std::runtime_error if even that fails.
  void factorize(const SparseMatrix& A);
  /// Factorises A without regularisation; false if A is not positive definite.
  [[nodiscard]] bool try_factorize(const SparseMatrix& A);
  [[nodiscard]] VectorXd solve(const VectorXd& b) const;
  /// x = A⁻¹b into the caller's vector (resized to n). cholmod_solve2 with this solver's kept
  /// solution and workspace arrays: once warmed up no allocation per solve, where Eigen's solve
  /// allocates and frees the solution and CHOLMOD's workspace on every call. Not for concurrent
  /// calls on one solver.
  ///
  /// With solver_threads() ≥ 2 and a supernodal factor of at least parallel_solve_min_entries()
  /// numbers, the two triangular sweeps instead run on that many threads over disjoint subtrees
  /// of the supernodal elimination tree (the top of the tree, where the subtrees meet, on one
  /// thread): CHOLMOD 3 (SuiteSparse 5.12) solves on one thread whatever the setting, and a solve
  /// is bound by reading the factor twice, which two cores do faster than one
  /// (docs/measurements/msm_measurements.md). Same numbers up to rounding.
  void solve_into(const VectorXd& b, VectorXd& x) const;
  /// The smallest factor (numbers stored) solved on several threads; default 4 M (32 MB, beyond
  /// the caches, where the sweeps are bound by memory bandwidth). Below it one thread.
  static void set_parallel_solve_min_entries(double entries);
  [[nodiscard]] static double parallel_solve_min_entries();
  /// Threads the last solve_into used (1: CHOLMOD's own solve).
  [[nodiscard]] int last_solve_threads() const { return last_solve_threads_; }
  /// Solves for several right-hand sides (the columns of B) in one CHOLMOD call.
  [[nodiscard]] Eigen::MatrixXd solve_columns(const Eigen::MatrixXd& B) const;
  /// Numbers stored in the factor L (supernodal: with the zeros of supernode amalgamation), what
  /// each triangular sweep of a solve reads; 0 before the first analysis.
  [[nodiscard]] double factor_entries() const;
  /// Floating-point operations of one numeric factorisation (CHOLMOD's count at the symbolic
  /// analysis); 0 before the first analysis.
  [[nodiscard]] double factor_flops() const { return flops_; }
  [[nodiscard]] int symbolic_analyses() const { return analyses_; }
  [[nodiscard]] int numeric_factorisations() const { return factorisations_; }
  [[nodiscard]] double last_regularisation() const { return mu_; }
  /// The factorised matrix's dimension (−1 before the first factorisation).
  [[nodiscard]] Eigen::Index rows() const { return pattern_rows_; }
  /// Wall-clock seconds spent in numeric factorisations (and symbolic analyses) so far.
  [[nodiscard]] double factorisation_seconds() const { return seconds_; }

 private:
  detail::CholmodFactor llt_;
  mutable cholmod_dense* x_ = nullptr;  ///< cholmod_solve2's solution, kept between solves
  mutable cholmod_dense* y_ = nullptr;  ///< and its workspace
  mutable cholmod_dense* e_ = nullptr;
  /// The parallel sweeps' plan, for the current symbolic factor and thread count (built at the
  /// first parallel solve after an analysis).
  mutable std::unique_ptr<detail::SupernodalTreeSolve> tree_;
  mutable int last_solve_threads_ = 1;
  [[nodiscard]] bool same_pattern(const SparseMatrix& A) const;
  void keep_pattern(const SparseMatrix& A);
  Eigen::Index pattern_rows_ = -1;
  std::vector<SparseMatrix::StorageIndex> pattern_outer_;  ///< the analysed matrix's pattern
  std::vector<SparseMatrix::StorageIndex> pattern_inner_;
  int analyses_ = 0;
  int factorisations_ = 0;
  double flops_ = 0.0;
  double mu_ = 0.0;
  double seconds_ = 0.0;
};

}  // namespace vessel::msm
