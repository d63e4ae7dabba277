#pragma once
/// Linear P1 FEM on the Form interface: the isotropic linear elastic tetrahedron, energy density
/// ψ = μ ε:ε + ½λ (tr ε)² with the small strain ε = sym(F) − I, so per tet
///   W = V₀ ψ,  P = 2μ ε + λ tr ε I,  ∂P/∂F = μ(I + T) + λ vec I vec Iᵀ (T: vec F ↦ vec Fᵀ),
/// and the element stiffness K₀ = V₀ Bᵀ (∂P/∂F) B, constant. W = ½ uᵀ K₀ u exactly (u = x − X).
/// Not rotation invariant: a rigid rotation strains it (what the corotational tet removes).
/// Units: positions m, Lamé parameters Pa, energy J, gradient N, Hessian N/m.
#include "msm/fem/tet_term.hpp"

namespace vessel::msm {

/// ∂P/∂F of the linear isotropic material, Pa (9×9, column-major vec).
Mat9 linear_elastic_tangent(const LameParameters& lame);

double linear_tet_energy(const std::array<Vec3, 4>& x, const TetRestShape& s,
                         const LameParameters& lame);
Vec12 linear_tet_gradient(const std::array<Vec3, 4>& x, const TetRestShape& s,
                          const LameParameters& lame);
/// K₀ (whatever x), N/m.
Mat12 linear_tet_stiffness(const TetRestShape& s, const LameParameters& lame);

/// Linear P1 FEM of a tet mesh as a Form (no damping).
class LinearTetTerm final : public TetTerm {
 public:
  LinearTetTerm(const std::vector<Vec3>& nodes, std::vector<Tet> tets, LameParameters lame);

 private:
  [[nodiscard]] double element_energy(std::size_t k, const std::array<Vec3, 4>& x) const override;
  [[nodiscard]] Vec12 element_gradient(std::size_t k, const std::array<Vec3, 4>& x) const override;
  [[nodiscard]] Mat12 element_hessian(std::size_t k, const std::array<Vec3, 4>& x,
                                      bool project_psd) const override;
};

}  // namespace vessel::msm
