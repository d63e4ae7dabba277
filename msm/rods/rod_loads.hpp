#pragma once
/// Loads shared by the rod models: a pure end moment about a fixed axis for a planar rod (a
/// conservative load: potential −M ψ, ψ the rotation of the last edge about the axis from the
/// clamp, summed over the vertices' signed turning angles so that it is continuous through any
/// number of turns).
#include <vector>

#include "msm/form/form.hpp"
#include "msm/rods/rod_layout.hpp"

namespace vessel::msm::rods {

/// −M·ψ over the nodes of a rod layout whose positions are the first 3·nodes dofs of x.
class PlanarEndMoment : public Form {
 public:
  PlanarEndMoment(const RodLayout& layout, int num_dofs, const Eigen::Vector3d& axis);
  void set_moment(double moment) { moment_ = moment; }  ///< N·m
  [[nodiscard]] double moment() const { return moment_; }
  [[nodiscard]] int num_dofs() const override { return num_dofs_; }
  [[nodiscard]] double energy(const VectorXd& x) const override;
  void gradient(const VectorXd& x, VectorXd& g) const override;
  void hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const override;
  /// ψ at x, rad: the last material edge's rotation about the axis from the clamp's ghost edge.
  [[nodiscard]] double end_rotation(const VectorXd& x) const;

 private:
  int first_vertex_ = 1, last_vertex_ = 0, num_dofs_ = 0;
  Eigen::Vector3d axis_;
  double moment_ = 0.0;
};

}  // namespace vessel::msm::rods
