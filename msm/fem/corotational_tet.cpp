#include "msm/fem/corotational_tet.hpp"

#include "msm/fem/linear_tet.hpp"
#include "msm/fem/polar_rotation.hpp"

namespace vessel::msm {

double corotational_tet_energy(const std::array<Vec3, 4>& x, const TetRestShape& s,
                               const LameParameters& lame) {
  const Mat3 F = deformation_gradient(x, s);
  const Mat3 R = rotated_svd(F).rotation;
  const double t = (R.transpose() * F).trace() - 3.0;
  return s.volume * (lame.mu * (F - R).squaredNorm() + 0.5 * lame.lambda * t * t);
}

Vec12 corotational_tet_gradient(const std::array<Vec3, 4>& x, const TetRestShape& s,
                                const LameParameters& lame) {
  const Mat3 F = deformation_gradient(x, s);
  const Mat3 R = rotated_svd(F).rotation;
  const double t = (R.transpose() * F).trace() - 3.0;
  return tet_gradient_from_stress(s, 2.0 * lame.mu * (F - R) + lame.lambda * t * R);
}

Mat12 corotational_tet_hessian(const std::array<Vec3, 4>& x, const TetRestShape& s,
                               const LameParameters& lame) {
  const Mat3 F = deformation_gradient(x, s);
  const RotatedSvd svd = rotated_svd(F);
  const Mat3& R = svd.rotation;
  const double t = (R.transpose() * F).trace() - 3.0;
  // dP = 2μ(dF − dR) + λ (R:dF) R + λ t dR; the term λ (dR:F) R vanishes (dR = RΩ, Ω skew, RᵀF
  // symmetric).
  const Vec9 r = vec9(R);
  const Mat9 tangent = 2.0 * lame.mu * Mat9::Identity() + lame.lambda * r * r.transpose() +
                       (lame.lambda * t - 2.0 * lame.mu) * rotation_derivative(svd);
  return tet_hessian_from_tangent(s, tangent);
}

Mat12 corotational_tet_warped_stiffness(const std::array<Vec3, 4>& x, const TetRestShape& s,
                                        const LameParameters& lame) {
  const Mat3 R = rotated_svd(deformation_gradient(x, s)).rotation;
  Mat12 Rb = Mat12::Zero();
  for (int a = 0; a < 4; ++a) Rb.block<3, 3>(3 * a, 3 * a) = R;
  return Rb * linear_tet_stiffness(s, lame) * Rb.transpose();
}

CorotationalTetTerm::CorotationalTetTerm(const std::vector<Vec3>& nodes, std::vector<Tet> tets,
                                         LameParameters lame, CorotationalStiffness stiffness)
    : TetTerm(nodes, std::move(tets), lame, "corotational tet term"), stiffness_(stiffness) {}

double CorotationalTetTerm::element_energy(std::size_t k, const std::array<Vec3, 4>& x) const {
  return corotational_tet_energy(x, rest_shapes()[k], lame());
}

Vec12 CorotationalTetTerm::element_gradient(std::size_t k, const std::array<Vec3, 4>& x) const {
  return corotational_tet_gradient(x, rest_shapes()[k], lame());
}

Mat12 CorotationalTetTerm::element_hessian(std::size_t k, const std::array<Vec3, 4>& x,
                                           bool project_psd) const {
  if (stiffness_ == CorotationalStiffness::warped) {
    return corotational_tet_warped_stiffness(x, rest_shapes()[k], lame());  // PSD already
  }
  const Mat12 H = corotational_tet_hessian(x, rest_shapes()[k], lame());
  return project_psd ? psd_projection(H) : H;
}

}  // namespace vessel::msm
