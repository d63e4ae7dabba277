#pragma once
/// The stable neo-Hookean tetrahedron without its log term, in Macklin & Müller's form: from
/// Macklin & Müller 2021, "A constraint-based formulation of stable neo-Hookean materials", MIG
/// (after Smith, de Goes & Kim 2018, "Stable neo-Hookean flesh simulation", ACM TOG 37(2)),
///   ψ = ½μ (I_C − 3) + ½λ (J − α)²,  I_C = tr(FᵀF), J = det F, α = 1 + μ/λ,
///   P = μ F + λ (J − α) ∂J/∂F,  ∂J/∂F = [f₁×f₂, f₂×f₀, f₀×f₁] (f_i: F's columns),
///   ∂P/∂F = μ I + λ vec ∂J/∂F vec ∂J/∂Fᵀ + λ (J − α) ∂²J/∂F²,
/// per tet W = V₀ψ. α makes the rest state stress free. Under small strain its Hessian at rest is
/// the linear isotropic material's with Lamé parameters μ and λ − μ (∂²J/∂F² at I contributes
/// −μ((tr H)² − tr H²)), so to reproduce a linear material (μ, λ_lin) take λ = λ_lin + μ
/// (snh_lambda_for_linear). ψ at rest is μ²/(2λ), not 0 (the paper's form, kept).
/// Units: positions m, Lamé parameters Pa, energy J, gradient N, Hessian N/m.
#include "msm/fem/tet_term.hpp"

namespace vessel::msm {

/// The λ of the stable neo-Hookean energy whose small-strain limit is the linear material with
/// Lamé parameters (μ, λ_lin): λ_lin + μ, Pa.
inline double snh_lambda_for_linear(const LameParameters& linear) {
  return linear.lambda + linear.mu;
}

/// ∂J/∂F, the cofactor matrix of F.
Mat3 determinant_gradient(const Mat3& F);
/// ∂²J/∂F² (9×9, column-major vec).
Mat9 determinant_hessian(const Mat3& F);

/// Per tet, with `lame` the energy's own (μ, λ), λ > 0.
double stable_neo_hookean_energy(const std::array<Vec3, 4>& x, const TetRestShape& s,
                                 const LameParameters& lame);
Vec12 stable_neo_hookean_gradient(const std::array<Vec3, 4>& x, const TetRestShape& s,
                                  const LameParameters& lame);
Mat12 stable_neo_hookean_hessian(const std::array<Vec3, 4>& x, const TetRestShape& s,
                                 const LameParameters& lame);

/// The stable neo-Hookean energy of a tet mesh as a Form (no damping). `lame`: the energy's own
/// (μ, λ) (use snh_lambda_for_linear for a linear material's); InputError for λ ≤ 0.
class StableNeoHookeanTerm final : public TetTerm {
 public:
  StableNeoHookeanTerm(const std::vector<Vec3>& nodes, std::vector<Tet> tets, LameParameters lame);

 private:
  [[nodiscard]] double element_energy(std::size_t k, const std::array<Vec3, 4>& x) const override;
  [[nodiscard]] Vec12 element_gradient(std::size_t k, const std::array<Vec3, 4>& x) const override;
  [[nodiscard]] Mat12 element_hessian(std::size_t k, const std::array<Vec3, 4>& x,
                                      bool project_psd) const override;
};

}  // namespace vessel::msm
