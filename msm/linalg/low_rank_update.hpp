#pragma once
/// Solves with a sparse symmetric matrix changed by a few rank-one terms, from the factor of the
/// unchanged matrix, by the Sherman–Morrison–Woodbury identity (Golub & Van Loan, Matrix
/// Computations, 4th ed., §2.1.4):
///   (A + U W Uᵀ)⁻¹ b = y − Z (W⁻¹ + UᵀZ)⁻¹ Uᵀ y,   y = A⁻¹ b,  Z = A⁻¹ U,  W = diag(w_j).
/// Each column u_j is sparse (a few rows) and named by an id; A⁻¹u_j is solved once per id and
/// kept, so the passes of an active-set iteration, whose changes from A are drawn from one set of
/// columns, cost one solve with the factor for a pass's new columns together (one sweep of the
/// factor for all of them) and a dense r × r system each.
#include <map>
#include <vector>

#include "msm/linalg/linear_solver.hpp"

namespace vessel::msm {

/// One sparse column u: its nonzero rows and their values.
struct SparseColumn {
  std::vector<int> rows;
  std::vector<double> values;
};

class LowRankUpdatedSolve {
 public:
  /// `a` holds A's factor; it must outlive this object and stay factorised as it was.
  explicit LowRankUpdatedSolve(const CholmodSolver& a) : a_(a) {}
  /// x = (A + Σ_j w_j u_j u_jᵀ)⁻¹ b over the columns given (`ids[j]` names `u[j]` for as long as
  /// this object lives; w_j ≠ 0). std::runtime_error if the capacitance W⁻¹ + UᵀZ is singular
  /// (the updated matrix is).
  [[nodiscard]] VectorXd solve(const VectorXd& b, const std::vector<int>& ids,
                               const std::vector<SparseColumn>& u, const std::vector<double>& w);

 private:
  /// A⁻¹u_j for each column not solved yet, in one solve with several right-hand sides.
  void solve_new_columns(const std::vector<int>& ids, const std::vector<SparseColumn>& u);
  const CholmodSolver& a_;
  std::map<int, VectorXd> solved_;
};

}  // namespace vessel::msm
