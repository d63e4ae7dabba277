#include "msm/solvers/linear_solver.hpp"

#include <chrono>
#include <stdexcept>

namespace vessel::msm {

CholmodSolver::CholmodSolver() {
  llt_.cholmod().print = 0;  // a failed (indefinite) attempt is handled here, not printed
}
CholmodSolver::~CholmodSolver() = default;

namespace {
double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

bool CholmodSolver::try_factorize(const SparseMatrix& A) {
  const double t0 = now();
  if (A.rows() != pattern_rows_ || A.nonZeros() != pattern_nonzeros_) {
    // Supernodal from 1000 unknowns (measured here with OpenBLAS, CPU time of whole static
    // solves: 6.5k-unknown surface model 2.9 vs 8.3 s simplicial, 1.6k: 0.63 vs 0.85 s; with
    // Debian's reference BLAS the crossing was near 10k). Simplicial for the tiny test problems.
    llt_.setMode(A.rows() < 1000 ? Eigen::CholmodSimplicialLLt : Eigen::CholmodSupernodalLLt);
    llt_.analyzePattern(A);
    pattern_rows_ = A.rows();
    pattern_nonzeros_ = A.nonZeros();
    ++analyses_;
  }
  mu_ = 0.0;
  llt_.factorize(A);
  ++factorisations_;
  seconds_ += now() - t0;
  return llt_.info() == Eigen::Success;
}

void CholmodSolver::factorize(const SparseMatrix& A) {
  if (try_factorize(A)) return;
  // Not positive definite (e.g. a surface membrane without transverse stiffness): regularise.
  VectorXd diag = A.diagonal();
  // A dof without stiffness (zero diagonal: e.g. a node between compressed springs, whose
  // transverse stiffness the projection removed) gets a shift relative to the mean diagonal.
  const double floor = 1e-3 * diag.cwiseAbs().mean() + 1e-300;
  for (double mu = 1e-10; mu <= 1e-2; mu *= 10.0) {
    SparseMatrix R = A;
    for (Eigen::Index i = 0; i < R.rows(); ++i) R.coeffRef(i, i) += mu * std::max(diag[i], floor);
    const double t0 = now();
    llt_.factorize(R);
    ++factorisations_;
    seconds_ += now() - t0;
    if (llt_.info() == Eigen::Success) {
      mu_ = mu;
      return;
    }
  }
  throw std::runtime_error("CHOLMOD: the system matrix is not positive definite, even regularised");
}

VectorXd CholmodSolver::solve(const VectorXd& b) const { return llt_.solve(b); }

}  // namespace vessel::msm
