#pragma once
/// A P1 tetrahedron's deformation gradient and its derivative: what every per-tet hyperelastic
/// kernel in msm/fem shares. With the edge matrices D_s = [x1 − x0, x2 − x0, x3 − x0] (current)
/// and D_m (rest), F = D_s D_m⁻¹ is constant over the tet and linear in the corners, vec F = B x
/// (vec column-major: entry F_ij at i + 3j; x the 12 corner coordinates stacked). A per-tet energy
/// V₀ ψ(F) then has gradient V₀ Bᵀ vec P (P = ∂ψ/∂F) and Hessian V₀ Bᵀ (∂P/∂F) B (Sifakis &
/// Barbič 2012, "FEM simulation of 3D deformable solids", SIGGRAPH course notes, §4).
/// Units: positions m, F dimensionless.
#include <array>

#include "msm/terms/four_node_blocks.hpp"

namespace vessel::msm {

using Mat3 = Eigen::Matrix3d;
using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Mat9x12 = Eigen::Matrix<double, 9, 12>;

/// [x1 − x0, x2 − x0, x3 − x0], m.
Mat3 tet_edge_matrix(const std::array<Vec3, 4>& x);

/// A tet's rest shape: D_m⁻¹ (1/m), V₀ = |det D_m|/6 (m³) and B = ∂vec F/∂x (1/m).
struct TetRestShape {
  Mat3 rest_inverse;
  double volume = 0.0;
  Mat9x12 dF_dx;
};
/// Throws InputError if the rest tet is degenerate (zero volume).
TetRestShape tet_rest_shape(const std::array<Vec3, 4>& rest);

/// F = D_s D_m⁻¹.
Mat3 deformation_gradient(const std::array<Vec3, 4>& x, const TetRestShape& shape);

/// vec(M), column-major.
inline Vec9 vec9(const Mat3& m) { return Eigen::Map<const Vec9>(m.data()); }

/// Per-tet energy V₀ψ: gradient V₀ Bᵀ vec P (N) and Hessian V₀ Bᵀ (∂P/∂F) B (N/m).
inline Vec12 tet_gradient_from_stress(const TetRestShape& s, const Mat3& P) {
  return s.volume * s.dF_dx.transpose() * vec9(P);
}
inline Mat12 tet_hessian_from_tangent(const TetRestShape& s, const Mat9& dP_dF) {
  return s.volume * s.dF_dx.transpose() * dP_dF * s.dF_dx;
}

}  // namespace vessel::msm
