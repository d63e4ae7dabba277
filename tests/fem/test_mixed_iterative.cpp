/// The block-preconditioned FGMRES solver of the mixed (Taylor–Hood) system against a second,
/// independent solver (UMFPACK's LU of the same matrix), at ν = 0.49 and 0.5, under a contact
/// patch (clamped ends) and internal pressure (rollers): displacements and stresses (which carry
/// the pressure unknown) agree to the iteration tolerance.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>

#include "fem_reference/elasticity.hpp"
#include "fem_test_meshes.hpp"
#include "lame_problem.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/surface_loads.hpp"

using namespace vessel;
using namespace vessel::fem;

namespace {

ElasticityProblem contact_problem(const TetMesh& m, double nu) {
  ElasticityProblem p;
  p.material.poisson_ratio = nu;
  p.options.formulation = Formulation::mixed;
  p.dirichlet = {DirichletCondition::clamped("inlet"), DirichletCondition::clamped("outlet")};
  ContactPatchSpec spec;
  spec.point = Vec3(3e-3, 0, 0.5e-3);
  spec.force = 1e-4;
  p.patches = {contact_patch(m, spec)};
  return p;
}

/// max over nodes |a − b| / max |b|, and the same for the tets' stresses.
std::pair<double, double> difference(const ElasticityResult& a, const ElasticityResult& b) {
  double du = 0, su = 0, ds = 0, ss = 0;
  for (std::size_t n = 0; n < b.nodal_displacement.size(); ++n) {
    du = std::max(du, (a.nodal_displacement[n] - b.nodal_displacement[n]).norm());
    su = std::max(su, b.nodal_displacement[n].norm());
  }
  for (std::size_t t = 0; t < b.tet_stress.size(); ++t) {
    for (int c = 0; c < 6; ++c) {
      ds = std::max(ds, std::abs(a.tet_stress[t][c] - b.tet_stress[t][c]));
      ss = std::max(ss, std::abs(b.tet_stress[t][c]));
    }
  }
  return {du / su, ds / ss};
}

}  // namespace

TEST(MixedIterative, BlockPreconditionedGmresAgreesWithTheDirectSolver) {
  const auto& m = test::short_tube_mesh(0);
  for (double nu : {0.49, 0.5}) {
    for (bool contact : {true, false}) {
      ElasticityProblem p =
          contact ? contact_problem(m, nu) : test::lame_problem(nu, 2, Formulation::mixed);
      p.options.solver = LinearSolver::direct;
      const auto direct = solve_elasticity(m, p);
      p.options.solver = LinearSolver::gmres_block;
      const auto it = solve_elasticity(m, p);
      EXPECT_EQ(it.solver, LinearSolver::gmres_block);
      EXPECT_GT(it.iterations, 0u);
      const auto [du, ds] = difference(it, direct);
      std::cout << "  nu " << nu << (contact ? " contact" : " pressure") << ": " << it.n_dofs
                << " DoFs, " << it.iterations << " FGMRES iterations, |du| " << du << ", |dsigma| "
                << ds << "\n";
      EXPECT_LT(du, 1e-7) << nu << " " << contact;
      EXPECT_LT(ds, 1e-6) << nu << " " << contact;
    }
  }
}

TEST(MixedIterative, AutomaticChoosesGmresAboveTheMixedDirectLimit) {
  const auto& m = test::short_tube_mesh(0);
  auto p = contact_problem(m, 0.5);
  p.options.direct_max_mixed_dofs = 10;
  EXPECT_EQ(solve_elasticity(m, p).solver, LinearSolver::gmres_block);
  p.options.direct_max_mixed_dofs = 1000000;
  EXPECT_EQ(solve_elasticity(m, p).solver, LinearSolver::direct);
}

TEST(MixedIterative, SolverAndFormulationMismatchIsRefused) {
  const auto& m = test::short_tube_mesh(0);
  auto p = contact_problem(m, 0.49);
  p.options.solver = LinearSolver::cg_amg;  // CG cannot solve the indefinite mixed system
  EXPECT_THROW(solve_elasticity(m, p), InputError);
  p.options.formulation = Formulation::displacement;
  p.options.solver = LinearSolver::gmres_block;
  EXPECT_THROW(solve_elasticity(m, p), InputError);
}
