// Preconditioned conjugate gradients (msm/solvers/pcg.hpp) against a dense Cholesky solve, and
// implicit Euler solved by it (implicit-euler-pcg, implicit-euler-rest-pcg) against the same steps
// solved by CHOLMOD (implicit-euler, implicit-euler-rest) on the level-0 vessel's volume model.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "meshes/foundation/errors.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/solvers/pcg.hpp"
#include "msm/solvers/solve.hpp"
#include "msm/stiffness/stiffness_rules.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

/// A random symmetric positive-definite matrix with the pattern of a spring network: 3×3 blocks
/// B Bᵀ coupling random node pairs (a stiffness), plus a positive diagonal (a mass).
SparseMatrix random_spd(int nodes, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, nodes - 1);
  std::vector<Eigen::Triplet<double>> t;
  for (int e = 0; e < 4 * nodes; ++e) {
    const int a = pick(rng), b = pick(rng);
    if (a == b) continue;
    Eigen::Matrix3d B;
    for (int i = 0; i < 9; ++i) B(i / 3, i % 3) = u(rng);
    const Eigen::Matrix3d S = B * B.transpose();  // PSD; the pair's block [S −S; −S S]
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        t.emplace_back(3 * a + i, 3 * a + j, S(i, j));
        t.emplace_back(3 * b + i, 3 * b + j, S(i, j));
        t.emplace_back(3 * a + i, 3 * b + j, -S(i, j));
        t.emplace_back(3 * b + i, 3 * a + j, -S(i, j));
      }
    }
  }
  for (int i = 0; i < 3 * nodes; ++i) t.emplace_back(i, i, 0.05 + 0.5 * (u(rng) + 1.0));
  SparseMatrix A(3 * nodes, 3 * nodes);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

/// The level-0 vessel's volume model (seed 001 springs, consistent masses) under 1 mN on the
/// shared contact patch, inlet and outlet fixed.
struct Tube {
  TetMesh mesh;
  SpringNetwork net;
  std::unique_ptr<SpringModel> model;
  Problem problem;
};

Tube tube() {
  Tube t;
  const VesselParams params;
  t.mesh = generate_vessel_mesh(params);
  t.net = build_volume_network(t.mesh);
  assign_stiffness(t.net, StiffnessRule::seed001, StiffnessParams{});
  t.model = std::make_unique<SpringModel>(t.net);
  const auto masses = nodal_masses(t.net, MassRule::consistent, kVesselDensity);
  ContactPatchSpec spec;
  spec.point = Vec3(3e-3, 0, 20e-3);
  spec.radius = 1e-3;
  spec.force = 1e-3;
  const auto loads = traction_nodal_loads(t.mesh, contact_patch(t.mesh, spec));
  t.problem = make_problem(*t.model, t.net, masses, t.mesh, loads, {"inlet", "outlet"});
  return t;
}

/// The positions after each step of implicit Euler with the given matrix choice.
std::vector<Eigen::VectorXd> trajectory(const Problem& p, ImplicitMatrix matrix, int steps,
                                        double tolerance, DynamicResult* result = nullptr) {
  DynamicOptions o;
  o.integrator = Integrator::implicit_euler;
  o.implicit_matrix = matrix;
  o.dt = 1e-3;
  o.steps = steps;
  o.pcg.tolerance = tolerance;
  std::vector<Eigen::VectorXd> xs;
  o.on_step = [&](int, const Eigen::VectorXd& x, const Eigen::VectorXd&) { xs.push_back(x); };
  const DynamicResult r = integrate(p, o);
  if (result) *result = r;
  return xs;
}

/// Largest ‖x − x_ref‖ / ‖x_ref − rest‖ over the steps.
double worst_relative_difference(const std::vector<Eigen::VectorXd>& x,
                                 const std::vector<Eigen::VectorXd>& ref,
                                 const Eigen::VectorXd& rest) {
  EXPECT_EQ(x.size(), ref.size());
  double worst = 0.0;
  for (std::size_t s = 0; s < std::min(x.size(), ref.size()); ++s) {
    worst = std::max(worst, (x[s] - ref[s]).norm() / (ref[s] - rest).norm());
  }
  return worst;
}

}  // namespace

TEST(Pcg, SolvesARandomSpdSystemToItsToleranceAgainstADenseCholesky) {
  const SparseMatrix A = random_spd(60, 7);
  const Eigen::MatrixXd dense(A);
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  Eigen::VectorXd b(A.rows());
  for (Eigen::Index i = 0; i < b.size(); ++i) b[i] = g(rng);
  const Eigen::VectorXd exact = dense.llt().solve(b);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(dense);
  const double kappa = eig.eigenvalues().maxCoeff() / eig.eigenvalues().minCoeff();
  for (const auto pc : {PcgPreconditioner::jacobi, PcgPreconditioner::block_jacobi}) {
    PcgOptions o;
    o.tolerance = 1e-10;
    o.preconditioner = pc;
    PcgSolver cg;
    cg.compute(A, o);
    Eigen::VectorXd x;  // empty: started from zero
    const PcgResult r = cg.solve(b, x);
    EXPECT_TRUE(r.converged);
    EXPECT_GT(r.iterations, 0);
    EXPECT_LE((b - dense * x).norm(), 1e-10 * b.norm());  // the residual it reports, recomputed
    EXPECT_LE(r.relative_residual, 1e-10);
    // ‖x − x*‖/‖x*‖ ≤ κ(A) · ‖r‖/‖b‖
    EXPECT_LE((x - exact).norm(), kappa * 1e-10 * exact.norm());
    // Warm-started at the answer: nothing to do.
    Eigen::VectorXd warm = exact;
    EXPECT_EQ(cg.solve(b, warm).iterations, 0);
    // b = 0: x = 0 whatever the start.
    Eigen::VectorXd z = exact;
    EXPECT_TRUE(cg.solve(Eigen::VectorXd::Zero(b.size()), z).converged);
    EXPECT_EQ(z.norm(), 0.0);
  }
}

TEST(Pcg, BlockJacobiIsExactOnABlockDiagonalMatrixInOneIteration) {
  // Each node's 3×3 block inverted exactly: P⁻¹A = I, CG's first step is the answer.
  std::vector<Eigen::Triplet<double>> t;
  for (int node = 0; node < 5; ++node) {
    const double a = 2.0 + node;
    const double blk[3][3] = {{a, 0.5, 0.1}, {0.5, a, 0.2}, {0.1, 0.2, a}};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) t.emplace_back(3 * node + i, 3 * node + j, blk[i][j]);
    }
  }
  SparseMatrix A(15, 15);
  A.setFromTriplets(t.begin(), t.end());
  PcgOptions o;
  o.tolerance = 1e-13;
  PcgSolver cg;
  cg.compute(A, o);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(15, 1.0, 15.0);
  Eigen::VectorXd x;
  const PcgResult r = cg.solve(b, x);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_LE((Eigen::MatrixXd(A).llt().solve(b) - x).norm(), 1e-13 * x.norm());
}

TEST(Pcg, RefusesANonPositiveDiagonalAndReportsNonConvergence) {
  SparseMatrix A = random_spd(20, 1);
  PcgOptions o;
  o.preconditioner = PcgPreconditioner::jacobi;
  A.coeffRef(4, 4) = -1.0;
  PcgSolver cg;
  EXPECT_THROW(cg.compute(A, o), std::runtime_error);
  o.tolerance = 1e-14;
  o.max_iterations = 2;
  cg.compute(random_spd(20, 1), o);
  Eigen::VectorXd x;
  const PcgResult r = cg.solve(Eigen::VectorXd::Ones(60), x);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 2);
  EXPECT_GT(r.relative_residual, 1e-14);
  EXPECT_THROW((void)parse_pcg_preconditioner("ilu"), InputError);
}

TEST(ConjugateGradients, ANearbyMatrixsInverseAsPreconditionerNeedsAsManyStepsAsTheChangesRank) {
  // A = M + Σ_{k<3} v_k v_kᵀ: with M⁻¹ as preconditioner, M⁻¹A = I + rank 3 has four distinct
  // eigenvalues, so CG is exact in at most four steps (Saad 2003, Theorem 6.29's corollary).
  const SparseMatrix M = random_spd(40, 3);
  const Eigen::MatrixXd Md(M);
  const Eigen::LLT<Eigen::MatrixXd> m(Md);
  Eigen::MatrixXd A = Md;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 3; ++k) {
    Eigen::VectorXd v(120);
    for (int i = 0; i < 120; ++i) v[i] = u(rng);
    A += v * v.transpose();
  }
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(120, -1.0, 2.0);
  Eigen::VectorXd x;
  PcgWorkspace w;
  const PcgResult r =
      conjugate_gradients([&](const Eigen::VectorXd& v, Eigen::VectorXd& out) { out = A * v; },
                          [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) { out = m.solve(v); },
                          b, x, 1e-12, 50, w);
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.iterations, 5);  // four in exact arithmetic, one more for round-off
  EXPECT_LE((A.llt().solve(b) - x).norm(), 1e-10 * x.norm());
  EXPECT_FALSE(r.negative_curvature);

  // An indefinite operator: −A along every direction, found on the first step.
  const PcgResult n =
      conjugate_gradients([&](const Eigen::VectorXd& v, Eigen::VectorXd& out) { out = -(A * v); },
                          [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) { out = m.solve(v); },
                          b, x, 1e-12, 50, w);
  EXPECT_TRUE(n.negative_curvature);
  EXPECT_FALSE(n.converged);
  EXPECT_EQ(n.iterations, 0);
}

TEST(ImplicitEulerPcg, RestPcgConvergesToTheFactorisedStepOver100Steps) {
  const Tube t = tube();
  const Problem& p = t.problem;
  const auto direct = trajectory(p, ImplicitMatrix::rest_prefactored, 100, 0.0);
  DynamicResult r;
  const auto tight = trajectory(p, ImplicitMatrix::rest_pcg, 100, 1e-10, &r);
  EXPECT_EQ(r.numeric_factorisations, 0);
  EXPECT_GT(r.linear_iterations, 100);
  const double e_tight = worst_relative_difference(tight, direct, p.rest);
  // A relative residual τ leaves a relative error ≲ κ(A)·τ in each step's Δv (κ(A) ~ 1e2–1e3 here
  // at 1 ms: 1 + (h ω_max)²); over 100 damped steps the measured worst was 7.8e-11 (τ = 1e-4: 5.8e-5).
  EXPECT_LE(e_tight, 1e-8);
  // The tolerance is what sets the error: 1e-4 is visibly further from the direct steps.
  const auto loose = trajectory(p, ImplicitMatrix::rest_pcg, 100, 1e-4);
  const double e_loose = worst_relative_difference(loose, direct, p.rest);
  EXPECT_GT(e_loose, 10.0 * e_tight);
  EXPECT_LE(e_loose, 1e-3);
  std::cout << "worst relative difference over 100 steps: τ = 1e-10 " << e_tight << ", τ = 1e-4 "
            << e_loose << "; CG iterations per step at 1e-10: "
            << static_cast<double>(r.linear_iterations) / r.steps << '\n';
}

TEST(ImplicitEulerPcg, CurrentStatePcgConvergesToImplicitEulerRefactorisedEveryStep) {
  const Tube t = tube();
  const Problem& p = t.problem;
  const auto direct = trajectory(p, ImplicitMatrix::current_state, 20, 0.0);
  DynamicResult r;
  const auto pcg = trajectory(p, ImplicitMatrix::current_pcg, 20, 1e-10, &r);
  EXPECT_EQ(r.numeric_factorisations, 0);
  const double e = worst_relative_difference(pcg, direct, p.rest);
  EXPECT_LE(e, 1e-6);
  // And it is the current-state step, not the rest one: those differ far more.
  const auto rest = trajectory(p, ImplicitMatrix::rest_prefactored, 20, 0.0);
  EXPECT_GT(worst_relative_difference(rest, direct, p.rest), 100.0 * e);
}

TEST(ImplicitEulerPcg, IsNamedAndStopsWithAClearErrorWhenCgDoesNotConverge) {
  EXPECT_EQ(parse_solver("implicit-euler-pcg").implicit_matrix, ImplicitMatrix::current_pcg);
  EXPECT_EQ(parse_solver("implicit-euler-rest-pcg").implicit_matrix, ImplicitMatrix::rest_pcg);
  const Tube t = tube();
  SolverSpec s = parse_solver("implicit-euler-rest-pcg");
  s.dt = 1e-3;
  s.steps = 3;
  s.pcg.tolerance = 1e-12;
  s.pcg.max_iterations = 3;
  try {
    (void)solve(t.problem, s);
    FAIL() << "expected a non-convergence error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("conjugate gradients stopped at step 1"),
              std::string::npos)
        << e.what();
  }
}
