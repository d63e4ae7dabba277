#pragma once
/// The finite-strain verification problems shared by the fast and the slow tests: Rivlin's tube
/// (incompressible, follower pressure) and a manufactured solution of compressible neo-Hookean,
/// each returning its relative L2 error on one level of the short structured tube.
#include <array>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <stdexcept>

#include "fem_reference/hyperelastic.hpp"
#include "fem_reference/rivlin.hpp"
#include "fem_test_meshes.hpp"

namespace vessel::test {

/// Rivlin's pressure for the hoop stretch a/A = 1.3: 0.1627 μ (docs/physics/finite_strain.md).
inline double rivlin_test_pressure(const fem::RivlinTube& t) {
  return t.pressure(1.3 * t.inner_radius);
}

struct FiniteRun {
  double error = 0.0;  ///< relative L2 error of the displacement
  fem::HyperelasticResult result;
};

/// The short tube at ν = 0.5 (Taylor–Hood, curved walls), follower pressure on the inner wall,
/// axial rollers on both ends (plane strain), against Rivlin's displacement.
inline FiniteRun rivlin_run(int level) {
  const fem::RivlinTube tube;
  const double P = rivlin_test_pressure(tube);
  fem::ElasticityProblem p;
  p.material.poisson_ratio = 0.5;
  p.options.formulation = fem::Formulation::mixed;
  p.dirichlet = {fem::DirichletCondition::roller("inlet", 2),
                 fem::DirichletCondition::roller("outlet", 2)};
  p.point_constraints = tube_in_plane_pins(3e-3, 0.0);
  p.pressures = {{"inner_wall", P}};
  p.curved_surfaces = fem::tube_curved_walls(3e-3, 4e-3);
  fem::HyperelasticSolver s(short_tube_mesh(level), p);
  FiniteRun run;
  run.result = s.solve();
  if (!run.result.completed) throw std::runtime_error(run.result.stop_reason);
  run.error = s.relative_l2_error([&](const Vec3& x) { return tube.displacement(x, P); });
  std::cout << "  Rivlin level " << level << " " << run.result.element << " dofs "
            << run.result.n_dofs << " steps " << run.result.steps.size() << " Newton "
            << run.result.newton_iterations << " rel L2 error " << std::scientific
            << std::setprecision(3) << run.error << std::defaultfloat << " ("
            << run.result.timings.assembly + run.result.timings.solve << " s)\n";
  return run;
}

/// u = s (x²y, y²z, z²x) with s = 1.25e4 /m²: about 20 % strain on the tube (|x| ≤ 4 mm).
inline constexpr double kManufacturedScale = 1.25e4;

inline Vec3 manufactured_u(const Vec3& p) {
  const double x = p.x(), y = p.y(), z = p.z();
  return kManufacturedScale * Vec3(x * x * y, y * y * z, z * z * x);
}

/// F = I + ∇u of manufactured_u, by hand.
inline fem::Mat3 manufactured_F(const Vec3& p) {
  const double s = kManufacturedScale, x = p.x(), y = p.y(), z = p.z();
  return fem::Mat3::Identity() +
         s * (fem::Mat3() << 2 * x * y, x * x, 0, 0, 2 * y * z, y * y, z * z, 0, 2 * z * x)
                 .finished();
}

/// ∂F/∂X_J of manufactured_u, by hand: (∂F/∂X_J)_aL = ∂²u_a/∂X_L∂X_J (u_0: ∂xx = 2sy,
/// ∂xy = 2sx; u_1: ∂yy = 2sz, ∂yz = 2sy; u_2: ∂zz = 2sx, ∂zx = 2sz).
inline std::array<fem::Mat3, 3> manufactured_dF(const Vec3& p) {
  const double s = kManufacturedScale, x = p.x(), y = p.y(), z = p.z();
  std::array<fem::Mat3, 3> H;  // H[a](L, J) = ∂²u_a/∂X_L∂X_J
  H[0] << 2 * s * y, 2 * s * x, 0, 2 * s * x, 0, 0, 0, 0, 0;
  H[1] << 0, 0, 0, 0, 2 * s * z, 2 * s * y, 0, 2 * s * y, 0;
  H[2] << 0, 0, 2 * s * z, 0, 0, 0, 2 * s * z, 0, 2 * s * x;
  std::array<fem::Mat3, 3> dF;
  for (int J = 0; J < 3; ++J)
    for (int a = 0; a < 3; ++a)
      for (int L = 0; L < 3; ++L) dF[J](a, L) = H[a](L, J);
  return dF;
}

/// Compressible neo-Hookean's first Piola–Kirchhoff stress written here, apart from the product:
/// Ψ = μ/2 (tr FᵀF − 3) − μ ln J + λ/2 (ln J)², P = ∂Ψ/∂F = μ F + (λ ln J − μ) F⁻ᵀ (Bonet & Wood,
/// Nonlinear Continuum Mechanics for FEA, 2nd ed., eq. 6.28). test_hyperelastic_verification.cpp
/// checks it against finite differences of the product's energy.
inline fem::Mat3 neo_hookean_stress(const fem::Mat3& F, double mu, double lambda) {
  const fem::Mat3 F_invT = F.inverse().transpose();
  return mu * F + (lambda * std::log(F.determinant()) - mu) * F_invT;
}

/// b = −Div P(F(X)), Div P_a = Σ_J ∂P_aJ/∂X_J, by the chain rule on neo_hookean_stress:
/// ∂_J P = μ ∂_J F + λ tr(F⁻¹ ∂_J F) F⁻ᵀ − (λ ln J − μ) F⁻ᵀ (∂_J F)ᵀ F⁻ᵀ (∂_J ln J = tr(F⁻¹ ∂_J F),
/// ∂_J F⁻ᵀ = −F⁻ᵀ (∂_J F)ᵀ F⁻ᵀ). Independent of the product's stress and tangent.
inline Vec3 manufactured_body_force(const Vec3& p, double mu, double lambda) {
  const fem::Mat3 F = manufactured_F(p);
  const fem::Mat3 F_inv = F.inverse();
  const fem::Mat3 F_invT = F_inv.transpose();
  const double c = lambda * std::log(F.determinant()) - mu;
  const auto dF = manufactured_dF(p);
  Vec3 div = Vec3::Zero();
  for (int J = 0; J < 3; ++J) {
    const fem::Mat3 dP = mu * dF[J] + lambda * (F_inv * dF[J]).trace() * F_invT -
                         c * F_invT * dF[J].transpose() * F_invT;
    div += dP.col(J);
  }
  return -div;
}

/// The manufactured solution prescribed on the whole boundary, compressible (ν = 0.3).
inline FiniteRun manufactured_run(int degree, int level) {
  fem::ElasticityProblem p;
  p.material.poisson_ratio = 0.3;
  p.options.degree = degree;
  p.options.formulation = fem::Formulation::displacement;
  const double mu = p.material.mu(), lambda = p.material.lambda();
  p.body_force = [mu, lambda](const Vec3& x) { return manufactured_body_force(x, mu, lambda); };
  for (const char* g : {"inlet", "outlet", "inner_wall", "outer_wall"})
    p.dirichlet.push_back(fem::DirichletCondition::clamped(g, manufactured_u));
  fem::HyperelasticSolver s(short_tube_mesh(level), p);
  FiniteRun run;
  run.result = s.solve();
  if (!run.result.completed) throw std::runtime_error(run.result.stop_reason);
  run.error = s.relative_l2_error(manufactured_u);
  std::cout << "  manufactured " << run.result.element << " level " << level << " dofs "
            << run.result.n_dofs << " steps " << run.result.steps.size() << " Newton "
            << run.result.newton_iterations << " max strain " << run.result.max_abs_principal_strain
            << " rel L2 error " << std::scientific << std::setprecision(3) << run.error
            << std::defaultfloat << "\n";
  return run;
}

}  // namespace vessel::test
