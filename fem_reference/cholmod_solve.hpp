#pragma once
/// CHOLMOD's supernodal Cholesky for the symmetric positive definite displacement system, in its
/// own translation unit (no deal.II), fed through Eigen's CHOLMOD interface.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>

namespace vessel::fem {

/// Solves K x = b for a symmetric positive definite K given in full (both triangles). Throws
/// std::runtime_error if the factorisation fails (K not positive definite).
Eigen::VectorXd solve_spd_cholmod(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& b);

/// As solve_spd_cholmod, with the factor of an earlier call on an identical K (same size,
/// pattern and values, compared exactly) when one is kept, else a new factor that is then kept:
/// the linear references of several loads on one vessel (a scene's contact, another's gravity)
/// factorise once. Keeps the factors of the four matrices used last (each with a copy of its K);
/// thread-safe. Not for matrices that change every call (a Newton tangent).
Eigen::VectorXd solve_spd_cholmod_keeping_factor(const Eigen::SparseMatrix<double>& K,
                                                 const Eigen::VectorXd& b);
/// Frees the kept factors (their memory: gigabytes at the reference levels).
void release_kept_factors();
/// How many solve_spd_cholmod_keeping_factor calls found their factor kept, since the start.
long kept_factor_hits();

/// A CHOLMOD supernodal Cholesky factor kept for repeated solves (the Newmark transient factorises
/// K + 4/dt² M once and reuses it every step).
class CholmodFactor {
 public:
  /// Factorises the SPD matrix K (both triangles stored); std::runtime_error if not SPD.
  explicit CholmodFactor(const Eigen::SparseMatrix<double>& K);
  ~CholmodFactor();
  CholmodFactor(const CholmodFactor&) = delete;
  CholmodFactor& operator=(const CholmodFactor&) = delete;
  [[nodiscard]] Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  /// K X = B for several right-hand sides at once (CHOLMOD's blocked solve: much faster than
  /// one column at a time).
  [[nodiscard]] Eigen::MatrixXd solve_block(const Eigen::MatrixXd& B) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Solves a sequence of SPD systems whose matrices share one sparsity pattern (a Newton method's
/// tangents): CHOLMOD's symbolic analysis (its fill-reducing ordering, METIS or AMD) runs for the
/// first matrix and again only when the pattern changes; each call factorises its own values.
/// At P2 level 0 the analysis was a fifth of a finite-strain Newton iteration.
class CholmodSamePattern {
 public:
  CholmodSamePattern();
  ~CholmodSamePattern();
  CholmodSamePattern(const CholmodSamePattern&) = delete;
  CholmodSamePattern& operator=(const CholmodSamePattern&) = delete;
  /// Solves K x = b for K given in full (both triangles). std::runtime_error if K is not positive
  /// definite (the analysis is kept for the next matrix).
  [[nodiscard]] Eigen::VectorXd solve(const Eigen::SparseMatrix<double>& K,
                                      const Eigen::VectorXd& b);
  /// Symbolic analyses run so far (1 for any number of matrices of one pattern).
  [[nodiscard]] int analyses() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vessel::fem
