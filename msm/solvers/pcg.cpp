#include "msm/solvers/pcg.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "meshes/foundation/errors.hpp"

namespace vessel::msm {

PcgPreconditioner parse_pcg_preconditioner(const std::string& name) {
  if (name == "jacobi") return PcgPreconditioner::jacobi;
  if (name == "block-jacobi") return PcgPreconditioner::block_jacobi;
  throw InputError("cg preconditioner: expected jacobi or block-jacobi; got '" + name + "'");
}

void PcgSolver::compute(SparseMatrix A, const PcgOptions& options) {
  if (A.rows() != A.cols()) throw std::invalid_argument("PcgSolver: the matrix is not square");
  options_ = options;
  A_ = std::move(A);
  A_.makeCompressed();
  const Eigen::Index n = A_.rows();
  if (options_.preconditioner == PcgPreconditioner::jacobi) {
    inverse_diagonal_ = A_.diagonal();
    for (Eigen::Index i = 0; i < n; ++i) {
      if (!(inverse_diagonal_[i] > 0.0)) {
        throw std::runtime_error("PCG: diagonal entry " + std::to_string(i) +
                                 " is not positive; the matrix is not positive definite");
      }
      inverse_diagonal_[i] = 1.0 / inverse_diagonal_[i];
    }
    return;
  }
  if (n % 3 != 0) throw std::invalid_argument("PcgSolver: block Jacobi needs 3 dofs per node");
  inverse_blocks_.assign(static_cast<std::size_t>(3 * n), 0.0);
  for (Eigen::Index node = 0; node < n / 3; ++node) {
    Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
    for (int a = 0; a < 3; ++a) {
      for (SparseMatrix::InnerIterator it(A_, 3 * node + a); it; ++it) {  // column 3·node + a
        const Eigen::Index c = it.row() - 3 * node;
        if (c >= 0 && c < 3) B(c, a) = it.value();
      }
    }
    const Eigen::LLT<Eigen::Matrix3d> llt(B);
    if (llt.info() != Eigen::Success) {
      throw std::runtime_error("PCG: the 3×3 diagonal block of node " + std::to_string(node) +
                               " is not positive definite");
    }
    const Eigen::Matrix3d inv = llt.solve(Eigen::Matrix3d::Identity());
    for (int a = 0; a < 3; ++a) {
      for (int c = 0; c < 3; ++c) inverse_blocks_[9 * node + 3 * a + c] = inv(a, c);
    }
  }
}

void PcgSolver::multiply(const VectorXd& x, VectorXd& y) const {
  y.noalias() = A_.transpose() * x;
}

void PcgSolver::precondition(const VectorXd& r, VectorXd& z) const {
  if (options_.preconditioner == PcgPreconditioner::jacobi) {
    z = inverse_diagonal_.cwiseProduct(r);
    return;
  }
  z.resize(r.size());
  const double* m = inverse_blocks_.data();
  for (Eigen::Index i = 0; i < r.size(); i += 3, m += 9) {
    const double r0 = r[i], r1 = r[i + 1], r2 = r[i + 2];
    z[i] = m[0] * r0 + m[1] * r1 + m[2] * r2;
    z[i + 1] = m[3] * r0 + m[4] * r1 + m[5] * r2;
    z[i + 2] = m[6] * r0 + m[7] * r1 + m[8] * r2;
  }
}

PcgResult PcgSolver::solve(const VectorXd& b, VectorXd& x) const {
  if (b.size() != A_.rows()) {
    throw std::invalid_argument("PcgSolver::solve: right-hand side of wrong size");
  }
  return conjugate_gradients([this](const VectorXd& v, VectorXd& out) { multiply(v, out); },
                             [this](const VectorXd& r, VectorXd& z) { precondition(r, z); }, b, x,
                             options_.tolerance, options_.max_iterations, work_);
}

}  // namespace vessel::msm
