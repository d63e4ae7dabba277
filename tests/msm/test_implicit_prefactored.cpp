// implicit-euler-rest (implicit Euler with A = M + hD + h²K at rest, factorised once) against the
// same scheme written out as a plain loop that builds and factorises A every step; and the
// program's own solver threading (set_solver_threads).
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>

#include <algorithm>
#include <vector>

#include "meshes/foundation/errors.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/linalg/linear_solver.hpp"
#include "msm/solvers/solve.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

/// A 3 × 3 × 2 lattice of 1 mm cells with edge and face-diagonal springs, axial damping on every
/// spring and point damping; the x = 0 face fixed, a load on the far corner large enough that the
/// stiffness at the deformed state differs from the one at rest (geometric nonlinearity: 0.34 mm
/// of displacement on 1 mm cells) and small enough that the motion settles. (At 10× the load the
/// trajectory never settles, stays at ~1 m/s and amplifies round-off ~1.8× per step: two codes
/// then agree to 1e-12 only if their arithmetic is bit-identical, which tests nothing.)
struct Lattice {
  SpringNetwork net;
  std::unique_ptr<SpringModel> model;
  Problem problem;
};

Lattice make_lattice(int nx = 3, int ny = 3, int nz = 2) {
  Lattice c;
  auto id = [&](int i, int j, int k) { return (k * ny + j) * nx + i; };
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) c.net.nodes.push_back(Vec3(1e-3 * i, 1e-3 * j, 1e-3 * k));
    }
  }
  const int n = static_cast<int>(c.net.nodes.size());
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      const double d = (c.net.nodes[a] - c.net.nodes[b]).norm();
      if (d > 1.5e-3) continue;  // edges (1 mm) and face diagonals (1.41 mm)
      Spring s;
      s.a = a;
      s.b = b;
      s.rest_length = d;
      s.law = {50.0, 50.0};
      s.damping = 1e-3;  // N·s/m, seed 000 eq. (3.4)
      c.net.springs.push_back(s);
    }
  }
  c.model = std::make_unique<SpringModel>(c.net, 2e-4);
  Problem& p = c.problem;
  p.form = c.model.get();
  p.rest = flatten(c.net.nodes);
  p.mass = Eigen::VectorXd::Constant(3 * n, 1e-5);
  p.external_force = Eigen::VectorXd::Zero(3 * n);
  const int corner = id(nx - 1, ny - 1, nz - 1);
  p.external_force.segment<3>(3 * corner) = Vec3(0.0, -0.002, 0.003);
  p.fixed.assign(3 * n, 0);
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int d = 0; d < 3; ++d) p.fixed[3 * id(0, j, k) + d] = 1;
    }
  }
  return c;
}

/// Runs implicit-euler-rest for 100 steps against the same scheme written out with A built and
/// factorised every step (and solved by CHOLMOD's own solve, on one thread); returns the result.
/// `settles`: the motion has settled on the static answer after the 100 steps (the 3 × 3 × 2
/// lattice; the larger one is still moving, at 1e-2 of its fastest velocity).
DynamicResult expect_rest_equals_refactorised(const Lattice& c, bool settles) {
  const Problem& p = c.problem;
  const double h = 1e-3;
  const int steps = 100;
  const int n = p.num_dofs();

  // The reference: Baraff–Witkin's linearised step with K and D at rest, A built and factorised
  // anew every step.
  std::vector<Eigen::VectorXd> x_ref, v_ref;
  {
    Eigen::VectorXd x = p.rest, v = Eigen::VectorXd::Zero(n), g(n), fd(n);
    SparseMatrix K, D;
    p.form->hessian(p.rest, K, true);
    p.form->damping_jacobian(p.rest, D);
    for (int step = 1; step <= steps; ++step) {
      p.form->gradient(x, g);
      p.form->damping_force(x, v, fd);
      Eigen::VectorXd f = -g + p.external_force + fd;
      for (int i = 0; i < n; ++i) {
        if (p.fixed[i]) f[i] = 0.0;
      }
      SparseMatrix A = h * h * K + h * D;
      for (int i = 0; i < n; ++i) A.coeffRef(i, i) += p.mass[i];
      apply_dirichlet(A, p.fixed);
      Eigen::VectorXd rhs = h * (f - h * (K * v));
      for (int i = 0; i < n; ++i) {
        if (p.fixed[i]) rhs[i] = 0.0;
      }
      CholmodSolver solver;
      solver.factorize(A);
      v += solver.solve(rhs);
      x += h * v;
      x_ref.push_back(x);
      v_ref.push_back(v);
    }
  }

  // The motion settles (damped), so velocities are compared on the scale of the fastest one.
  double v_scale = 0.0;
  for (const Eigen::VectorXd& v : v_ref) v_scale = std::max(v_scale, v.norm());

  DynamicOptions o;
  o.integrator = Integrator::implicit_euler;
  o.implicit_matrix = ImplicitMatrix::rest_prefactored;
  o.dt = h;
  o.steps = steps;
  int checked = 0;
  o.on_step = [&](int step, const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
    const Eigen::VectorXd& xr = x_ref[static_cast<std::size_t>(step - 1)];
    const Eigen::VectorXd& vr = v_ref[static_cast<std::size_t>(step - 1)];
    EXPECT_LE((x - xr).norm(), 1e-12 * (xr - p.rest).norm()) << "step " << step;
    EXPECT_LE((v - vr).norm(), 1e-12 * v_scale) << "step " << step;
    ++checked;
  };
  const DynamicResult r = integrate(p, o);
  EXPECT_EQ(checked, steps);
  EXPECT_EQ(r.numeric_factorisations, 1);
  EXPECT_GT(r.setup_seconds, 0.0);  // the factorisation at rest is timed

  // The motion has settled on the static answer, which both matrices share.
  if (settles) EXPECT_LT(v_ref.back().norm(), 1e-6 * v_scale);
  return r;
}

}  // namespace

TEST(ImplicitEulerRest, EqualsTheSameSchemeRefactorisedEveryStepAndFactorisesOnce) {
  const Lattice c = make_lattice();
  const Problem& p = c.problem;
  expect_rest_equals_refactorised(c, true);
  // The problem tells the two matrices apart on the way: implicit Euler with K at the current
  // state (refactorised every step) is elsewhere after 10 steps.
  DynamicOptions o;
  o.integrator = Integrator::implicit_euler;
  o.implicit_matrix = ImplicitMatrix::rest_prefactored;
  o.dt = 1e-3;
  o.steps = 10;
  const Eigen::VectorXd x_rest = integrate(p, o).x;
  o.implicit_matrix = ImplicitMatrix::current_state;
  const DynamicResult current = integrate(p, o);
  EXPECT_EQ(current.numeric_factorisations, 10);
  const Eigen::VectorXd u = x_rest - p.rest;
  EXPECT_GT((current.x - x_rest).norm(), 1e-6 * u.norm());
}

TEST(ImplicitEulerRest, EqualsTheSameSchemeRefactorisedWithTheSolveOnTwoThreads) {
  // 10 × 8 × 6 nodes, 1 440 dofs: CHOLMOD's factor is supernodal (from 1 000 unknowns), so with
  // two solver threads and no size threshold every step's solve runs on the parallel sweeps.
  const Lattice c = make_lattice(10, 8, 6);
  const double saved = CholmodSolver::parallel_solve_min_entries();
  CholmodSolver::set_parallel_solve_min_entries(0.0);
  set_solver_threads(2);
  expect_rest_equals_refactorised(c, false);
  set_solver_threads(1);
  CholmodSolver::set_parallel_solve_min_entries(saved);
}

TEST(CholmodSolver, ParallelSweepsSolveLikeAnIndependentFactorisationAndFollowRefactorisation) {
  // A = M + h²K of a 10 × 8 × 6 lattice with its fixed face as identity rows (a forest: every
  // fixed dof is a tree of its own), against Eigen's simplicial LDLᵀ (another code).
  const Lattice c = make_lattice(10, 8, 6);
  const Problem& p = c.problem;
  SparseMatrix K;
  p.form->hessian(p.rest, K, true);
  const double saved = CholmodSolver::parallel_solve_min_entries();
  CholmodSolver::set_parallel_solve_min_entries(0.0);
  CholmodSolver solver;
  Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(p.num_dofs(), -1.0, 2.0).array().sin();
  for (const double h : {1e-3, 3e-3}) {  // the second: new values, the same pattern
    SparseMatrix A = h * h * K;
    for (int i = 0; i < p.num_dofs(); ++i) A.coeffRef(i, i) += p.mass[i];
    apply_dirichlet(A, p.fixed);
    solver.factorize(A);
    const Eigen::SimplicialLDLT<SparseMatrix> ldlt(A);
    ASSERT_EQ(ldlt.info(), Eigen::Success);
    const Eigen::VectorXd truth = ldlt.solve(b);
    for (const int threads : {1, 2, 3}) {
      set_solver_threads(threads);
      Eigen::VectorXd x;
      solver.solve_into(b, x);
      set_solver_threads(1);
      EXPECT_EQ(solver.last_solve_threads(), threads);
      EXPECT_LE((x - truth).norm(), 1e-12 * truth.norm()) << "h " << h << ", threads " << threads;
      EXPECT_LE((A * x - b).norm(), 1e-12 * b.norm()) << "h " << h << ", threads " << threads;
    }
  }
  EXPECT_EQ(solver.symbolic_analyses(), 1);
  // Below the size threshold the solve stays on one thread.
  CholmodSolver::set_parallel_solve_min_entries(1e300);
  set_solver_threads(2);
  Eigen::VectorXd x;
  solver.solve_into(b, x);
  set_solver_threads(1);
  EXPECT_EQ(solver.last_solve_threads(), 1);
  CholmodSolver::set_parallel_solve_min_entries(saved);
}

TEST(ImplicitEulerRest, IsNamedAndRunsThroughSolve) {
  const SolverSpec spec = parse_solver("implicit-euler-rest");
  EXPECT_EQ(spec.kind, SolverKind::integrator);
  EXPECT_EQ(spec.integrator, Integrator::implicit_euler);
  EXPECT_EQ(spec.implicit_matrix, ImplicitMatrix::rest_prefactored);
  EXPECT_EQ(parse_solver("implicit-euler").implicit_matrix, ImplicitMatrix::current_state);
  const Lattice c = make_lattice();
  SolverSpec s = spec;
  s.dt = 1e-3;
  s.steps = 5;
  const SolveResult r = solve(c.problem, s);
  EXPECT_EQ(std::get<DynamicResult>(r.detail).numeric_factorisations, 1);
}

TEST(SolverThreads, DefaultsToOneAndRefusesLessThanOne) {
  EXPECT_EQ(solver_threads(), 1);
  EXPECT_THROW(set_solver_threads(0), InputError);
  EXPECT_EQ(solver_threads(), 1);
  // Two threads and back give the same factorisation (CHOLMOD's result does not depend on it
  // beyond rounding; here the problem is small and simplicial, so it is bitwise the same).
  const Lattice c = make_lattice();
  DynamicOptions o;
  o.integrator = Integrator::implicit_euler;
  o.dt = 1e-3;
  o.steps = 10;
  const DynamicResult one = integrate(c.problem, o);
  set_solver_threads(2);
  const DynamicResult two = integrate(c.problem, o);
  set_solver_threads(1);
  EXPECT_EQ(solver_threads(), 1);
  EXPECT_LE((one.x - two.x).norm(), 1e-12 * (one.x - c.problem.rest).norm());
}
