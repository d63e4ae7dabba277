/// The FEM reference against independent truth: input validation, rigid-body motion, the
/// constant-strain patch test, equilibrium of reactions and applied loads, point evaluation, and
/// the system on the free DoFs against a second solver.
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>

#include <memory>
#include <set>

#include <cmath>
#include <string>

#include "fem_reference/elasticity.hpp"
#include "cube_mesh.hpp"
#include "fem_test_meshes.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/surface_loads.hpp"

using namespace vessel;
using namespace vessel::fem;

namespace {

const TetMesh& mesh0() { return test::short_tube_mesh(0); }

/// Message of the InputError the constructor throws, or "" if it throws none.
std::string input_error(const ElasticityProblem& p) {
  try {
    ElasticitySolver s(mesh0(), p);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// All four surface groups clamped to u = g(x).
ElasticityProblem all_boundary_prescribed(std::function<Vec3(const Vec3&)> g, int degree) {
  ElasticityProblem p;
  p.options.degree = degree;
  for (const char* grp : {"inlet", "outlet", "inner_wall", "outer_wall"}) {
    p.dirichlet.push_back(fem::DirichletCondition::clamped(grp, g));
  }
  return p;
}

double max_norm(const std::vector<Vec3>& v) {
  double m = 0;
  for (const auto& x : v) m = std::max(m, x.norm());
  return m;
}

}  // namespace

TEST(ElasticityInput, RejectsBadMaterialAndGroupsWithClearMessages) {
  ElasticityProblem p;
  p.material.youngs_modulus = 0.0;
  EXPECT_NE(input_error(p).find("Young's modulus"), std::string::npos);
  p = {};
  p.material.poisson_ratio = 0.51;
  EXPECT_NE(input_error(p).find("0 <= nu <= 0.5"), std::string::npos);
  p.material.poisson_ratio = -0.1;
  EXPECT_NE(input_error(p).find("Poisson"), std::string::npos);
  p = {};
  p.material.poisson_ratio = 0.5;
  p.options.formulation = Formulation::displacement;
  EXPECT_NE(input_error(p).find("mixed formulation"), std::string::npos);
  p = {};
  p.options.degree = 3;
  EXPECT_NE(input_error(p).find("degree"), std::string::npos);
  p = {};
  p.dirichlet = {fem::DirichletCondition::clamped("no_such_group")};
  EXPECT_NE(input_error(p).find("no_such_group"), std::string::npos);
  p = {};
  p.pressures = {{"lumen", 1.0}};
  EXPECT_NE(input_error(p).find("lumen"), std::string::npos);
  p = {};
  p.point_constraints = {{Vec3(0, 0, 0), 0}};  // the tube's axis: no node there
  EXPECT_NE(input_error(p).find("no mesh node"), std::string::npos);
}

TEST(ElasticityRigidBody, NoLoadGivesNoDisplacement) {
  for (int degree : {1, 2}) {
    ElasticityProblem p;
    p.options.degree = degree;
    p.dirichlet = {fem::DirichletCondition::clamped("inlet")};
    const auto r = solve_elasticity(mesh0(), p);
    EXPECT_EQ(max_norm(r.nodal_displacement), 0.0);
    EXPECT_EQ(r.strain_energy, 0.0);
  }
}

TEST(ElasticityRigidBody, ImposedRigidMotionIsReproducedWithoutStrain) {
  // u = c + ω × x, small rotation: a rigid motion has ε = 0 exactly (linear kinematics).
  const Vec3 c(1e-6, -2e-6, 0.5e-6);
  const Vec3 w(1e-4, 2e-4, -3e-4);
  auto g = [&](const Vec3& x) -> Vec3 { return c + w.cross(x); };
  for (int degree : {1, 2}) {
    const auto r = solve_elasticity(mesh0(), all_boundary_prescribed(g, degree));
    const auto& m = mesh0();
    double err = 0, ref = 0;
    for (std::size_t n = 0; n < m.nodes.size(); ++n) {
      err = std::max(err, (r.nodal_displacement[n] - g(m.nodes[n])).norm());
      ref = std::max(ref, g(m.nodes[n]).norm());
    }
    EXPECT_LT(err, 1e-10 * ref) << "P" << degree;
    EXPECT_LT(r.max_abs_principal_strain, 1e-10) << "P" << degree;
    // Energy scale of a strain of 1e-4 over the wall: ½ E ε² V ≈ 1e-10 J; a rigid motion is 0.
    EXPECT_LT(r.strain_energy, 1e-20) << "P" << degree;
    for (const auto& rx : r.reactions) EXPECT_LT(rx.force.norm(), 1e-12) << rx.group;
  }
}

TEST(ElasticityPatchTest, P1ReproducesAConstantStrainFieldExactly) {
  // u = A x + c on the whole boundary: the exact solution has ε = sym(A) everywhere and
  // σ = λ tr(ε) I + 2μ ε (hand-computed below), with no body force.
  Eigen::Matrix3d a;
  a << 1e-3, 2e-4, -3e-4, -1e-4, -2e-3, 5e-4, 4e-4, 1e-4, 1.5e-3;
  const Vec3 c(2e-6, 0, -1e-6);
  auto g = [&](const Vec3& x) -> Vec3 { return a * x + c; };
  const Eigen::Matrix3d eps = 0.5 * (a + a.transpose());
  for (int degree : {1, 2}) {
    auto p = all_boundary_prescribed(g, degree);
    p.material.poisson_ratio = 0.3;
    ElasticitySolver solver(mesh0(), p);
    const auto& r = solver.solve();
    const auto& m = mesh0();
    double err = 0;
    for (std::size_t n = 0; n < m.nodes.size(); ++n) {
      err = std::max(err, (r.nodal_displacement[n] - g(m.nodes[n])).norm());
    }
    EXPECT_LT(err, 1e-9 * 4e-3 * 2e-3) << "P" << degree;  // |A x| ≈ 2e-3 · 4 mm
    const double e = p.material.youngs_modulus, nu = 0.3;
    const double lambda = e * nu / ((1 + nu) * (1 - 2 * nu)), mu = e / (2 * (1 + nu));
    const Eigen::Matrix3d sigma = lambda * eps.trace() * Eigen::Matrix3d::Identity() + 2 * mu * eps;
    const int ij[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};
    for (std::size_t t = 0; t < m.tets.size(); t += 37) {
      for (int v = 0; v < 6; ++v) {
        EXPECT_NEAR(r.tet_strain[t][v], eps(ij[v][0], ij[v][1]), 1e-12);
        EXPECT_NEAR(r.tet_stress[t][v], sigma(ij[v][0], ij[v][1]), 1e-7 * sigma.norm());
      }
    }
    // Strain energy density ½ σ:ε times the mesh volume.
    const double w = 0.5 * (sigma.array() * eps.array()).sum() * mesh_volume(m);
    EXPECT_NEAR(r.strain_energy, w, 1e-9 * w);
    // Point evaluation anywhere inside reproduces the linear field.
    const Vec3 inside(0.0, 3.4e-3, 0.37e-3), inside2(-2.5e-3, -2.2e-3, 0.81e-3);
    const auto u = solver.displacement_at({inside, inside2});
    EXPECT_LT((u[0] - g(inside)).norm(), 1e-9 * g(inside).norm());
    EXPECT_LT((u[1] - g(inside2)).norm(), 1e-9 * g(inside2).norm());
  }
}

TEST(ElasticityEquilibrium, ReactionsBalanceAContactPatch) {
  const auto& m = mesh0();
  ContactPatchSpec spec;
  spec.point = Vec3(3e-3, 0, 0.5e-3);
  spec.radius = 0.5e-3;
  spec.force = 1e-3;  // 1 mN
  const TractionPatch patch = contact_patch(m, spec);
  for (int degree : {1, 2}) {
    ElasticityProblem p;
    p.options.degree = degree;
    p.dirichlet = {fem::DirichletCondition::clamped("inlet"),
                   fem::DirichletCondition::clamped("outlet")};
    p.patches = {patch};
    const auto r = solve_elasticity(m, p);
    // The integrated traction equals the patch's total force −F n̂ (exact quadrature of a
    // constant traction over the same flat triangles).
    const Vec3 total = -spec.force * patch.outward_normal;
    EXPECT_LT((r.applied_load - total).norm(), 1e-12 * spec.force);
    ASSERT_EQ(r.reactions.size(), 2u);
    const Vec3 sum = r.reactions[0].force + r.reactions[1].force;
    EXPECT_LT((sum + total).norm(), 1e-8 * spec.force) << "P" << degree;
    // The patch pushes the inner wall outward (+x at (a, 0, z)).
    const auto u = ElasticitySolver(m, p).solve().nodal_displacement;
    EXPECT_GT(max_norm(u), 0.0);
    EXPECT_GT(r.strain_energy, 0.0);
  }
}

TEST(ElasticityEquilibrium, ReactionBalancesGravity) {
  const auto& m = mesh0();
  ElasticityProblem p;
  p.options.degree = 1;
  p.dirichlet = {fem::DirichletCondition::clamped("inlet")};
  p.gravity = Vec3(0, -9.81, 0);
  const auto r = solve_elasticity(m, p);
  const Vec3 weight = p.material.density * p.gravity * mesh_volume(m);  // ρ g V
  EXPECT_LT((r.applied_load - weight).norm(), 1e-10 * weight.norm());
  EXPECT_LT((r.reactions[0].force + weight).norm(), 1e-8 * weight.norm());
}

namespace {
/// P2 on `m`, inlet clamped, 5 Pa on the inner wall, solved: the point-evaluation tests' problem.
std::unique_ptr<ElasticitySolver> solved_inlet_clamped_under_pressure(const TetMesh& m) {
  ElasticityProblem p;
  p.options.degree = 2;
  p.dirichlet = {fem::DirichletCondition::clamped("inlet")};
  p.pressures = {{"inner_wall", 5.0}};
  auto s = std::make_unique<ElasticitySolver>(m, p);
  s->solve();
  return s;
}
}  // namespace

TEST(ElasticityPointEvaluation, MatchesNodalValuesAndRefusesOutsidePoints) {
  const auto& m = mesh0();
  const auto solver = solved_inlet_clamped_under_pressure(m);
  const ElasticitySolver& s = *solver;
  const auto& r = s.result();
  std::vector<Vec3> pts;
  for (std::size_t n = 0; n < m.nodes.size(); n += 7) pts.push_back(m.nodes[n]);
  const auto u = s.displacement_at(pts);
  for (std::size_t k = 0; k < pts.size(); ++k) {
    EXPECT_LT((u[k] - r.nodal_displacement[k * 7]).norm(), 1e-9 * max_norm(r.nodal_displacement));
  }
  EXPECT_THROW((void)s.displacement_at({Vec3(0, 0, 0.5e-3)}), InputError);  // in the lumen
}

TEST(ElasticityPointEvaluation, ToleranceAcceptsPointsJustOutsideACurvedWall) {
  // A point 5 µm outside an outer-wall node (the chord error of a curved wall is of that order):
  // refused by default, evaluated with a tolerance, and then close to the node's value (the
  // field's gradient times 5 µm).
  const auto& m = mesh0();
  const auto solver = solved_inlet_clamped_under_pressure(m);
  const ElasticitySolver& s = *solver;
  const auto& r = s.result();
  int node = -1;  // the outer-wall node that moves most
  for (int n : m.group_nodes(*m.find_group("outer_wall", 2))) {
    if (node < 0 || r.nodal_displacement[n].norm() > r.nodal_displacement[node].norm()) node = n;
  }
  const Vec3 x = m.nodes[node];
  const Vec3 outside = x + 5e-6 * Vec3(x.x(), x.y(), 0.0).normalized();
  EXPECT_THROW((void)s.displacement_at({outside}), InputError);
  const Vec3 u = s.displacement_at({outside}, 0.25)[0];
  EXPECT_LT((u - r.nodal_displacement[node]).norm(), 0.02 * r.nodal_displacement[node].norm());
}

TEST(ElasticitySolvers, AmgCgAgreesWithTheDirectSolver) {
  // A second solver as independent check: UMFPACK vs CG with ML AMG (translations only, and all
  // six rigid-body modes), on a contact patch with clamped ends, P1 and P2.
  const auto& m = test::short_tube_mesh(1);
  ContactPatchSpec spec;
  spec.point = Vec3(3e-3, 0, 0.5e-3);
  spec.force = 1e-4;
  for (int degree : {1, 2}) {
    ElasticityProblem p;
    p.options.degree = degree;
    p.dirichlet = {DirichletCondition::clamped("inlet"), DirichletCondition::clamped("outlet")};
    p.patches = {contact_patch(m, spec)};
    p.options.solver = LinearSolver::direct;
    const auto direct = solve_elasticity(m, p);
    const double scale = max_norm(direct.nodal_displacement);
    for (bool rigid : {false, true}) {
      p.options.solver = LinearSolver::cg_amg;
      p.options.amg_rigid_body_modes = rigid;
      const auto cg = solve_elasticity(m, p);
      EXPECT_EQ(cg.solver, LinearSolver::cg_amg);
      EXPECT_GT(cg.iterations, 0u);
      double diff = 0;
      for (std::size_t n = 0; n < m.nodes.size(); ++n) {
        diff = std::max(diff, (cg.nodal_displacement[n] - direct.nodal_displacement[n]).norm());
      }
      std::cout << "  P" << degree << " AMG-CG (" << (rigid ? "6 rigid modes" : "3 translations")
                << "): " << cg.iterations << " iterations, max |u_cg - u_direct| / max |u| "
                << diff / scale << "\n";
      EXPECT_LT(diff, 1e-7 * scale) << "P" << degree << " rigid " << rigid;
    }
  }
}

TEST(FreeDisplacementSystem, AnAffineFieldsInterpolantStoresItsClosedFormEnergy) {
  // u(x) = x₀ b vanishes on the clamped face x₀ = 0 and is affine, so P1 and P2 hold it exactly:
  // ½ uᵀK u over the rows interpolate_rows fills must be the uniform strain's energy
  // (μ ε:ε + λ/2 (tr ε)²) L³, ε = sym(b ⊗ e₀). A row given another point or component breaks it.
  const double L = 1e-3;
  const vessel::TetMesh mesh = vessel::test::cube_mesh(2, L);
  const vessel::Vec3 b(1e-3, 2e-3, -1.5e-3);
  for (const int degree : {1, 2}) {
    ElasticityProblem p;
    p.material.poisson_ratio = 0.3;
    p.options.degree = degree;
    p.dirichlet = {DirichletCondition::clamped("x0")};
    const ElasticitySolver solver(mesh, p);
    FreeDisplacementSystem sys = solver.free_displacement_system();
    EXPECT_TRUE(sys.row_points.empty());  // only where asked for
    solver.set_row_points(sys);
    ASSERT_EQ(static_cast<Eigen::Index>(sys.row_points.size()), sys.K.rows());
    const Eigen::VectorXd u =
        interpolate_rows(sys, [&](const vessel::Vec3& x) -> vessel::Vec3 { return x[0] * b; });
    Eigen::Matrix3d eps = Eigen::Matrix3d::Zero();
    eps.col(0) += 0.5 * b;
    eps.row(0) += 0.5 * b.transpose();
    const double E = p.material.youngs_modulus, nu = p.material.poisson_ratio;
    const double mu = E / (2 * (1 + nu)), lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
    const double exact =
        (mu * eps.squaredNorm() + 0.5 * lambda * eps.trace() * eps.trace()) * L * L * L;
    EXPECT_NEAR(0.5 * u.dot(sys.K * u), exact, 1e-10 * exact) << "P" << degree;
  }
}

TEST(FreeDisplacementSystem, P2RowsOnACurvedWallLieOnItsCylinders) {
  // The tube's walls (r = 3 and 4 mm) as curved P2 geometry: every row's support point lies in
  // the wall, r ∈ [3, 4] mm, and the rows on the walls that are not mesh nodes (edge midpoints)
  // lie on the cylinders themselves. Through the flat tets' mapping an inner-wall edge's midpoint
  // would lie inside r = 3 mm (its chord).
  const vessel::TetMesh& mesh = vessel::test::short_tube_mesh(0);
  ElasticityProblem p;
  p.options.degree = 2;
  p.dirichlet = {DirichletCondition::clamped("inlet")};
  p.curved_surfaces = tube_curved_walls(3e-3, 4e-3);
  const ElasticitySolver solver(mesh, p);
  FreeDisplacementSystem sys = solver.free_displacement_system();
  solver.set_row_points(sys);
  std::set<std::array<long long, 3>> nodes;
  const auto key = [](const vessel::Vec3& x) {
    return std::array<long long, 3>{std::llround(x.x() * 1e9), std::llround(x.y() * 1e9),
                                    std::llround(x.z() * 1e9)};
  };
  for (const vessel::Vec3& x : mesh.nodes) nodes.insert(key(x));
  int inner_midpoints = 0, outer_midpoints = 0;
  for (const vessel::Vec3& x : sys.row_points) {
    const double r = std::hypot(x.x(), x.y());
    EXPECT_GE(r, 3e-3 * (1 - 1e-12));
    EXPECT_LE(r, 4e-3 * (1 + 1e-12));
    if (nodes.count(key(x)) != 0) continue;
    inner_midpoints += std::abs(r - 3e-3) < 1e-15;
    outer_midpoints += std::abs(r - 4e-3) < 1e-15;
  }
  EXPECT_GT(inner_midpoints, 0);
  EXPECT_GT(outer_midpoints, 0);
}

TEST(FreeDisplacementSystem, SolvedByASecondSolverItGivesTheStaticSolution) {
  // What the harness factorises to time P1 and P2 as a simulator runs them: the system on the
  // free DoFs, solved here by Eigen's LDLT, must give solve()'s displacements (CHOLMOD on the
  // constrained full system) at every free DoF, on the displacement formulation at P1 and P2.
  const vessel::TetMesh mesh = vessel::test::cube_mesh(3, 1e-3);
  for (const int degree : {1, 2}) {
    ElasticityProblem p;
    p.material.poisson_ratio = 0.45;
    p.options.degree = degree;
    p.dirichlet = {DirichletCondition::clamped("x0")};
    p.pressures = {{"x1", 100.0}};
    p.gravity = vessel::Vec3(0, 0, -9.81);
    ElasticitySolver solver(mesh, p);
    const FreeDisplacementSystem sys = solver.free_displacement_system();
    solver.solve();
    const std::vector<double> u = solver.solution_dofs();
    ASSERT_EQ(sys.free_index.size(), u.size());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(sys.K);
    ASSERT_EQ(ldlt.info(), Eigen::Success);
    const Eigen::VectorXd x = ldlt.solve(sys.f);
    double diff = 0.0, norm = 0.0;
    int free = 0;
    for (std::size_t d = 0; d < u.size(); ++d) {
      if (sys.free_index[d] < 0) continue;
      ++free;
      diff = std::max(diff, std::abs(x[sys.free_index[d]] - u[d]));
      norm = std::max(norm, std::abs(u[d]));
    }
    EXPECT_EQ(free, sys.K.rows());
    EXPECT_LT(free, static_cast<int>(u.size()));  // the clamped face's DoFs are not in it
    EXPECT_GT(norm, 0.0);
    EXPECT_LE(diff, 1e-10 * norm) << "P" << degree;
  }
  ElasticityProblem mixed;
  mixed.material.poisson_ratio = 0.5;
  mixed.options.degree = 2;
  mixed.options.formulation = Formulation::mixed;
  mixed.dirichlet = {DirichletCondition::clamped("x0")};
  EXPECT_THROW((void)ElasticitySolver(mesh, mixed).free_displacement_system(), vessel::InputError);
}
