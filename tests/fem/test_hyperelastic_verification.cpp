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

// The manufactured problem's truth is the test's own: its stress is the derivative of the
// product's energy (central differences, h = 1e-6 on F ~ 1), and its body force the divergence
// of that stress (central differences in X, h = 1e-7 m on a 4 mm tube), at points of the tube.
TEST(ManufacturedFiniteStrain, BodyForceIsTheDivergenceOfTheEnergysStress) {
  const Material m{14.24e3, 0.3};
  const NeoHookean nh = NeoHookean::of(m);
  for (const Vec3& X : {Vec3(3.2e-3, 1.1e-3, 2.0e-3), Vec3(-2.5e-3, 3.0e-3, 4.5e-3),
                        Vec3(0.4e-3, -3.9e-3, 0.7e-3)}) {
    const Mat3 F = test::manufactured_F(X);
    const Mat3 P = test::neo_hookean_stress(F, m.mu(), m.lambda());
    for (int a = 0; a < 3; ++a) {
      for (int J = 0; J < 3; ++J) {
        const double h = 1e-6;
        Mat3 Fp = F, Fm = F;
        Fp(a, J) += h;
        Fm(a, J) -= h;
        const double dpsi = (nh.energy(Fp) - nh.energy(Fm)) / (2 * h);
        EXPECT_NEAR(P(a, J), dpsi, 1e-6 * P.norm()) << a << J;
      }
    }
    Vec3 div = Vec3::Zero();
    for (int J = 0; J < 3; ++J) {
      const double h = 1e-7;
      const Vec3 e = Vec3::Unit(J) * h;
      div += (test::neo_hookean_stress(test::manufactured_F(X + e), m.mu(), m.lambda()) -
              test::neo_hookean_stress(test::manufactured_F(X - e), m.mu(), m.lambda()))
                 .col(J) /
             (2 * h);
    }
    const Vec3 b = test::manufactured_body_force(X, m.mu(), m.lambda());
    EXPECT_LT((b + div).norm(), 1e-6 * div.norm()) << b.transpose() << " vs " << -div.transpose();
    // F from manufactured_u by differences too.
    for (int J = 0; J < 3; ++J) {
      const Vec3 e = Vec3::Unit(J) * 1e-7;
      const Vec3 col = (test::manufactured_u(X + e) - test::manufactured_u(X - e)) / 2e-7;
      EXPECT_LT((F.col(J) - Vec3::Unit(J) - col).norm(), 1e-8) << J;
    }
  }
}

TEST(ManufacturedFiniteStrain, P1ConvergesWithOrderTwo) {
  const double e0 = test::manufactured_run(1, 0).error, e1 = test::manufactured_run(1, 1).error;
  const double p = observed_order(e0, e1);
  std::cout << "  P1 observed order " << p << "\n";
  EXPECT_NEAR(p, 2.0, 0.1);  // measured 2.01 (errors 3.29e-2, 8.19e-3)
}

TEST(ManufacturedFiniteStrain, P2ConvergesWithOrderThree) {
  const double e0 = test::manufactured_run(2, 0).error, e1 = test::manufactured_run(2, 1).error;
  const double p = observed_order(e0, e1);
  std::cout << "  P2 observed order " << p << "\n";
  EXPECT_NEAR(p, 3.0, 0.1);  // measured 3.01 (errors 9.21e-4, 1.14e-4)
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
