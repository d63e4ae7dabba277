#pragma once
/// Corotational linear P1 FEM (Müller & Gross 2004, "Interactive virtual materials", Graphics
/// Interface: the element force f = R K₀ (Rᵀx − X), K₀ the linear tet stiffness, R the tet's
/// rotation). R is the rotation of F by the rotated SVD with inversion handling (Irving et al.
/// 2004; msm/fem/polar_rotation.hpp), the polar factor of F on an uninverted tet. Its energy
/// density is ψ = μ‖F − R‖² + ½λ (tr(RᵀF) − 3)² (Sifakis & Barbič 2012 §5.1.1), whose first
/// Piola stress P = 2μ(F − R) + λ tr(RᵀF − I) R equals R σ(ε), σ the linear stress of the
/// symmetric strain ε = RᵀF − I: its gradient is Müller & Gross's force exactly. Two stiffnesses:
///   consistent: ∂P/∂F = 2μ I + λ vec R vec Rᵀ + (λ tr(RᵀF − I) − 2μ) ∂R/∂F, the true Hessian of
///               the energy, for static Newton (msm/solvers/static_solver.hpp), which needs it to
///               converge quadratically; it can be indefinite, and project_psd projects each
///               tet's block onto the PSD cone;
///   warped:     R K₀ Rᵀ (R block-diagonal on the four corners; "stiffness warping", Müller &
///               Gross 2004), what real-time simulators (SOFA's TetrahedronFEMForceField) assemble
///               each step; always PSD; for implicit Euler (msm/solvers/integrators.hpp,
///               re-assembled each step with ImplicitMatrix::current_state, or K₀ once with
///               rest_prefactored).
/// Units: positions m, Lamé parameters Pa, energy J, gradient N, Hessian N/m.
#include "msm/fem/tet_term.hpp"

namespace vessel::msm {

enum class CorotationalStiffness { consistent, warped };

double corotational_tet_energy(const std::array<Vec3, 4>& x, const TetRestShape& s,
                               const LameParameters& lame);
Vec12 corotational_tet_gradient(const std::array<Vec3, 4>& x, const TetRestShape& s,
                                const LameParameters& lame);
/// The consistent tangent (exact Hessian of the energy), N/m.
Mat12 corotational_tet_hessian(const std::array<Vec3, 4>& x, const TetRestShape& s,
                               const LameParameters& lame);
/// The warped stiffness R K₀ Rᵀ, N/m.
Mat12 corotational_tet_warped_stiffness(const std::array<Vec3, 4>& x, const TetRestShape& s,
                                        const LameParameters& lame);

/// Corotational P1 FEM of a tet mesh as a Form (no damping); its hessian() is the consistent
/// tangent or the warped stiffness as `stiffness` says.
class CorotationalTetTerm final : public TetTerm {
 public:
  CorotationalTetTerm(const std::vector<Vec3>& nodes, std::vector<Tet> tets, LameParameters lame,
                      CorotationalStiffness stiffness = CorotationalStiffness::consistent);
  [[nodiscard]] CorotationalStiffness stiffness() const { return stiffness_; }

 private:
  [[nodiscard]] double element_energy(std::size_t k, const std::array<Vec3, 4>& x) const override;
  [[nodiscard]] Vec12 element_gradient(std::size_t k, const std::array<Vec3, 4>& x) const override;
  [[nodiscard]] Mat12 element_hessian(std::size_t k, const std::array<Vec3, 4>& x,
                                      bool project_psd) const override;

  CorotationalStiffness stiffness_;
};

}  // namespace vessel::msm
