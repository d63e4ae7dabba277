#include "msm/fem/stable_neo_hookean.hpp"

#include <string>

#include "meshes/foundation/errors.hpp"

namespace vessel::msm {

namespace {

Mat3 cross_matrix(const Vec3& a) {
  Mat3 m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

double alpha(const LameParameters& lame) { return 1.0 + lame.mu / lame.lambda; }

}  // namespace

Mat3 determinant_gradient(const Mat3& F) {
  Mat3 g;
  g << F.col(1).cross(F.col(2)), F.col(2).cross(F.col(0)), F.col(0).cross(F.col(1));
  return g;
}

Mat9 determinant_hessian(const Mat3& F) {
  // d(f₁×f₂) = −[f₂]× df₁ + [f₁]× df₂, and cyclically (Smith et al. 2018, eq. 23's blocks).
  Mat9 h = Mat9::Zero();
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    h.block<3, 3>(3 * i, 3 * j) = -cross_matrix(F.col(k));
    h.block<3, 3>(3 * i, 3 * k) = cross_matrix(F.col(j));
  }
  return h;
}

double stable_neo_hookean_energy(const std::array<Vec3, 4>& x, const TetRestShape& s,
                                 const LameParameters& lame) {
  const Mat3 F = deformation_gradient(x, s);
  const double c = F.determinant() - alpha(lame);
  return s.volume * (0.5 * lame.mu * (F.squaredNorm() - 3.0) + 0.5 * lame.lambda * c * c);
}

Vec12 stable_neo_hookean_gradient(const std::array<Vec3, 4>& x, const TetRestShape& s,
                                  const LameParameters& lame) {
  const Mat3 F = deformation_gradient(x, s);
  const double c = F.determinant() - alpha(lame);
  return tet_gradient_from_stress(s, lame.mu * F + lame.lambda * c * determinant_gradient(F));
}

Mat12 stable_neo_hookean_hessian(const std::array<Vec3, 4>& x, const TetRestShape& s,
                                 const LameParameters& lame) {
  const Mat3 F = deformation_gradient(x, s);
  const double c = F.determinant() - alpha(lame);
  const Vec9 g = vec9(determinant_gradient(F));
  const Mat9 tangent = lame.mu * Mat9::Identity() + lame.lambda * g * g.transpose() +
                       lame.lambda * c * determinant_hessian(F);
  return tet_hessian_from_tangent(s, tangent);
}

StableNeoHookeanTerm::StableNeoHookeanTerm(const std::vector<Vec3>& nodes, std::vector<Tet> tets,
                                           LameParameters lame)
    : TetTerm(nodes, std::move(tets), lame, "stable neo-Hookean term") {
  if (!(lame.lambda > 0.0)) {
    throw InputError("stable neo-Hookean term: expected λ > 0 (Pa), got " +
                     std::to_string(lame.lambda));
  }
}

double StableNeoHookeanTerm::element_energy(std::size_t k, const std::array<Vec3, 4>& x) const {
  return stable_neo_hookean_energy(x, rest_shapes()[k], lame());
}

Vec12 StableNeoHookeanTerm::element_gradient(std::size_t k, const std::array<Vec3, 4>& x) const {
  return stable_neo_hookean_gradient(x, rest_shapes()[k], lame());
}

Mat12 StableNeoHookeanTerm::element_hessian(std::size_t k, const std::array<Vec3, 4>& x,
                                            bool project_psd) const {
  const Mat12 H = stable_neo_hookean_hessian(x, rest_shapes()[k], lame());
  return project_psd ? psd_projection(H) : H;
}

}  // namespace vessel::msm
