#include "msm/fem/linear_tet.hpp"

namespace vessel::msm {

namespace {

Mat3 small_strain(const Mat3& F) { return 0.5 * (F + F.transpose()) - Mat3::Identity(); }

}  // namespace

Mat9 linear_elastic_tangent(const LameParameters& lame) {
  Mat9 c = lame.mu * Mat9::Identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) c(i + 3 * j, j + 3 * i) += lame.mu;  // the transpose map T
  }
  const Vec9 id = vec9(Mat3::Identity());
  c += lame.lambda * id * id.transpose();
  return c;
}

double linear_tet_energy(const std::array<Vec3, 4>& x, const TetRestShape& s,
                         const LameParameters& lame) {
  const Mat3 e = small_strain(deformation_gradient(x, s));
  return s.volume * (lame.mu * e.squaredNorm() + 0.5 * lame.lambda * e.trace() * e.trace());
}

Vec12 linear_tet_gradient(const std::array<Vec3, 4>& x, const TetRestShape& s,
                          const LameParameters& lame) {
  const Mat3 e = small_strain(deformation_gradient(x, s));
  return tet_gradient_from_stress(s,
                                  2.0 * lame.mu * e + lame.lambda * e.trace() * Mat3::Identity());
}

Mat12 linear_tet_stiffness(const TetRestShape& s, const LameParameters& lame) {
  return tet_hessian_from_tangent(s, linear_elastic_tangent(lame));
}

LinearTetTerm::LinearTetTerm(const std::vector<Vec3>& nodes, std::vector<Tet> tets,
                             LameParameters lame)
    : TetTerm(nodes, std::move(tets), lame, "linear tet term") {}

double LinearTetTerm::element_energy(std::size_t k, const std::array<Vec3, 4>& x) const {
  return linear_tet_energy(x, rest_shapes()[k], lame());
}

Vec12 LinearTetTerm::element_gradient(std::size_t k, const std::array<Vec3, 4>& x) const {
  return linear_tet_gradient(x, rest_shapes()[k], lame());
}

Mat12 LinearTetTerm::element_hessian(std::size_t k, const std::array<Vec3, 4>& /*x*/,
                                     bool /*project_psd*/) const {
  return linear_tet_stiffness(rest_shapes()[k], lame());  // PSD for μ ≥ 0, 3λ + 2μ ≥ 0
}

}  // namespace vessel::msm
