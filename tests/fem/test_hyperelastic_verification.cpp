/// The finite-strain reference against closed forms on the tube: Rivlin's inflation
/// (incompressible, Taylor–Hood, follower pressure), a manufactured solution (compressible, P1 and
/// P2) with observed orders, and the linear reference's limit: at small loads the two differ by
/// O(load²). The three-mesh studies are in test_hyperelastic_slow.cpp.
#include <gtest/gtest.h>

#include <iostream>

#include "fem_reference/convergence.hpp"
#include "hyperelastic_problems.hpp"
#include "lame_problem.hpp"

using namespace vessel;
using namespace vessel::fem;

TEST(RivlinTubeFem, TaylorHoodMatchesRivlinsInflation) {
  const auto run = test::rivlin_run(0);
  EXPECT_LT(run.error, 2e-3);
  EXPECT_GT(run.result.max_abs_principal_strain, 0.25);  // finite strain indeed
}

TEST(ManufacturedFiniteStrain, P1ConvergesWithOrderTwo) {
  const double e0 = test::manufactured_run(1, 0).error, e1 = test::manufactured_run(1, 1).error;
  const double p = observed_order(e0, e1);
  std::cout << "  P1 observed order " << p << "\n";
  EXPECT_NEAR(p, 2.0, 0.3);
}

TEST(ManufacturedFiniteStrain, P2ConvergesWithOrderThree) {
  const double e0 = test::manufactured_run(2, 0).error, e1 = test::manufactured_run(2, 1).error;
  const double p = observed_order(e0, e1);
  std::cout << "  P2 observed order " << p << "\n";
  EXPECT_NEAR(p, 3.0, 0.35);
}

TEST(FiniteStrainLinearLimit, DiffersFromTheLinearReferenceByLoadSquared) {
  // Lamé's problem (P1, level 0): ‖u_finite − u_linear‖ / ‖u_linear‖ ∝ load, so halving the
  // pressure halves it (the absolute difference is O(load²)).
  const TetMesh& mesh = test::short_tube_mesh(0);
  std::vector<double> rel;
  for (const double pressure : {40.0, 20.0, 10.0}) {
    auto p = test::lame_problem(0.3, 1, Formulation::displacement);
    p.pressures = {{"inner_wall", pressure}};
    const auto lin = solve_elasticity(mesh, p);
    HyperelasticSolver s(mesh, p);
    const auto& fin = s.solve();
    ASSERT_TRUE(fin.completed) << fin.stop_reason;
    double d2 = 0.0, n2 = 0.0;
    for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
      d2 += (fin.nodal_displacement[i] - lin.nodal_displacement[i]).squaredNorm();
      n2 += lin.nodal_displacement[i].squaredNorm();
    }
    rel.push_back(std::sqrt(d2 / n2));
    std::cout << "  pressure " << pressure << " Pa: max strain " << lin.max_abs_principal_strain
              << ", |u_finite - u_linear| / |u_linear| = " << rel.back() << "\n";
  }
  for (std::size_t k = 1; k < rel.size(); ++k) {
    const double ratio = rel[k - 1] / rel[k];
    std::cout << "  ratio at half the load " << ratio << " (2 for O(load^2))\n";
    EXPECT_NEAR(ratio, 2.0, 0.05);
  }
}
