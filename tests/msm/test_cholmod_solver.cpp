// CholmodSolver's reuse of its symbolic analysis, against Eigen's dense LLᵀ (another code).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "msm/linalg/linear_solver.hpp"

namespace vessel::msm {
namespace {

/// A path Laplacian on n unknowns, shifted, with one extra coupling (a, b): SPD.
SparseMatrix path_with_link(int n, int a, int b) {
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 3.0 + 0.1 * i);
    if (i + 1 < n) t.emplace_back(i, i + 1, -1.0), t.emplace_back(i + 1, i, -1.0);
  }
  t.emplace_back(a, b, -0.5);
  t.emplace_back(b, a, -0.5);
  SparseMatrix m(n, n);
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

TEST(CholmodSolver, AnalysesAgainAMatrixWithTheSameCountButNotTheSamePattern) {
  // Two matrices with the same dimension and nonzero count, their extra link in different
  // places: a factor analysed for the first cannot hold the second's fill.
  const SparseMatrix first = path_with_link(40, 2, 30), second = path_with_link(40, 5, 37);
  ASSERT_EQ(first.nonZeros(), second.nonZeros());
  const VectorXd b = VectorXd::LinSpaced(40, 1.0, 2.0);
  CholmodSolver solver;
  solver.factorize(first);
  solver.factorize(second);
  EXPECT_EQ(solver.symbolic_analyses(), 2);
  const VectorXd expected = Eigen::MatrixXd(second).llt().solve(b);
  EXPECT_LT((solver.solve(b) - expected).norm(), 1e-12 * expected.norm());
  // The same pattern with other values: analysed once more only for the changed pattern.
  SparseMatrix scaled = 2.0 * second;
  solver.factorize(scaled);
  EXPECT_EQ(solver.symbolic_analyses(), 2);
  EXPECT_LT((solver.solve(b) - 0.5 * expected).norm(), 1e-12 * expected.norm());
}

TEST(CholmodSolver, CountsAFactorisationsFlopsAsTheSumOfItsSquaredColumnCounts) {
  // CHOLMOD's count (cholmod_rowcolcounts): Σ_j c_j² over L's column counts c_j. A dense matrix
  // fills completely under any ordering: column counts n, n − 1, …, 1. A path has a fill-free
  // ordering (from its ends, the one AMD finds): counts 2, …, 2, 1.
  const int n = 40;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Constant(n, n, -0.1);
  dense.diagonal().setConstant(10.0);
  CholmodSolver full;
  EXPECT_EQ(full.factor_flops(), 0.0);
  full.factorize(dense.sparseView());
  EXPECT_DOUBLE_EQ(full.factor_flops(), n * (n + 1) * (2 * n + 1) / 6.0);
  CholmodSolver path;
  path.factorize(path_with_link(n, 0, 1));
  EXPECT_DOUBLE_EQ(path.factor_flops(), 4.0 * (n - 1) + 1.0);
}

}  // namespace
}  // namespace vessel::msm
