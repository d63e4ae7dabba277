#include "meshes/tet_locator.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace vessel {

Eigen::Vector4d barycentric(const TetMesh& mesh, const Tet& tet, const Vec3& x) {
  const Vec3& p0 = mesh.nodes[static_cast<std::size_t>(tet[0])];
  Eigen::Matrix3d m;
  for (int c = 0; c < 3; ++c) m.col(c) = mesh.nodes[static_cast<std::size_t>(tet[c + 1])] - p0;
  const Vec3 l = m.partialPivLu().solve(x - p0);
  return {1.0 - l.sum(), l[0], l[1], l[2]};
}

double min_barycentric(const TetMesh& mesh, const Tet& tet, const Vec3& x) {
  return barycentric(mesh, tet, x).minCoeff();
}

TetLocator::TetLocator(const TetMesh& mesh) : mesh_(&mesh) {
  lo_ = hi_ = mesh.nodes.empty() ? Vec3::Zero() : mesh.nodes[0];
  for (const auto& x : mesh.nodes) {
    lo_ = lo_.cwiseMin(x);
    hi_ = hi_.cwiseMax(x);
  }
  const double extent = (hi_ - lo_).maxCoeff();
  double largest_tet = 0.0;
  for (const auto& tet : mesh.tets) {
    largest_tet = std::max(largest_tet, (mesh.nodes[tet[1]] - mesh.nodes[tet[0]]).norm());
  }
  lo_ -= Vec3::Constant(1e-9 * extent + kBoxPadding * largest_tet);
  hi_ += Vec3::Constant(1e-9 * extent + kBoxPadding * largest_tet);
  const double per_axis = std::cbrt(static_cast<double>(std::max<std::size_t>(mesh.tets.size(), 1)));
  for (int d = 0; d < 3; ++d) {
    n_[d] = std::max(1, static_cast<int>(per_axis * (hi_[d] - lo_[d]) / extent) + 1);
  }
  buckets_.resize(static_cast<std::size_t>(n_[0]) * n_[1] * n_[2]);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    Vec3 a = mesh.nodes[mesh.tets[t][0]], b = a;
    for (int v : mesh.tets[t]) {
      a = a.cwiseMin(mesh.nodes[v]);
      b = b.cwiseMax(mesh.nodes[v]);
    }
    // Listed also in the buckets just outside its box, so that points slightly outside the
    // mesh (a curved wall's chord error) still find their tet when a tolerance allows it.
    const Vec3 pad = Vec3::Constant(kBoxPadding * (b - a).norm());
    a -= pad;
    b += pad;
    const auto ia = bucket_of(a), ib = bucket_of(b);
    for (int i = ia[0]; i <= ib[0]; ++i)
      for (int j = ia[1]; j <= ib[1]; ++j)
        for (int k = ia[2]; k <= ib[2]; ++k) buckets_[index(i, j, k)].push_back(static_cast<int>(t));
  }
}

const std::vector<int>& TetLocator::candidates(const Vec3& x) const {
  static const std::vector<int> none;
  for (int d = 0; d < 3; ++d) {
    if (x[d] < lo_[d] || x[d] > hi_[d]) return none;
  }
  const auto ijk = bucket_of(x);
  return buckets_[index(ijk[0], ijk[1], ijk[2])];
}

int TetLocator::find(const Vec3& x, double tol) const {
  int best = -1;
  double best_min = -tol;
  for (int t : candidates(x)) {
    const double lmin = min_barycentric(*mesh_, mesh_->tets[static_cast<std::size_t>(t)], x);
    if (lmin >= best_min) {
      best_min = lmin;
      best = t;
    }
  }
  return best;
}

std::array<int, 3> TetLocator::bucket_of(const Vec3& x) const {
  std::array<int, 3> ijk{};
  for (int d = 0; d < 3; ++d) {
    const int i = static_cast<int>((x[d] - lo_[d]) / (hi_[d] - lo_[d]) * n_[d]);
    ijk[d] = std::clamp(i, 0, n_[d] - 1);
  }
  return ijk;
}

}  // namespace vessel
