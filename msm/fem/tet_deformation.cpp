#include "msm/fem/tet_deformation.hpp"

#include <cmath>
#include <string>

#include "meshes/foundation/errors.hpp"

namespace vessel::msm {

Mat3 tet_edge_matrix(const std::array<Vec3, 4>& x) {
  Mat3 d;
  d << x[1] - x[0], x[2] - x[0], x[3] - x[0];
  return d;
}

TetRestShape tet_rest_shape(const std::array<Vec3, 4>& rest) {
  const Mat3 dm = tet_edge_matrix(rest);
  const double det = dm.determinant();
  if (!(std::abs(det) > 0.0)) {
    throw InputError("tet rest shape: zero rest volume; expected a non-degenerate tetrahedron");
  }
  TetRestShape s;
  s.rest_inverse = dm.inverse();
  s.volume = std::abs(det) / 6.0;
  // F_ij = Σ_k (x_{k+1} − x_0)_i (D_m⁻¹)_kj: ∂F_ij/∂x_{a,i} = (D_m⁻¹)_{a−1,j} for a ≥ 1, and
  // minus the column sum for a = 0.
  s.dF_dx.setZero();
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      for (int a = 1; a < 4; ++a) s.dF_dx(i + 3 * j, 3 * a + i) = s.rest_inverse(a - 1, j);
      s.dF_dx(i + 3 * j, i) = -s.rest_inverse.col(j).sum();
    }
  }
  return s;
}

Mat3 deformation_gradient(const std::array<Vec3, 4>& x, const TetRestShape& shape) {
  return tet_edge_matrix(x) * shape.rest_inverse;
}

}  // namespace vessel::msm
