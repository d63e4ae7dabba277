#pragma once
/// The springs of each tetrahedron coupled in pairs: the edge-based Saint Venant–Kirchhoff (StVK)
/// tetrahedron of Kikuuwe, Tabuchi & Yamamoto (2009), "An edge-based computationally efficient
/// formulation of Saint Venant-Kirchhoff tetrahedral finite elements", ACM Transactions on
/// Graphics 28(1), article 8. Their formulation "reduces to that of a spring-network model by
/// simply ignoring all the tetrahedron-sharing edge pairs": a spring network plus these pair
/// terms is linear P1 FEM's StVK tetrahedron, exactly. The suite uses it to show what a spring
/// network lacks to be as accurate as P1 (docs/physics/accuracy.md).
///
/// Per tet, with reference edge vectors D_k and current ones d_k (k = the six node pairs
/// (0,1), (0,2), (0,3), (1,2), (1,3), (2,3), D_k = X_b − X_a), the edge's squared-length change
/// δ_k = ½(d_k·d_k − D_k·D_k) equals D_kᵀ·E·D_k for the tet's Green strain E (d_k = F·D_k). The six
/// equations determine E: e = A⁻¹δ, with e = (E11, E22, E33, E23, E13, E12) and the row
/// A_k = (D1², D2², D3², 2D2D3, 2D1D3, 2D1D2). StVK's W = V₀(μ E:E + ½λ (tr E)²) = ½ eᵀ·S·e with
/// S = λ·(1 1 1 0 0 0)ᵀ(1 1 1 0 0 0) + 2μ·diag(1, 1, 1, 2, 2, 2), so
///   W = ½ δᵀ C δ,  C = V₀ A⁻ᵀ S A⁻¹ (6×6, from the rest shape alone),
///   ∇W = Σ_k t_k ∇δ_k with t = C δ (∇δ_k = −d_k at node a, +d_k at node b: forces along edges),
///   ∇²W = Bᵀ C B + Σ_k t_k G_k (B's rows ∇δ_kᵀ; G_k = [I −I; −I I] on the edge's two nodes).
/// C's diagonal is the spring part (each edge's biquadratic spring), its off-diagonal entries the
/// tetrahedron-sharing edge pairs. At rest (δ = 0) the Hessian Bᵀ C B is P1's element stiffness.
/// Units: positions m, λ and μ Pa, energy J, gradient N, Hessian N/m.
#include <string>
#include <array>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "msm/form/form.hpp"
#include "msm/kernels/spring_kernels.hpp"
#include "msm/terms/four_node_blocks.hpp"

namespace vessel::msm {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

/// The Lamé parameters of the StVK material the pair term carries, Pa.
struct LameParameters {
  double lambda = 0.0;
  double mu = 0.0;
};
/// λ = Eν/((1 + ν)(1 − 2ν)), μ = E/(2(1 + ν)). InputError for E ≤ 0 or ν outside [0, 0.5)
/// (λ is infinite at 0.5: displacement-only P1 cannot represent incompressibility either).
LameParameters lame_parameters(double E, double nu);
/// Why the edge-pair model cannot take E (Pa) and ν, or "" if it can (what lame_parameters
/// throws): ν in [0, 0.5), E > 0.
std::string edge_pair_refusal(double E, double nu);

/// The tet's edges as node pairs (a, b), in the order of C's rows.
inline constexpr std::array<std::array<int, 2>, 6> kTetEdges{
    {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};

/// C = V₀ A⁻ᵀ S A⁻¹ of the tet with rest corners X (header). InputError for a degenerate tet.
Mat6 edge_pair_coefficients(const std::array<Vec3, 4>& X, const LameParameters& lame);

/// δ_k = ½(|x_b − x_a|² − |X_b − X_a|²) for the six edges, m².
Vec6 edge_squared_length_changes(const std::array<Vec3, 4>& x, const std::array<Vec3, 4>& X);

/// One tet's energy ½ δᵀ C δ (J), gradient (N) and 12×12 Hessian (N/m; with project_psd,
/// projected onto the positive semi-definite cone).
double edge_pair_energy(const std::array<Vec3, 4>& x, const std::array<Vec3, 4>& X, const Mat6& C);
Vec12 edge_pair_gradient(const std::array<Vec3, 4>& x, const std::array<Vec3, 4>& X,
                         const Mat6& C);
Mat12 edge_pair_hessian(const std::array<Vec3, 4>& x, const std::array<Vec3, 4>& X, const Mat6& C,
                        bool project_psd);

/// Every tet's pair term as a Form (no damping).
class EdgePairTerm : public FourNodeTerm {
 public:
  /// `nodes`: rest positions (m); `tets` index them. InputError for a tet with an out-of-range
  /// node or zero rest volume.
  EdgePairTerm(const std::vector<Vec3>& nodes, std::vector<Tet> tets, const LameParameters& lame);

  /// Largest edge strain |l − L|/L over the tets' edges at x.
  [[nodiscard]] double max_strain(const VectorXd& x) const override;
  [[nodiscard]] const LameParameters& lame() const { return lame_; }

 private:
  [[nodiscard]] double element_energy(std::size_t k, const std::array<Vec3, 4>& x) const override;
  [[nodiscard]] Vec12 element_gradient(std::size_t k, const std::array<Vec3, 4>& x) const override;
  [[nodiscard]] Mat12 element_hessian(std::size_t k, const std::array<Vec3, 4>& x,
                                      bool project_psd) const override;

  LameParameters lame_;
  std::vector<std::array<Vec3, 4>> rest_corners_;  ///< per tet
  std::vector<Mat6> coefficients_;                 ///< C per tet
};

}  // namespace vessel::msm
