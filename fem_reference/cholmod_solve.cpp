#include "fem_reference/cholmod_solve.hpp"

#include <Eigen/CholmodSupport>
#include <stdexcept>

#include "meshes/solver_threads.hpp"

namespace vessel::fem {

Eigen::VectorXd solve_spd_cholmod(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& b) {
  return CholmodFactor(K).solve(b);
}

struct CholmodFactor::Impl {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
};

CholmodFactor::CholmodFactor(const Eigen::SparseMatrix<double>& K)
    : impl_(std::make_unique<Impl>()) {
  apply_solver_threads();
  // A matrix that is not positive definite is reported by the exception below (the
  // finite-strain Newton then solves by LU); CHOLMOD's own warning on stderr would only repeat it.
  impl_->llt.cholmod().print = 0;
  impl_->llt.compute(K);
  if (impl_->llt.info() != Eigen::Success) {
    throw std::runtime_error(
        "CHOLMOD could not factorise the displacement system: it is not positive definite "
        "(an unconstrained rigid-body motion?)");
  }
}

CholmodFactor::~CholmodFactor() = default;

Eigen::VectorXd CholmodFactor::solve(const Eigen::VectorXd& b) const {
  apply_solver_threads();
  Eigen::VectorXd x = impl_->llt.solve(b);
  if (impl_->llt.info() != Eigen::Success) throw std::runtime_error("CHOLMOD solve failed");
  return x;
}

}  // namespace vessel::fem
