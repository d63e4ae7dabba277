#include "fem_reference/cholmod_solve.hpp"

#include <Eigen/CholmodSupport>
#include <stdexcept>

namespace vessel::fem {

Eigen::VectorXd solve_spd_cholmod(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& b) {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt(K);
  if (llt.info() != Eigen::Success) {
    throw std::runtime_error(
        "CHOLMOD could not factorise the displacement system: it is not positive definite "
        "(an unconstrained rigid-body motion?)");
  }
  Eigen::VectorXd x = llt.solve(b);
  if (llt.info() != Eigen::Success) throw std::runtime_error("CHOLMOD solve failed");
  return x;
}

}  // namespace vessel::fem
