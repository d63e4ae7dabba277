#pragma once
/// What the P1 tet hyperelastic terms of msm/fem share: a FourNodeTerm whose elements are a mesh's
/// tets, each with its rest shape (D_m⁻¹, V₀, ∂F/∂x) computed once, and Lamé parameters.
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "msm/fem/tet_deformation.hpp"
#include "msm/terms/edge_pair_term.hpp"  // LameParameters

namespace vessel::msm {

class TetTerm : public FourNodeTerm {
 public:
  [[nodiscard]] const LameParameters& lame() const { return lame_; }
  [[nodiscard]] const std::vector<TetRestShape>& rest_shapes() const { return shapes_; }

 protected:
  /// `nodes`: rest positions (m); `tets` index them; Lamé parameters in Pa. Throws InputError
  /// for a node index out of range, a degenerate tet, or a non-finite or negative μ.
  TetTerm(const std::vector<Vec3>& nodes, std::vector<Tet> tets, LameParameters lame,
          const char* name);

 private:
  LameParameters lame_;
  std::vector<TetRestShape> shapes_;
};

}  // namespace vessel::msm
