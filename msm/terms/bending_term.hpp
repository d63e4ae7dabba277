#pragma once
/// The bending term of a surface model: the hinge energy of Grinspun, Hirani, Desbrun & Schröder
/// (2003), "Discrete Shells", SCA 2003, on the dihedral angle of every interior edge of the surface
/// triangle mesh, with its stiffness from the wall's plate bending rigidity D = E·t³/(12(1 − ν²)).
///
/// Per hinge (interior edge ē shared by two triangles of rest areas A₁, A₂, Ā = A₁ + A₂; rest
/// dihedral angle θ̄, current θ):
///   Discrete Shells:  W = k_B·(θ − θ̄)²·‖ē‖/h̄,  h̄ = a third of the mean of the two triangles'
///                     heights over ē = Ā/(3‖ē‖),  so W = k_B·3‖ē‖²/Ā·(θ − θ̄)²;
///   our constant:     k_B = D/6,  i.e.  W = ½·k_h·(θ − θ̄)² with k_h = D·‖ē‖²/Ā  (N·m).
/// Why D/6 (derivation in docs/physics/discrete_shells.md, checked by the tests): a cylinder of radius R
/// meshed by a grid of a × b quads split into two triangles bends only at the axial edges, each by
/// the exterior angle a/R between neighbouring chord planes, so each quad (area ab) stores
/// k_B·3b²/(ab)·(a/R)² = 3k_B·ab/R²: energy density 3k_B/R², which equals the plate's D/(2R²) for
/// k_B = D/6. The same constant gives density (D/2)·(κ₁ + κ₂)² + c·κ₁κ₂ on a mesh of equilateral
/// triangles in any orientation (the Gaussian term's c differs from the plate's −D(1 − ν); its
/// integral only depends on boundary values for a plate). The pinched ring and the cantilever
/// strip in tests/msm/test_bending_term.cpp check it against closed forms.
///
/// Dihedral angle of the hinge (x0, x1, x2, x3): edge e = x1 − x0, triangles (x0, x1, x2) and
/// (x0, x3, x1) with normals N_A = e × (x2 − x0), N_B = (x3 − x0) × e (equal when flat),
///   θ = atan2((n_A × n_B)·ê, n_A·n_B) ∈ (−π, π]  (the robust form: accurate near 0 and ±π, where
///   acos of the dot product is not); 0 when flat.
/// Gradient (Bridson, Marino & Fedkiw 2003, "Simulation of clothing with folds and wrinkles", SCA;
/// Tamstorf & Grinspun 2013, "Discrete bending forces and their Jacobians", Graphical Models 75):
/// the opposite vertices move along their triangle's normal, ∂θ/∂x2 = −‖e‖·N_A/‖N_A‖²,
/// ∂θ/∂x3 = −‖e‖·N_B/‖N_B‖², and the edge's vertices take the rest by translation and rotation
/// invariance: with α_i = (x_i − x0)·e/‖e‖² (where x_i projects on the edge),
///   ∂θ/∂x0 = −(1 − α₂)·∂θ/∂x2 − (1 − α₃)·∂θ/∂x3,   ∂θ/∂x1 = −α₂·∂θ/∂x2 − α₃·∂θ/∂x3.
/// Hessian of θ: the chain rule through those expressions (bending_term.cpp), exact; checked
/// against finite differences of the gradient. W's Hessian k_h·(∇θ∇θᵀ + (θ − θ̄)∇²θ) is indefinite
/// away from rest; with project_psd each hinge's 12×12 block is projected onto the PSD cone
/// (eigenvalues clamped at zero), so that Newton's direction stays a descent direction.
/// Units: positions m, D N·m, k_h N·m (per rad²), energy J, gradient N, Hessian N/m.
#include <array>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "msm/form/form.hpp"
#include "msm/terms/volume_term.hpp"

namespace vessel::msm {

/// Plate bending rigidity D = E·t³/(12(1 − ν²)), N·m (E Pa, t m). InputError unless E > 0, t > 0
/// and 0 ≤ ν < 1 (finite).
double plate_bending_rigidity(double E, double thickness, double nu);

/// The hinge stiffness of Discrete Shells with k_B = D/6 (header): k_h = D·‖ē‖²/Ā (N·m), Ā the sum
/// of the two triangles' rest areas (m²), ‖ē‖ the rest edge length (m).
double discrete_shells_hinge_stiffness(double D, double edge_length, double area_sum);

/// Signed dihedral angle θ of the hinge (x0, x1, x2, x3), rad (header's convention).
double dihedral_angle(const std::array<Vec3, 4>& x);
/// ∂θ/∂(x0, x1, x2, x3) stacked, 1/m.
Vec12 dihedral_angle_gradient(const std::array<Vec3, 4>& x);
/// ∂²θ/∂x², 1/m².
Mat12 dihedral_angle_hessian(const std::array<Vec3, 4>& x);

/// One hinge's energy W = ½k_h(θ − θ̄)², J; its gradient, N; its Hessian, N/m (with project_psd,
/// projected onto the positive semi-definite cone).
double hinge_energy(const std::array<Vec3, 4>& x, double rest_angle, double k);
Vec12 hinge_gradient(const std::array<Vec3, 4>& x, double rest_angle, double k);
Mat12 hinge_hessian(const std::array<Vec3, 4>& x, double rest_angle, double k, bool project_psd);

/// A hinge: the edge (nodes[0], nodes[1]) and the opposite vertices nodes[2] (of the triangle that
/// runs nodes[0] → nodes[1]) and nodes[3].
struct Hinge {
  std::array<int, 4> nodes{};
  double rest_angle = 0.0;  ///< θ̄, rad
  double stiffness = 0.0;   ///< k_h, N·m
};

/// The hinges of a triangle mesh: one per edge shared by exactly two triangles (boundary and
/// non-manifold edges carry none), in a deterministic order.
std::vector<std::array<int, 4>> interior_hinges(const std::vector<Triangle>& triangles);

/// The Discrete Shells bending term of a triangle surface as a Form (no damping).
class BendingTerm : public FourNodeTerm {
 public:
  /// `nodes`: rest positions (m); `triangles` index them; D the plate bending rigidity (N·m).
  /// Throws InputError for a non-finite or negative D, an index out of range, or a degenerate
  /// (zero-area) triangle on a hinge.
  BendingTerm(const std::vector<Vec3>& nodes, const std::vector<Triangle>& triangles,
              double bending_rigidity);

  [[nodiscard]] double bending_rigidity() const { return rigidity_; }
  [[nodiscard]] const std::vector<Hinge>& hinges() const { return hinges_; }

 private:
  [[nodiscard]] double element_energy(std::size_t k, const std::array<Vec3, 4>& x) const override;
  [[nodiscard]] Vec12 element_gradient(std::size_t k, const std::array<Vec3, 4>& x) const override;
  [[nodiscard]] Mat12 element_hessian(std::size_t k, const std::array<Vec3, 4>& x,
                                      bool project_psd) const override;

  double rigidity_ = 0.0;
  std::vector<Hinge> hinges_;
};

}  // namespace vessel::msm
