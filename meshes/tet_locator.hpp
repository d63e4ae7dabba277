#pragma once
/// Point location in a TetMesh (a uniform bucket grid over the tets' bounding boxes): the FEM
/// reference's point evaluation and the check that a user's spring network lies in the vessel.
#include <array>
#include <vector>

#include "meshes/tet_mesh.hpp"

namespace vessel {

class TetLocator {
 public:
  static constexpr double kBoxPadding = 0.1;  ///< of a tet's box diagonal
  explicit TetLocator(const TetMesh& mesh);

  /// The tet containing x (the one with the largest smallest barycentric coordinate, ≥ −tol), or
  /// −1.
  [[nodiscard]] int find(const Vec3& x, double tol = 1e-9) const;
  /// The tets whose (padded) box may contain x, for tests find does not do (every tet holding x,
  /// not the best one); empty outside the grid.
  [[nodiscard]] const std::vector<int>& candidates(const Vec3& x) const;

 private:
  [[nodiscard]] std::array<int, 3> bucket_of(const Vec3& x) const;
  [[nodiscard]] std::size_t index(int i, int j, int k) const {
    return (static_cast<std::size_t>(i) * n_[1] + j) * n_[2] + k;
  }
  const TetMesh* mesh_;
  Vec3 lo_, hi_;
  std::array<int, 3> n_{};
  std::vector<std::vector<int>> buckets_;
};

/// x's barycentric coordinates in `tet` (λ0..λ3, summing to 1; all ≥ 0 inside).
Eigen::Vector4d barycentric(const TetMesh& mesh, const Tet& tet, const Vec3& x);
/// The smallest barycentric coordinate of x in `tet` (≥ 0 inside).
double min_barycentric(const TetMesh& mesh, const Tet& tet, const Vec3& x);

}  // namespace vessel
