#include "msm/fem/polar_rotation.hpp"

#include <Eigen/SVD>
#include <cmath>

namespace vessel::msm {

// GCC 12 reports Eigen's 3×3 JacobiSVD singular values as maybe uninitialised (they are set by
// the Jacobi sweeps); a false positive, silenced for this function only.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
RotatedSvd rotated_svd(const Mat3& F) {
  // Square: no QR preconditioning needed.
  const Eigen::JacobiSVD<Mat3, Eigen::NoQRPreconditioner> svd(
      F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  RotatedSvd r;
  r.U = svd.matrixU();
  r.V = svd.matrixV();
  r.sigma = svd.singularValues();
  // Irving et al. 2004 §5: make U and V rotations by negating the smallest singular value's
  // column (and that σ); two negations on one σ cancel.
  if (r.U.determinant() < 0.0) {
    r.U.col(2) *= -1.0;
    r.sigma[2] *= -1.0;
  }
  if (r.V.determinant() < 0.0) {
    r.V.col(2) *= -1.0;
    r.sigma[2] *= -1.0;
  }
  r.rotation = r.U * r.V.transpose();
  return r;
}
#pragma GCC diagnostic pop

Mat9 rotation_derivative(const RotatedSvd& svd) {
  Mat9 d;
  for (int l = 0; l < 3; ++l) {
    for (int k = 0; k < 3; ++k) {
      // dF = e_k e_lᵀ: M = Uᵀ dF V = U.row(k)ᵀ V.row(l).
      const Mat3 M = svd.U.row(k).transpose() * svd.V.row(l);
      Mat3 omega = Mat3::Zero();
      for (int i = 0; i < 3; ++i) {
        for (int j = i + 1; j < 3; ++j) {
          const double s = svd.sigma[i] + svd.sigma[j];
          if (std::abs(s) <= 1e-12 * svd.sigma.cwiseAbs().maxCoeff()) continue;
          omega(i, j) = (M(i, j) - M(j, i)) / s;
          omega(j, i) = -omega(i, j);
        }
      }
      d.col(k + 3 * l) = vec9(svd.U * omega * svd.V.transpose());
    }
  }
  return d;
}

}  // namespace vessel::msm
