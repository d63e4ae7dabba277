// The finite-strain reference's Newton systems on the matrix-free machinery: the matrix-free
// neo-Hookean tangent against the assembled one (itself checked against finite differences of the
// residual in test_hyperelastic.cpp), and Newton with the p-multigrid against the closed-form
// uniaxial stretch and against the direct solver's equilibrium.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <random>
#include <stdexcept>
#include <string>

#include "cube_mesh.hpp"
#include "fem_reference/hyperelastic.hpp"
#include "fem_test_meshes.hpp"

using namespace vessel;
using namespace vessel::fem;

namespace {

/// A cube with rollers on x0, y0, z0, gravity, pressure on x1 (follower unless `dead`).
ElasticityProblem loaded_cube(int degree, LinearSolver solver) {
  ElasticityProblem p;
  p.material.poisson_ratio = 0.3;
  p.options.degree = degree;
  p.options.solver = solver;
  p.dirichlet = {DirichletCondition::roller("x0", 0), DirichletCondition::roller("y0", 1),
                 DirichletCondition::roller("z0", 2)};
  p.pressures = {{"x1", 2000.0}};
  p.gravity = Vec3(0, 0, -9.81 * 50);
  return p;
}

}  // namespace

namespace {

/// Uniform random values in [−scale, scale]; zero on the constrained DoFs when `free` is given.
std::vector<double> random_values(std::mt19937& rng, std::size_t n, double scale,
                                  const std::vector<int>* free = nullptr) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = free && (*free)[i] < 0 ? 0.0 : scale * uniform(rng);
  return v;
}

}  // namespace

TEST(HyperelasticMatrixFree, TangentProductAndDiagonalEqualTheAssembledTangentOnFreeRows) {
  const double L = 1e-3;
  std::mt19937 rng(5);
  for (const int degree : {1, 2}) {
    HyperelasticOptions o;
    o.follower_pressure = false;  // the assembled tangent then has no face terms
    const HyperelasticSolver s(test::cube_mesh(2, L), loaded_cube(degree, LinearSolver::direct), o);
    // Displacements of 5 % of the cube: strains of order 0.1, F far from the identity.
    const auto u = random_values(rng, s.n_dofs(), 0.05 * L);
    const auto free = s.free_dofs().free_index;
    const auto v = random_values(rng, s.n_dofs(), 1.0, &free);
    const auto K = s.tangent_columns(u, 1.0);  // K[j][i] = ∂R_i/∂u_j
    // Every instruction set of the batched kernel (this CPU's widest first, by default).
    for (const char* isa : {"", "sse2", "avx2", "avx512"}) {
      if (*isa != 0) ::setenv("VESSELVERIFY_MATRIX_FREE_ISA", isa, 1);
      std::vector<double> av, diagonal;
      try {
        av = s.matrix_free_tangent_product(u, v);
        diagonal = s.matrix_free_tangent_diagonal(u);
      } catch (const std::runtime_error& e) {  // this CPU lacks the instruction set
        EXPECT_NE(std::string(e.what()).find("this CPU lacks it"), std::string::npos) << e.what();
        ::unsetenv("VESSELVERIFY_MATRIX_FREE_ISA");
        continue;
      }
      ::unsetenv("VESSELVERIFY_MATRIX_FREE_ISA");
      double diff = 0.0, scale = 0.0, diagonal_diff = 0.0, diagonal_scale = 0.0;
      for (std::size_t i = 0; i < v.size(); ++i) {
        if (free[i] < 0) continue;
        double kv = 0.0;
        for (std::size_t j = 0; j < v.size(); ++j) kv += K[j][i] * v[j];
        diff = std::max(diff, std::abs(av[i] - kv));
        scale = std::max(scale, std::abs(kv));
        diagonal_diff = std::max(diagonal_diff, std::abs(diagonal[i] - K[i][i]));
        diagonal_scale = std::max(diagonal_scale, std::abs(K[i][i]));
      }
      std::cout << "  matrix-free tangent P" << degree << " " << (*isa ? isa : "default")
                << ": max |A v - K v| / max |K v| " << diff / scale
                << ", diagonal max |d - K_ii| / max K_ii " << diagonal_diff / diagonal_scale
                << "\n";
      EXPECT_LT(diff / scale, 1e-12) << isa;
      EXPECT_LT(diagonal_diff / diagonal_scale, 1e-12) << isa;
    }
  }
}

TEST(HyperelasticMatrixFree, CurvedTangentProductIsTheResidualsDirectionalDerivative) {
  // On curved walls (P2 geometry) the operator takes deal.II's FEEvaluation path: against the
  // central difference (R(u + h v) − R(u − h v)) / 2h of the residual, whose error is O(h²).
  ElasticityProblem p = loaded_cube(2, LinearSolver::direct);
  p.dirichlet = {DirichletCondition::clamped("inlet"), DirichletCondition::clamped("outlet")};
  p.pressures = {{"inner_wall", 1000.0}};
  p.gravity = Vec3::Zero();
  p.curved_surfaces = tube_curved_walls(3e-3, 4e-3);
  HyperelasticOptions o;
  o.follower_pressure = false;
  const HyperelasticSolver s(test::short_tube_mesh(0), p, o);
  std::mt19937 rng(7);
  const auto free = s.free_dofs().free_index;
  const auto u = random_values(rng, s.n_dofs(), 5e-5, &free);  // 5 % of the wall's thickness
  const auto v = random_values(rng, s.n_dofs(), 1.0, &free);
  const double h = 1e-9;
  auto up = u, um = u;
  for (std::size_t i = 0; i < u.size(); ++i) {
    up[i] += h * v[i];
    um[i] -= h * v[i];
  }
  const auto rp = s.residual(up, 0.0), rm = s.residual(um, 0.0);
  const auto av = s.matrix_free_tangent_product(u, v);
  double diff = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (free[i] < 0) continue;
    const double fd = (rp[i] - rm[i]) / (2 * h);
    diff = std::max(diff, std::abs(av[i] - fd));
    scale = std::max(scale, std::abs(fd));
  }
  std::cout << "  curved P2 matrix-free tangent against the residual's central difference: "
            << diff / scale << "\n";
  EXPECT_LT(diff / scale, 1e-6);
}

TEST(HyperelasticMatrixFree, NewtonReachesTheUniaxialStretchsClosedForm) {
  // A homogeneous stretch is in every element's space: the discrete equilibrium is exact to the
  // Newton tolerance. The Cauchy traction on the deformed face is a follower "pressure" −σ_xx, so
  // the Newton systems are unsymmetric: FGMRES on the matrix-free tangent plus the faces' matrix.
  const double L = 1e-3;
  const double stretch = 1.5;
  Material m;
  m.poisson_ratio = 0.3;
  const double mu = m.mu(), lambda = m.lambda();
  // σ_yy = (μ(t² − 1) + λ ln(l t²))/J = 0 for the lateral stretch t, by bisection.
  double lo = 0.1, hi = 2.0;
  for (int i = 0; i < 200; ++i) {
    const double t = 0.5 * (lo + hi);
    (mu * (t * t - 1) + lambda * std::log(stretch * t * t) < 0 ? lo : hi) = t;
  }
  const double t = 0.5 * (lo + hi);
  const double cauchy = mu * (stretch * stretch - t * t) / (stretch * t * t);
  for (const int degree : {1, 2}) {
    ElasticityProblem p = loaded_cube(degree, LinearSolver::matrix_free);
    p.gravity = Vec3::Zero();
    p.pressures = {{"x1", -cauchy}};
    HyperelasticSolver s(test::cube_mesh(2, L), p);
    const auto& r = s.solve();
    ASSERT_TRUE(r.completed) << r.stop_reason;
    EXPECT_EQ(r.solver, LinearSolver::matrix_free);
    const Vec3 u = s.displacement_at({Vec3(L, L, L)})[0];
    const Vec3 expect((stretch - 1) * L, (t - 1) * L, (t - 1) * L);
    std::cout << "  uniaxial l=" << stretch << " P" << degree << " matrix-free: Newton "
              << r.newton_iterations << ", Krylov " << r.linear_iterations
              << ", |u - exact| / L = " << (u - expect).norm() / L << "\n";
    EXPECT_LT((u - expect).norm(), 1e-8 * L);
  }
}

TEST(HyperelasticMatrixFree, NewtonReachesTheDirectSolversEquilibriumOnATube) {
  // The short tube clamped at the inlet, its outlet pulled 0.3 mm along the axis (a prescribed
  // increment: the tangent predictor's lift), a follower pressure inside: P2, ν 0.45.
  for (const bool follower : {true, false}) {
    const auto problem = [](LinearSolver solver) {
      ElasticityProblem p;
      p.material.poisson_ratio = 0.45;
      p.options.degree = 2;
      p.options.solver = solver;
      p.dirichlet = {DirichletCondition::clamped("inlet"),
                     DirichletCondition::clamped(
                         "outlet", [](const Vec3&) { return Vec3(0.0, 0.0, 0.3e-3); })};
      p.pressures = {{"inner_wall", 1000.0}};
      return p;
    };
    HyperelasticOptions o;
    o.follower_pressure = follower;
    HyperelasticSolver direct(test::short_tube_mesh(0), problem(LinearSolver::direct), o);
    HyperelasticSolver mf(test::short_tube_mesh(0), problem(LinearSolver::matrix_free), o);
    const auto t0 = std::chrono::steady_clock::now();
    const auto& rd = direct.solve();
    const auto t1 = std::chrono::steady_clock::now();
    const auto& rm = mf.solve();
    const auto t2 = std::chrono::steady_clock::now();
    ASSERT_TRUE(rd.completed) << rd.stop_reason;
    ASSERT_TRUE(rm.completed) << rm.stop_reason;
    double diff = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < rd.nodal_displacement.size(); ++i) {
      diff = std::max(diff, (rm.nodal_displacement[i] - rd.nodal_displacement[i]).norm());
      scale = std::max(scale, rd.nodal_displacement[i].norm());
    }
    std::cout << "  tube P2 " << (follower ? "follower" : "dead") << " pressure: Newton "
              << rd.newton_iterations << " direct, " << rm.newton_iterations
              << " matrix-free (Krylov " << rm.linear_iterations << "); max |u_mf - u_direct| / "
              << "max |u| " << diff / scale << ", max GL strain " << rd.max_abs_principal_strain
              << " (" << std::chrono::duration<double>(t1 - t0).count() << " s direct, "
              << std::chrono::duration<double>(t2 - t1).count() << " s matrix-free)\n";
    EXPECT_GT(rd.max_abs_principal_strain, 0.05);
    EXPECT_LT(diff / scale, 1e-8);
    EXPECT_NEAR(rm.strain_energy, rd.strain_energy, 1e-8 * rd.strain_energy);
  }
}

TEST(HyperelasticMatrixFree,
     AutomaticTakesItForFollowerPressureAndMovesToTheAssembledTangentWhenItsKrylovSolveFails) {
  // The tube above (follower pressure: FGMRES) under `automatic` with the matrix-free switch at
  // one DoF, so the linear reference's rule takes the matrix-free solve here. With the Krylov
  // solver allowed 3 iterations the first Newton system fails: the solve must move to the
  // assembled tangent (UMFPACK, which max_iterations does not bound) and reach the direct
  // solver's equilibrium; with the default cap it stays matrix-free. The symmetric tangent (a
  // dead pressure) keeps the assembled path (CHOLMOD).
  const auto problem = [](LinearSolver solver, unsigned max_iterations) {
    ElasticityProblem p;
    p.material.poisson_ratio = 0.45;
    p.options.degree = 2;
    p.options.solver = solver;
    p.options.matrix_free_min_dofs = 1;
    p.options.max_iterations = max_iterations;
    p.dirichlet = {
        DirichletCondition::clamped("inlet"),
        DirichletCondition::clamped("outlet", [](const Vec3&) { return Vec3(0.0, 0.0, 0.3e-3); })};
    p.pressures = {{"inner_wall", 1000.0}};
    return p;
  };
  HyperelasticOptions o;
  o.follower_pressure = true;
  HyperelasticSolver direct(test::short_tube_mesh(0), problem(LinearSolver::direct, 5000), o);
  const auto& rd = direct.solve();
  ASSERT_TRUE(rd.completed) << rd.stop_reason;
  double scale = 0.0;
  for (const auto& x : rd.nodal_displacement) scale = std::max(scale, x.norm());
  for (const unsigned cap : {5000U, 3U}) {
    SCOPED_TRACE("max_iterations " + std::to_string(cap));
    HyperelasticSolver automatic(test::short_tube_mesh(0), problem(LinearSolver::automatic, cap),
                                 o);
    const auto& ra = automatic.solve();
    ASSERT_TRUE(ra.completed) << ra.stop_reason;
    std::cout << "  automatic, Krylov cap " << cap << ": " << to_string(ra.solver) << " ("
              << ra.solver_reason << ")\n";
    EXPECT_EQ(ra.solver_reason.rfind("auto:", 0), 0U) << ra.solver_reason;
    if (cap == 3U) {
      EXPECT_EQ(ra.solver, LinearSolver::direct);
      EXPECT_NE(ra.solver_reason.find("the assembled tangent from then on"), std::string::npos);
      EXPECT_EQ(ra.newton_iterations, rd.newton_iterations);
    } else {
      EXPECT_EQ(ra.solver, LinearSolver::matrix_free);
    }
    double diff = 0.0;
    for (std::size_t i = 0; i < rd.nodal_displacement.size(); ++i) {
      diff = std::max(diff, (ra.nodal_displacement[i] - rd.nodal_displacement[i]).norm());
    }
    EXPECT_LT(diff / scale, 1e-8);
  }
  HyperelasticOptions dead_load;
  dead_load.follower_pressure = false;
  HyperelasticSolver dead(test::short_tube_mesh(0), problem(LinearSolver::automatic, 5000),
                          dead_load);
  const auto& rs = dead.solve();
  ASSERT_TRUE(rs.completed) << rs.stop_reason;
  EXPECT_EQ(rs.solver, LinearSolver::direct) << rs.solver_reason;
}
