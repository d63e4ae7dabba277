// CHOLMOD factors kept between solves of an identical matrix (the harness's references of several
// loads on one vessel): the answers equal fresh factorisations', identical matrices hit, a matrix
// differing in one value misses, and two threads solving with one kept factor agree.
#include <gtest/gtest.h>

#include <random>
#include <thread>

#include "fem_reference/cholmod_solve.hpp"
#include "cube_mesh.hpp"
#include "fem_reference/elasticity.hpp"

using namespace vessel::fem;

namespace {

/// A random sparse SPD matrix: a 1D Laplacian plus random symmetric couplings, diagonally
/// dominant.
Eigen::SparseMatrix<double> random_spd(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, n - 1);
  std::vector<Eigen::Triplet<double>> t;
  std::vector<double> diag(n, 2.0);
  for (int i = 0; i + 1 < n; ++i) {
    t.emplace_back(i, i + 1, -1.0);
    t.emplace_back(i + 1, i, -1.0);
  }
  for (int k = 0; k < 3 * n; ++k) {
    const int i = pick(rng), j = pick(rng);
    if (i == j) continue;
    const double v = 0.3 * u(rng);
    t.emplace_back(i, j, v);
    t.emplace_back(j, i, v);
    diag[i] += std::abs(v);
    diag[j] += std::abs(v);
  }
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, diag[i] + 1.0);
  Eigen::SparseMatrix<double> K(n, n);
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

}  // namespace

TEST(KeptFactor, IdenticalMatricesShareAFactorAndGiveTheFreshAnswer) {
  release_kept_factors();
  const Eigen::SparseMatrix<double> K = random_spd(400, 7);
  const Eigen::VectorXd b1 = Eigen::VectorXd::Random(400), b2 = Eigen::VectorXd::Random(400);
  const long hits0 = kept_factor_hits();
  const Eigen::VectorXd x1 = solve_spd_cholmod_keeping_factor(K, b1);
  EXPECT_EQ(kept_factor_hits(), hits0);  // the first solve factorises
  const Eigen::SparseMatrix<double> same = K;  // another object, the same matrix
  const Eigen::VectorXd x2 = solve_spd_cholmod_keeping_factor(same, b2);
  EXPECT_EQ(kept_factor_hits(), hits0 + 1);
  EXPECT_LT((x1 - solve_spd_cholmod(K, b1)).norm(), 1e-14 * x1.norm());
  EXPECT_LT((x2 - solve_spd_cholmod(K, b2)).norm(), 1e-14 * x2.norm());
  EXPECT_LT((K * x2 - b2).norm(), 1e-12 * b2.norm());  // and it solves K x = b

  Eigen::SparseMatrix<double> other = K;
  other.coeffRef(5, 5) += 1e-9;  // one value differs: a new factor
  const Eigen::VectorXd x3 = solve_spd_cholmod_keeping_factor(other, b2);
  EXPECT_EQ(kept_factor_hits(), hits0 + 1);
  EXPECT_LT((other * x3 - b2).norm(), 1e-12 * b2.norm());
  release_kept_factors();
  (void)solve_spd_cholmod_keeping_factor(K, b1);  // released: factorised again
  EXPECT_EQ(kept_factor_hits(), hits0 + 1);
  release_kept_factors();
}

TEST(KeptFactor, TwoThreadsSolvingWithOneKeptFactorAgreeWithAFreshSolve) {
  release_kept_factors();
  const Eigen::SparseMatrix<double> K = random_spd(2000, 11);
  (void)solve_spd_cholmod_keeping_factor(K, Eigen::VectorXd::Ones(2000));
  std::vector<Eigen::VectorXd> b(2), x(2);
  for (int t = 0; t < 2; ++t) b[t] = Eigen::VectorXd::Random(2000);
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t) {
    threads.emplace_back([&, t] {
      for (int r = 0; r < 20; ++r) x[t] = solve_spd_cholmod_keeping_factor(K, b[t]);
    });
  }
  for (auto& th : threads) th.join();
  for (int t = 0; t < 2; ++t) {
    EXPECT_LT((x[t] - solve_spd_cholmod(K, b[t])).norm(), 1e-14 * x[t].norm());
  }
  release_kept_factors();
}

TEST(KeptFactor, TwoLoadsOnOneVesselFactoriseOnceAndEqualSeparateSolves) {
  // What the harness does with its references: pressure on one problem, gravity on another, same
  // mesh, material and supports. With keep_factor the second solve reuses the first's factor;
  // the displacements equal those of solves that factorise afresh (the default).
  release_kept_factors();
  const vessel::TetMesh mesh = vessel::test::cube_mesh(3, 1e-3);
  auto problem = [](bool gravity, bool keep) {
    ElasticityProblem p;
    p.material.poisson_ratio = 0.3;
    p.options.degree = 2;
    p.options.solver = LinearSolver::direct;
    p.options.keep_factor = keep;
    p.dirichlet = {DirichletCondition::clamped("x0")};
    if (gravity) {
      p.gravity = vessel::Vec3(0, 0, -9.81);
    } else {
      p.pressures = {{"x1", 100.0}};
    }
    return p;
  };
  const long hits0 = kept_factor_hits();
  for (const bool gravity : {false, true}) {
    ElasticitySolver kept(mesh, problem(gravity, true)), fresh(mesh, problem(gravity, false));
    kept.solve();
    fresh.solve();
    const auto a = kept.solution_dofs(), b = fresh.solution_dofs();
    ASSERT_EQ(a.size(), b.size());
    double diff = 0.0, norm = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      diff = std::max(diff, std::abs(a[i] - b[i]));
      norm = std::max(norm, std::abs(b[i]));
    }
    EXPECT_GT(norm, 0.0);
    EXPECT_LE(diff, 1e-14 * norm) << (gravity ? "gravity" : "pressure");
  }
  EXPECT_EQ(kept_factor_hits(), hits0 + 1);  // gravity found pressure's factor
  release_kept_factors();
}

// CHOLMOD's symbolic analysis kept across the matrices of one pattern (the finite-strain Newton's
// tangents): each matrix is solved as K x = b (residual), one analysis serves every matrix of the
// pattern, another pattern is analysed again, and a matrix that is not positive definite is
// refused without spoiling the next solve.
TEST(CholmodSamePattern, OneAnalysisServesEveryMatrixOfThePattern) {
  const int n = 300;
  const Eigen::SparseMatrix<double> K1 = random_spd(n, 3);
  Eigen::SparseMatrix<double> K2 = K1;  // the same pattern, other values (still SPD)
  for (int k = 0; k < K2.outerSize(); ++k) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(K2, k); it; ++it) {
      if (it.row() == it.col()) it.valueRef() *= 1.5;
    }
  }
  const Eigen::VectorXd b = Eigen::VectorXd::Random(n);
  CholmodSamePattern solver;
  const Eigen::VectorXd x1 = solver.solve(K1, b);
  const Eigen::VectorXd x2 = solver.solve(K2, b);
  EXPECT_EQ(solver.analyses(), 1);
  EXPECT_LT((K1 * x1 - b).norm(), 1e-12 * b.norm());
  EXPECT_LT((K2 * x2 - b).norm(), 1e-12 * b.norm());
  EXPECT_GT((x1 - x2).norm(), 1e-3 * x1.norm());  // the second matrix was factorised anew

  Eigen::SparseMatrix<double> indefinite = K1;
  indefinite.coeffRef(5, 5) = -100.0;  // an existing entry: the pattern is unchanged
  EXPECT_THROW((void)solver.solve(indefinite, b), std::runtime_error);
  const Eigen::VectorXd again = solver.solve(K1, b);
  EXPECT_LT((K1 * again - b).norm(), 1e-12 * b.norm());
  EXPECT_EQ(solver.analyses(), 1);

  const Eigen::SparseMatrix<double> other = random_spd(n, 4);  // another pattern
  const Eigen::VectorXd x3 = solver.solve(other, b);
  EXPECT_EQ(solver.analyses(), 2);
  EXPECT_LT((other * x3 - b).norm(), 1e-12 * b.norm());
}
