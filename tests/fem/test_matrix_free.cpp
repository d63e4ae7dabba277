// The matrix-free displacement operator and its p-multigrid CG against the assembled system:
// A u (MatrixFree, FEEvaluation) against K u (FEValues assembly, free_displacement_system) on the
// free rows, and the matrix-free CG solution against CHOLMOD's.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <latch>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "fem_reference/elasticity.hpp"
#include "fem_test_meshes.hpp"
#include "meshes/foundation/solver_threads.hpp"

namespace vessel {
namespace {

using fem::ElasticityProblem;
using fem::ElasticitySolver;
using fem::LinearSolver;

ElasticityProblem pressurised_tube(int degree, double nu) {
  ElasticityProblem p;
  p.options.degree = degree;
  p.material.poisson_ratio = nu;
  p.dirichlet = {fem::DirichletCondition::clamped("inlet"),
                 fem::DirichletCondition::clamped("outlet")};
  p.pressures = {{"inner_wall", 5.0}};
  return p;
}

class MatrixFree : public ::testing::TestWithParam<int> {};

/// max over the free rows of |A u − K u| / max |K u| for a random u (zero on the constrained
/// DoFs), A u by `product` and K the assembled free-DoF stiffness.
template <typename Product>
double relative_product_difference(const ElasticitySolver& s, unsigned seed,
                                   const Product& product) {
  const auto sys = s.free_displacement_system();
  const std::size_t n = sys.free_index.size();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<double> u(n, 0.0);  // zero on the constrained DoFs
  Eigen::VectorXd u_free(sys.K.rows());
  for (std::size_t i = 0; i < n; ++i) {
    if (sys.free_index[i] < 0) continue;
    u[i] = uniform(rng);
    u_free[sys.free_index[i]] = u[i];
  }
  const auto au = product(u);
  const Eigen::VectorXd ku = sys.K * u_free;
  double diff = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (sys.free_index[i] >= 0) diff = std::max(diff, std::abs(au[i] - ku[sys.free_index[i]]));
  }
  return diff / ku.lpNorm<Eigen::Infinity>();
}

// On these straight tets the operator integrates at 1 (P1) or 4 (P2) points, its own kernel; the
// assembly at QGaussSimplex(degree + 1) (4, 14 points): both exact, so equal to rounding.
TEST_P(MatrixFree, ProductEqualsAssembledMatrixOnFreeRows) {
  const ElasticitySolver s(test::short_tube_mesh(0), pressurised_tube(GetParam(), 0.3));
  EXPECT_LT(
      relative_product_difference(s, 7, [&](const auto& u) { return s.matrix_free_product(u); }),
      1e-12)
      << "P" << GetParam();
}

// The same with each of the kernel's instruction sets (a batch of 8 cells in four SSE2, two AVX2
// or one AVX-512 register per quantity; the operator takes the widest this CPU has).
TEST_P(MatrixFree, EveryKernelVariantsProductEqualsAssembledMatrixOnFreeRows) {
  const ElasticitySolver s(test::short_tube_mesh(0), pressurised_tube(GetParam(), 0.3));
  for (const char* isa : {"sse2", "avx2", "avx512"}) {
    ::setenv("VESSELVERIFY_MATRIX_FREE_ISA", isa, 1);
    try {
      const double difference = relative_product_difference(
          s, 9, [&](const auto& u) { return s.matrix_free_product(u); });
      EXPECT_LT(difference, 1e-12) << "P" << GetParam() << " " << isa;
    } catch (const std::runtime_error& e) {  // this CPU lacks the instruction set
      EXPECT_NE(std::string(e.what()).find("this CPU lacks it"), std::string::npos) << e.what();
      std::cout << "P" << GetParam() << ": " << e.what() << "\n";
    }
    ::unsetenv("VESSELVERIFY_MATRIX_FREE_ISA");
  }
}

TEST(MatrixFreeKernel, AnUnknownInstructionSetIsRefusedByName) {
  const ElasticitySolver s(test::short_tube_mesh(0), pressurised_tube(2, 0.3));
  ::setenv("VESSELVERIFY_MATRIX_FREE_ISA", "neon", 1);
  const std::vector<double> u(s.free_displacement_system().free_index.size(), 0.0);
  try {
    (void)s.matrix_free_product(u);
    ADD_FAILURE() << "VESSELVERIFY_MATRIX_FREE_ISA=neon was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("VESSELVERIFY_MATRIX_FREE_ISA=neon: expected sse2, avx2"),
              std::string::npos)
        << e.what();
  }
  ::unsetenv("VESSELVERIFY_MATRIX_FREE_ISA");
}

// The batches cut into one part per thread, the parts' shared DoFs summed after: the same product
// on two and three threads.
TEST_P(MatrixFree, ThreadedProductEqualsAssembledMatrixOnFreeRows) {
  // A part has at least 32 batches of 8 cells (ElasticityOperator::partition_batches): this mesh
  // is cut into as many parts as threads.
  ASSERT_GE(test::short_tube_mesh(1).tets.size(), 3U * 32U * 8U);
  const ElasticitySolver s(test::short_tube_mesh(1), pressurised_tube(GetParam(), 0.3));
  for (const int threads : {2, 3}) {
    const ScopedSolverThreads on(threads);
    EXPECT_LT(
        relative_product_difference(s, 13, [&](const auto& u) { return s.matrix_free_product(u); }),
        1e-12)
        << "P" << GetParam() << " on " << threads << " threads";
  }
}

// The sparse matrix MatrixFreeTools::compute_matrix builds from the same cell kernel (the P1
// level's matrix for ML and CHOLMOD) against the assembled one.
TEST_P(MatrixFree, KernelMatrixEqualsAssembledMatrixOnFreeRows) {
  const ElasticitySolver s(test::short_tube_mesh(0), pressurised_tube(GetParam(), 0.3));
  EXPECT_LT(relative_product_difference(
                s, 5, [&](const auto& u) { return s.matrix_free_matrix_product(u); }),
            1e-12)
      << "P" << GetParam();
}

// The P1 level of the P2 cycle solved both ways: ML-CG (matrix_free_direct_coarse_max_dofs 0, the
// outer CG flexible) and a CHOLMOD factor (a limit above the P1 DoF count). P1 takes one ML
// V-cycle.
TEST_P(MatrixFree, CgWithPMultigridReachesCholmodSolution) {
  for (const auto& [nu, coarse_max_dofs] :
       {std::pair{0.0, std::size_t{0}}, {0.3, 0}, {0.45, 0}, {0.3, 1000000}, {0.45, 1000000}}) {
    auto p = pressurised_tube(GetParam(), nu);
    p.options.solver = LinearSolver::direct;
    const auto direct = fem::solve_elasticity(test::short_tube_mesh(0), p);
    p.options.solver = LinearSolver::matrix_free;
    p.options.cg_relative_tolerance = 1e-10;
    p.options.matrix_free_direct_coarse_max_dofs = coarse_max_dofs;
    const auto mf = fem::solve_elasticity(test::short_tube_mesh(0), p);
    EXPECT_EQ(mf.solver, LinearSolver::matrix_free);
    EXPECT_EQ(mf.matrix_free.coarse_method, GetParam() == 1        ? "one ML V-cycle"
                                            : coarse_max_dofs == 0 ? "ML-CG"
                                                                   : "CHOLMOD");
    EXPECT_GT(mf.iterations, 0u);
    double scale = 0.0, diff = 0.0;
    for (std::size_t k = 0; k < direct.nodal_displacement.size(); ++k) {
      scale = std::max(scale, direct.nodal_displacement[k].norm());
      diff = std::max(diff, (mf.nodal_displacement[k] - direct.nodal_displacement[k]).norm());
    }
    EXPECT_LT(diff, 1e-7 * scale) << "P" << GetParam() << " nu " << nu << ", " << mf.iterations
                                  << " iterations";
    EXPECT_NEAR(mf.strain_energy, direct.strain_energy, 1e-8 * direct.strain_energy);
    std::cout << "P" << GetParam() << " nu " << nu << ", P1 level by "
              << mf.matrix_free.coarse_method << ": " << mf.iterations
              << " CG iterations, max |u_mf - u_cholmod| / max |u| = " << diff / scale << "\n";
  }
}

// On curved walls (P2 geometry) the operator keeps the assembled path's quadrature; on straight
// tets it takes a smaller rule that is exact there. Both must give the assembled K.
TEST(MatrixFreeCurved, P2ProductEqualsAssembledMatrixOnFreeRows) {
  auto p = pressurised_tube(2, 0.3);
  p.curved_surfaces = fem::tube_curved_walls(3e-3, 4e-3);
  const ElasticitySolver s(test::short_tube_mesh(0), p);
  ASSERT_TRUE(s.result().curved);
  EXPECT_LT(
      relative_product_difference(s, 11, [&](const auto& u) { return s.matrix_free_product(u); }),
      1e-12);
}

// The Chebyshev smoother's diagonal against the assembled matrix's diagonal on the free rows.
TEST_P(MatrixFree, DiagonalEqualsAssembledMatrixDiagonal) {
  const ElasticitySolver s(test::short_tube_mesh(0), pressurised_tube(GetParam(), 0.3));
  const auto sys = s.free_displacement_system();
  const auto d = s.matrix_free_diagonal();
  ASSERT_EQ(d.size(), sys.free_index.size());
  const Eigen::VectorXd k_diag = sys.K.diagonal();
  double diff = 0.0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const int row = sys.free_index[i];
    diff = std::max(diff, row >= 0 ? std::abs(d[i] - k_diag[row]) : std::abs(d[i] - 1.0));
  }
  EXPECT_LT(diff, 1e-12 * k_diag.lpNorm<Eigen::Infinity>()) << "P" << GetParam();
}

// The multigrid's own P1 -> P2 prolongation (nodal interpolation, two index reads per P2 DoF)
// and its transpose against deal.II's MGTwoLevelTransfer for the same pair of spaces.
TEST(MatrixFreeTransfer, P1ToP2EmbeddingEqualsDealiiPolynomialTransfer) {
  const ElasticitySolver s(test::short_tube_mesh(0), pressurised_tube(2, 0.3));
  const auto [prolongation, restriction] = s.matrix_free_transfer_difference(3);
  EXPECT_LT(prolongation, 1e-14);
  EXPECT_LT(restriction, 1e-14);
}

// The harness solves references on several threads; in a process whose MPI is not yet
// initialised, the first solves started at once must initialise it once (Open MPI aborts the
// process on a second MPI_Init_thread). Each thread waits for the others before it solves.
TEST(MatrixFreeThreads, FirstSolvesStartedTogetherInitialiseMpiOnce) {
  const TetMesh& mesh = test::short_tube_mesh(0);
  constexpr int kThreads = 4;
  std::latch start(kThreads);
  std::vector<double> energy(kThreads, 0.0);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      auto p = pressurised_tube(2, 0.3);
      p.options.solver = LinearSolver::matrix_free;
      start.arrive_and_wait();
      energy[static_cast<std::size_t>(t)] = fem::solve_elasticity(mesh, p).strain_energy;
    });
  }
  for (std::thread& t : threads) t.join();
  for (int t = 1; t < kThreads; ++t) EXPECT_NEAR(energy[t], energy[0], 1e-9 * energy[0]);
}

INSTANTIATE_TEST_SUITE_P(Degrees, MatrixFree, ::testing::Values(1, 2));

// The two-level P2 -> P1 cycle with the P1 level solved to a fixed relative residual (ML-CG to
// 0.1) is an h-independent preconditioner: refining the mesh must not raise the outer CG
// iterations by more than 1.3x. With one ML V-cycle on P1 instead, the iterations grew 1.67x from
// structured level 0 to 1.
TEST(MatrixFreeMultigrid, P2IterationsStayWithinThirtyPercentFromLevelZeroToOne) {
  unsigned iterations[2] = {0, 0};
  for (const int level : {0, 1}) {
    auto p = pressurised_tube(2, 0.3);
    p.options.solver = LinearSolver::matrix_free;
    p.options.cg_relative_tolerance = 1e-10;
    p.options.matrix_free_direct_coarse_max_dofs = 0;
    const auto mf = fem::solve_elasticity(test::short_tube_mesh(level), p);
    EXPECT_EQ(mf.matrix_free.coarse_method, "ML-CG");
    p.options.solver = LinearSolver::direct;
    const auto direct = fem::solve_elasticity(test::short_tube_mesh(level), p);
    EXPECT_NEAR(mf.strain_energy, direct.strain_energy, 1e-8 * direct.strain_energy);
    iterations[level] = mf.iterations;
    std::cout << "P2 level " << level << ", " << mf.n_dofs << " DoFs: " << mf.iterations
              << " CG iterations\n";
  }
  const auto [low, high] = std::minmax(iterations[0], iterations[1]);
  ASSERT_GT(low, 0u);
  EXPECT_LE(static_cast<double>(high), 1.3 * low)
      << "CG iterations " << iterations[0] << " at level 0, " << iterations[1] << " at level 1";
}

// automatic's rule: the matrix-free CG for the linear reference's one P2 solve on straight tets
// from matrix_free_min_dofs; CHOLMOD below it, for P1, with keep_factor and on curved walls.
TEST(SolverChoice, AutomaticTakesMatrixFreeForOneStraightP2SolveFromItsLimit) {
  const TetMesh& mesh = test::short_tube_mesh(0);
  auto p = pressurised_tube(2, 0.3);
  p.options.solver = LinearSolver::direct;
  const auto direct = fem::solve_elasticity(mesh, p);
  ASSERT_GT(direct.n_dofs, 100u);
  p.options.solver = LinearSolver::automatic;
  p.options.matrix_free_min_dofs = direct.n_dofs;
  const auto at_limit = fem::solve_elasticity(mesh, p);
  EXPECT_EQ(at_limit.solver, LinearSolver::matrix_free) << at_limit.solver_reason;
  EXPECT_NE(at_limit.solver_reason.find("matrix-free-min-dofs"), std::string::npos)
      << at_limit.solver_reason;
  EXPECT_NEAR(at_limit.strain_energy, direct.strain_energy, 1e-8 * direct.strain_energy);

  auto expect_direct = [&](const fem::ElasticityProblem& q, const char* why) {
    const auto r = fem::solve_elasticity(mesh, q);
    EXPECT_EQ(r.solver, LinearSolver::direct) << why << ": " << r.solver_reason;
    EXPECT_NE(r.solver_reason.find("direct-max-dofs"), std::string::npos) << r.solver_reason;
  };
  auto below = p;
  below.options.matrix_free_min_dofs = direct.n_dofs + 1;
  expect_direct(below, "one DoF below the limit");
  auto kept = p;
  kept.options.keep_factor = true;
  expect_direct(kept, "keep_factor");
  auto never = p;
  never.options.matrix_free_min_dofs = 0;
  expect_direct(never, "limit 0");
  auto curved = p;
  curved.curved_surfaces = fem::tube_curved_walls(3e-3, 4e-3);  // short_tube's a and b
  expect_direct(curved, "curved walls");
  auto linear = pressurised_tube(1, 0.3);
  linear.options.matrix_free_min_dofs = 1;
  expect_direct(linear, "P1");
}

}  // namespace
}  // namespace vessel
