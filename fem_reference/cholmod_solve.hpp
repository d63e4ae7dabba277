#pragma once
/// CHOLMOD's supernodal Cholesky for the symmetric positive definite displacement system, in its
/// own translation unit (no deal.II), fed through Eigen's CHOLMOD interface.
#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace vessel::fem {

/// Solves K x = b for a symmetric positive definite K given in full (both triangles). Throws
/// std::runtime_error if the factorisation fails (K not positive definite).
Eigen::VectorXd solve_spd_cholmod(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& b);

}  // namespace vessel::fem
