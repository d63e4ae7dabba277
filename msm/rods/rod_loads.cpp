#include "msm/rods/rod_loads.hpp"

#include <array>
#include <cmath>

#include "msm/rods/element_assembly.hpp"
#include "msm/rods/vec3.hpp"

namespace vessel::msm::rods {

namespace {

/// Signed turning angle about `axis` between edges x0→x1 and x1→x2.
template <class T>
T turning_angle(const std::array<T, 9>& q, const Eigen::Vector3d& axis) {
  using std::atan2;
  const V3<T> x0(q[0], q[1], q[2]), x1(q[3], q[4], q[5]), x2(q[6], q[7], q[8]);
  const V3<T> e0 = x1 - x0, e1 = x2 - x1;
  return atan2(dot(cross(e0, e1), lift<T>(axis)), dot(e0, e1));
}

std::array<int, 9> vertex_dofs(int i) {
  std::array<int, 9> dofs{};
  for (int k = 0; k < 9; ++k) dofs[k] = 3 * (i - 1) + k;
  return dofs;
}

}  // namespace

PlanarEndMoment::PlanarEndMoment(const RodLayout& layout, int num_dofs, const Eigen::Vector3d& axis)
    : first_vertex_(layout.first_node), last_vertex_(layout.tip_node - 1), num_dofs_(num_dofs),
      axis_(axis.normalized()) {}

double PlanarEndMoment::end_rotation(const VectorXd& x) const {
  double psi = 0.0;
  for (int i = first_vertex_; i <= last_vertex_; ++i) {
    psi += turning_angle(double_inputs<9>(x, vertex_dofs(i)), axis_);
  }
  return psi;
}

double PlanarEndMoment::energy(const VectorXd& x) const { return -moment_ * end_rotation(x); }

void PlanarEndMoment::gradient(const VectorXd& x, VectorXd& g) const {
  g.setZero(num_dofs_);
  for (int i = first_vertex_; i <= last_vertex_; ++i) {
    const auto dofs = vertex_dofs(i);
    scatter_gradient<9, false>(-moment_ * turning_angle(jet_inputs<9, false>(x, dofs), axis_), dofs, g);
  }
}

void PlanarEndMoment::hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const {
  std::vector<Eigen::Triplet<double>> triplets;
  for (int i = first_vertex_; i <= last_vertex_; ++i) {
    const auto dofs = vertex_dofs(i);
    scatter_hessian<9>(-moment_ * turning_angle(jet_inputs<9>(x, dofs), axis_), dofs, project_psd,
                       triplets);
  }
  H.resize(num_dofs_, num_dofs_);
  H.setFromTriplets(triplets.begin(), triplets.end());
}

}  // namespace vessel::msm::rods
