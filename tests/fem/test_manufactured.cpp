/// Convergence with a manufactured solution prescribed on the whole boundary: no curved geometry
/// is involved (the mesh is the domain), so the orders are the elements' own: 2 for P1 and 3 for
/// P2 in L2 (Ciarlet, The Finite Element Method for Elliptic Problems, Thm 3.2.5 with
/// Aubin–Nitsche).
#include <gtest/gtest.h>

#include <iomanip>
#include <iostream>

#include "fem_reference/convergence.hpp"
#include "fem_reference/elasticity.hpp"
#include "fem_test_meshes.hpp"

using namespace vessel;
using namespace vessel::fem;

namespace {

constexpr double kScale = 1e3;  // 1/m², so |u| ≈ 1e3 · (4 mm)³ ≈ 6e-5 m

/// u = s (x²y, y²z, z²x).
Vec3 u_exact(const Vec3& p) {
  const double x = p.x(), y = p.y(), z = p.z();
  return kScale * Vec3(x * x * y, y * y * z, z * z * x);
}

/// b = −div σ = −[(λ+μ) ∇(div u) + μ Δu], hand-derived for u_exact:
/// div u = s(2xy + 2yz + 2zx), ∇ div u = 2s(y+z, x+z, x+y), Δu = 2s(y, z, x).
Vec3 body_force(const Vec3& p, double lambda, double mu) {
  const double x = p.x(), y = p.y(), z = p.z();
  const Vec3 grad_div = 2 * kScale * Vec3(y + z, x + z, x + y);
  const Vec3 laplacian = 2 * kScale * Vec3(y, z, x);
  return -((lambda + mu) * grad_div + mu * laplacian);
}

double error_on_level(int degree, int level, double nu) {
  ElasticityProblem p;
  p.material.poisson_ratio = nu;
  p.options.degree = degree;
  p.options.formulation = Formulation::displacement;
  const double lambda = p.material.lambda(), mu = p.material.mu();
  p.body_force = [=](const Vec3& x) { return body_force(x, lambda, mu); };
  for (const char* g : {"inlet", "outlet", "inner_wall", "outer_wall"}) {
    p.dirichlet.push_back(fem::DirichletCondition::clamped(g, u_exact));
  }
  ElasticitySolver s(test::short_tube_mesh(level), p);
  const auto& r = s.solve();
  const double e = s.relative_l2_error(u_exact);
  std::cout << "  manufactured nu=" << nu << " " << r.element << " level " << level << " dofs "
            << r.n_dofs << " rel L2 error " << std::scientific << std::setprecision(3) << e
            << std::defaultfloat << "\n";
  return e;
}

}  // namespace

TEST(ManufacturedSolution, P1ConvergesWithOrderTwo) {
  const double p = observed_order(error_on_level(1, 0, 0.3), error_on_level(1, 1, 0.3));
  std::cout << "  P1 observed order " << p << "\n";
  EXPECT_NEAR(p, 2.0, 0.25);
}

TEST(ManufacturedSolution, P2ConvergesWithOrderThree) {
  const double p = observed_order(error_on_level(2, 0, 0.3), error_on_level(2, 1, 0.3));
  std::cout << "  P2 observed order " << p << "\n";
  EXPECT_NEAR(p, 3.0, 0.3);
}
