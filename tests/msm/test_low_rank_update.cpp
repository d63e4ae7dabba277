// LowRankUpdatedSolve against a direct factorisation of the updated matrix (Eigen's simplicial
// LDLᵀ, another code).
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <random>

#include "msm/linalg/low_rank_update.hpp"

namespace vessel::msm {
namespace {

SparseMatrix with_terms(SparseMatrix a, const std::vector<SparseColumn>& u,
                        const std::vector<double>& w) {
  for (std::size_t j = 0; j < u.size(); ++j) {
    for (std::size_t p = 0; p < u[j].rows.size(); ++p) {
      for (std::size_t q = 0; q < u[j].rows.size(); ++q) {
        a.coeffRef(u[j].rows[p], u[j].rows[q]) += w[j] * u[j].values[p] * u[j].values[q];
      }
    }
  }
  return a;
}

TEST(LowRankUpdatedSolve, EqualsTheUpdatedMatrixFactorisedDirectly) {
  // B: a 3D 6-point Laplacian plus a small shift (SPD, 8³ unknowns); twelve 9-entry columns with
  // a stiffness k 100 × B's diagonal, six of them already in A (leaving: −k), six entering (+k),
  // as the contact model's active-set passes change A₀.
  const int n1 = 8, n = n1 * n1 * n1;
  std::vector<Eigen::Triplet<double>> t;
  auto id = [&](int i, int j, int l) { return (i * n1 + j) * n1 + l; };
  for (int i = 0; i < n1; ++i)
    for (int j = 0; j < n1; ++j)
      for (int l = 0; l < n1; ++l) {
        t.emplace_back(id(i, j, l), id(i, j, l), 6.1);
        if (i + 1 < n1)
          t.emplace_back(id(i, j, l), id(i + 1, j, l), -1.0),
              t.emplace_back(id(i + 1, j, l), id(i, j, l), -1.0);
        if (j + 1 < n1)
          t.emplace_back(id(i, j, l), id(i, j + 1, l), -1.0),
              t.emplace_back(id(i, j + 1, l), id(i, j, l), -1.0);
        if (l + 1 < n1)
          t.emplace_back(id(i, j, l), id(i, j, l + 1), -1.0),
              t.emplace_back(id(i, j, l + 1), id(i, j, l), -1.0);
      }
  SparseMatrix b(n, n);
  b.setFromTriplets(t.begin(), t.end());
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> row(0, n - 1);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  const double k = 610.0;
  std::vector<SparseColumn> leaving(6), entering(6);
  for (auto* set : {&leaving, &entering}) {
    for (SparseColumn& u : *set) {
      for (int p = 0; p < 9; ++p) {
        u.rows.push_back(row(rng));
        u.values.push_back(value(rng));
      }
    }
  }
  const SparseMatrix a = with_terms(b, leaving, std::vector<double>(6, k));
  CholmodSolver factor;
  factor.factorize(a);
  LowRankUpdatedSolve update(factor);
  const VectorXd rhs = VectorXd::LinSpaced(n, -1.0, 2.0).array().sin();

  // The entering changes, then every change: the kept solves of the entering columns reused and
  // the leaving ones solved beside them in one block.
  std::vector<int> ids;
  std::vector<SparseColumn> u;
  std::vector<double> w;
  for (int j = 0; j < 6; ++j) ids.push_back(j), u.push_back(leaving[j]), w.push_back(-k);
  for (int j = 0; j < 6; ++j) ids.push_back(6 + j), u.push_back(entering[j]), w.push_back(k);
  for (const bool with_leaving : {false, true}) {
    const std::size_t first = with_leaving ? 0 : 6;
    const std::vector<int> i(ids.begin() + first, ids.end());
    const std::vector<SparseColumn> c(u.begin() + first, u.end());
    const std::vector<double> weights(w.begin() + first, w.end());
    const SparseMatrix updated = with_terms(a, c, weights);
    const Eigen::SimplicialLDLT<SparseMatrix> direct(updated);
    ASSERT_EQ(direct.info(), Eigen::Success);
    const VectorXd truth = direct.solve(rhs);
    const VectorXd x = update.solve(rhs, i, c, weights);
    EXPECT_LT((x - truth).norm(), 1e-10 * truth.norm()) << "leaving terms " << with_leaving;
    EXPECT_LT((updated * x - rhs).norm(), 1e-10 * rhs.norm());
  }
  EXPECT_LT((update.solve(rhs, {}, {}, {}) - factor.solve(rhs)).norm(), 1e-15 * rhs.norm());
}

}  // namespace
}  // namespace vessel::msm
