#pragma once
/// The volume term of the hybrid mass-spring system of Golec, Palierne, Zara, Nicolle & Damiand
/// (2020), "Hybrid 3D mass-spring system for simulation of isotropic materials with any Poisson's
/// ratio", The Visual Computer 36(4): 809–825: an energy of each tetrahedron's volume alone,
/// insensitive to its change of shape, added to a spring network so that the network reaches any
/// Lamé λ (a spring network alone obeys the Cauchy relation λ = μ, ν = 1/4).
///
/// Per tet (rest volume V₀, current signed volume V, bulk stiffness κ in Pa):
///   W = ½·κ·V₀·(V/V₀ − 1)² = ½·κ·(V − V₀)²/V₀,
///   ∇W = κ·(V − V₀)/V₀ · ∇V,
///   ∇²W = κ/V₀ · ∇V ∇Vᵀ + κ·(V − V₀)/V₀ · ∇²V.
/// Under a small uniform strain ε, V − V₀ = V₀·tr ε, so W = ½·κ·V₀·(tr ε)²: the term adds exactly κ
/// to the network's λ and nothing to μ, on every tet whatever its shape (derivation of κ for the
/// network in model/mass_spring_model.hpp). Source check (2026-11): the paper's abstract was retrieved
/// ("supplement the spring deformation energy with an energy depending on the volume only,
/// insensitive to change of shape"); its own formulation (equations) was not, so this quadratic
/// form is the issue's, W = ½κV₀(V/V₀ − 1)², and the paper's equation numbers are not cited.
/// Units: positions m, κ Pa, volume m³, energy J, gradient N, Hessian N/m.
#include <array>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "msm/form/form.hpp"
#include "msm/terms/four_node_blocks.hpp"

namespace vessel::msm {

/// Signed volume (x1 − x0)·((x2 − x0) × (x3 − x0))/6 of the tet (x0, x1, x2, x3), m³.
double tet_signed_volume(const std::array<Vec3, 4>& x);
/// ∂V/∂(x0, x1, x2, x3) stacked, m².
Vec12 tet_volume_gradient(const std::array<Vec3, 4>& x);
/// ∂²V/∂x², m (constant in each edge vector, linear in the third: V is trilinear in the edges).
Mat12 tet_volume_hessian(const std::array<Vec3, 4>& x);

/// One tet's volume energy W = ½κ(V − V₀)²/|V₀|, J (V₀ the signed rest volume, nonzero).
double volume_energy(const std::array<Vec3, 4>& x, double rest_volume, double kappa);
Vec12 volume_gradient(const std::array<Vec3, 4>& x, double rest_volume, double kappa);
/// 12×12 Hessian; with project_psd, projected onto the positive semi-definite cone (eigenvalues
/// clamped at zero). For κ < 0 (ν < 1/4, see msm/stiffness/hybrid_moduli.hpp) the projection at rest is zero.
Mat12 volume_hessian(const std::array<Vec3, 4>& x, double rest_volume, double kappa,
                     bool project_psd);

/// The volume term of a tet mesh as a Form (no damping).
class VolumeTerm : public FourNodeTerm {
 public:
  /// `nodes`: rest positions (m) of num_nodes nodes; `tets` index them; κ in Pa. tet_factors: per
  /// tet, a factor f_e on κ (tet e's bulk stiffness is κ·f_e; empty: all 1; the homogenised rule's
  /// stability clip, volume_term_homogenised.hpp). Throws InputError for a tet of zero rest
  /// volume, a non-finite κ or factor, or a factor count other than the tet count.
  VolumeTerm(const std::vector<Vec3>& nodes, std::vector<Tet> tets, double kappa,
             std::vector<double> tet_factors = {});

  [[nodiscard]] double kappa() const { return kappa_; }
  /// κ of tet e (κ·f_e), Pa.
  [[nodiscard]] double tet_kappa(std::size_t e) const {
    return tet_factors_.empty() ? kappa_ : kappa_ * tet_factors_[e];
  }
  [[nodiscard]] const std::vector<Tet>& tets() const { return elements(); }
  [[nodiscard]] const std::vector<double>& rest_volumes() const { return rest_volumes_; }

 private:
  [[nodiscard]] double element_energy(std::size_t k, const std::array<Vec3, 4>& x) const override;
  [[nodiscard]] Vec12 element_gradient(std::size_t k, const std::array<Vec3, 4>& x) const override;
  [[nodiscard]] Mat12 element_hessian(std::size_t k, const std::array<Vec3, 4>& x,
                                      bool project_psd) const override;

  std::vector<double> rest_volumes_;
  double kappa_ = 0.0;
  std::vector<double> tet_factors_;  ///< empty: all 1
};

}  // namespace vessel::msm
