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

const VectorXd& LowRankUpdatedSolve::solved_column(int id, const SparseColumn& u) {
  const auto it = solved_.find(id);
  if (it != solved_.end()) return it->second;
  VectorXd dense = VectorXd::Zero(a_.rows());
  for (std::size_t i = 0; i < u.rows.size(); ++i) dense[u.rows[i]] += u.values[i];
  return solved_.emplace(id, a_.solve(dense)).first->second;
}

VectorXd LowRankUpdatedSolve::solve(const VectorXd& b, const std::vector<int>& ids,
                                    const std::vector<SparseColumn>& u,
                                    const std::vector<double>& w) {
  VectorXd x = a_.solve(b);
  const auto r = static_cast<Eigen::Index>(ids.size());
  if (r == 0) return x;
  std::vector<const VectorXd*> z(ids.size());
  for (std::size_t j = 0; j < ids.size(); ++j) z[j] = &solved_column(ids[j], u[j]);
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
