#pragma once
/// The rotation of a deformation gradient by the SVD with inversion handling, from Irving, Teran
/// & Fedkiw 2004, "Invertible finite elements for robust simulation of large deformation", SCA:
/// F = U Σ Vᵀ with U, V proper rotations (where det U or det V is negative, its column of the
/// smallest singular value is negated, and that σ with it), so σ₃ < 0 on an inverted tet and
/// R = U Vᵀ is always a rotation. Where F is not inverted this R is the polar factor of F
/// (F = R S, S = V Σ Vᵀ symmetric positive definite); on an inverted tet S keeps one negative
/// eigenvalue and R stays the nearest rotation.
///
/// Its derivative (Twigg & Kačić-Alesić 2010; Sifakis & Barbič 2012 §5): for a change dF, with
/// M = Uᵀ dF V, dR = U Ω Vᵀ, Ω skew, Ω_ij = (M_ij − M_ji)/(σ_i + σ_j) (i ≠ j). It is undefined
/// where two singular values sum to zero (a tet flattened with a repeated |σ|); there Ω_ij is set
/// to zero.
#include "msm/fem/tet_deformation.hpp"

namespace vessel::msm {

struct RotatedSvd {
  Mat3 U, V;      ///< proper rotations
  Vec3 sigma;     ///< descending magnitude; σ₃ < 0 on an inverted tet
  Mat3 rotation;  ///< R = U Vᵀ
};

/// F's rotated SVD and R.
RotatedSvd rotated_svd(const Mat3& F);

/// ∂vec R/∂vec F (9×9, column-major vec), from F's rotated SVD.
Mat9 rotation_derivative(const RotatedSvd& svd);

}  // namespace vessel::msm
