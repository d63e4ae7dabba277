#include "msm/linalg/low_rank_update.hpp"

#include <Eigen/LU>
#include <stdexcept>

namespace vessel::msm {

namespace {

double dot(const SparseColumn& u, const VectorXd& v) {
  double s = 0.0;
  for (std::size_t i = 0; i < u.rows.size(); ++i) s += u.values[i] * v[u.rows[i]];
  return s;
}

}  // namespace

void LowRankUpdatedSolve::solve_new_columns(const std::vector<int>& ids,
                                            const std::vector<SparseColumn>& u) {
  std::vector<std::size_t> fresh;
  for (std::size_t j = 0; j < ids.size(); ++j) {
    if (!solved_.contains(ids[j])) fresh.push_back(j);
  }
  if (fresh.empty()) return;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(a_.rows(), static_cast<Eigen::Index>(fresh.size()));
  for (std::size_t k = 0; k < fresh.size(); ++k) {
    const SparseColumn& column = u[fresh[k]];
    for (std::size_t i = 0; i < column.rows.size(); ++i) {
      dense(column.rows[i], static_cast<Eigen::Index>(k)) += column.values[i];
    }
  }
  // One solve for every new column: the factor is read once for all of them, where a solve per
  // column reads it per column (a large factor's solve is bound by reading it).
  const Eigen::MatrixXd z = a_.solve_columns(dense);
  for (std::size_t k = 0; k < fresh.size(); ++k) {
    solved_.emplace(ids[fresh[k]], z.col(static_cast<Eigen::Index>(k)));
  }
}

VectorXd LowRankUpdatedSolve::solve(const VectorXd& b, const std::vector<int>& ids,
                                    const std::vector<SparseColumn>& u,
                                    const std::vector<double>& w) {
  VectorXd x = a_.solve(b);
  const auto r = static_cast<Eigen::Index>(ids.size());
  if (r == 0) return x;
  solve_new_columns(ids, u);
  std::vector<const VectorXd*> z(ids.size());
  for (std::size_t j = 0; j < ids.size(); ++j) z[j] = &solved_.at(ids[j]);
  Eigen::MatrixXd capacitance(r, r);
  VectorXd t(r);
  for (Eigen::Index i = 0; i < r; ++i) {
    const SparseColumn& ui = u[static_cast<std::size_t>(i)];
    t[i] = dot(ui, x);
    for (Eigen::Index j = 0; j < r; ++j)
      capacitance(i, j) = dot(ui, *z[static_cast<std::size_t>(j)]);
    capacitance(i, i) += 1.0 / w[static_cast<std::size_t>(i)];
  }
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(capacitance);
  if (!lu.isInvertible()) {
    throw std::runtime_error("low-rank update: the updated matrix is singular");
  }
  const VectorXd c = lu.solve(t);
  for (Eigen::Index j = 0; j < r; ++j) x -= c[j] * *z[static_cast<std::size_t>(j)];
  return x;
}

}  // namespace vessel::msm
