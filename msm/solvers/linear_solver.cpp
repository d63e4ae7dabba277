#include "msm/solvers/linear_solver.hpp"

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>

#include "meshes/errors.hpp"

namespace vessel::msm {

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

CholmodSolver::CholmodSolver() {
  llt_.cholmod().print = 0;  // a failed (indefinite) attempt is handled here, not printed
}
CholmodSolver::~CholmodSolver() {
  // Before llt_'s destructor finishes the CHOLMOD common object these were allocated with.
  cholmod_free_dense(&x_, &llt_.common());
  cholmod_free_dense(&y_, &llt_.common());
  cholmod_free_dense(&e_, &llt_.common());
}

bool CholmodSolver::try_factorize(const SparseMatrix& A) {
  apply_solver_threads();
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

VectorXd CholmodSolver::solve(const VectorXd& b) const {
  apply_solver_threads();
  return llt_.solve(b);
}

double CholmodSolver::factor_entries() const {
  const cholmod_factor* L = llt_.factor();
  if (L == nullptr) return 0.0;
  return static_cast<double>(L->is_super ? L->xsize : L->nzmax);
}

void CholmodSolver::solve_into(const VectorXd& b, VectorXd& x) const {
  apply_solver_threads();
  cholmod_factor* L = llt_.factor();
  if (L == nullptr || llt_.info() != Eigen::Success) {
    throw std::logic_error("CholmodSolver::solve_into before a successful factorisation");
  }
  if (b.size() != static_cast<Eigen::Index>(L->n)) {
    throw std::invalid_argument("CholmodSolver::solve_into: right-hand side of the wrong size");
  }
  cholmod_dense B{};
  B.nrow = B.d = L->n;
  B.ncol = 1;
  B.nzmax = L->n;
  B.x = const_cast<double*>(b.data());  // read only: CHOLMOD_A does not write B
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  if (!cholmod_solve2(CHOLMOD_A, L, &B, nullptr, &x_, nullptr, &y_, &e_, &llt_.common())) {
    throw std::runtime_error("CHOLMOD: solve failed");
  }
  x = Eigen::Map<const VectorXd>(static_cast<const double*>(x_->x), b.size());
}

Eigen::MatrixXd CholmodSolver::solve_columns(const Eigen::MatrixXd& B) const {
  apply_solver_threads();
  return llt_.solve(B);
}

}  // namespace vessel::msm
