/// Point evaluation of the serial solution: the tet containing a point (detail/tet_locator) and
/// the element's shape functions there.
#include <sstream>

#include "fem_reference/detail/serial_solver.hpp"
#include "meshes/foundation/errors.hpp"

namespace vessel::fem {

ElasticitySolver::Impl::PointStencil ElasticitySolver::Impl::point_stencil(const Vec3& x,
                                                                          double tol) const {
  const int t = locator->find(x, tol);
  if (t < 0) {
    std::ostringstream m;
    m << "point (" << x.x() * 1e3 << ", " << x.y() * 1e3 << ", " << x.z() * 1e3
      << ") mm is outside the FEM mesh: expected a point inside the vessel wall";
    throw InputError(m.str());
  }
  const auto& cell = cells[static_cast<std::size_t>(t)];
  const dl::Point<kDim> px(x.x(), x.y(), x.z());
  dl::Point<kDim> ref = linear_mapping->transform_real_to_unit_cell(cell, px);
  if (result.curved) {
    // The curved cell differs from the straight one only near the curved faces (O(h²)); use
    // the curved inverse where deal.II provides it, else the straight one.
    try {
      ref = mapping->transform_real_to_unit_cell(cell, px);
    } catch (...) {
    }
  }
  const unsigned n = fe->n_dofs_per_cell();
  std::vector<Index> dofs(n);
  cell->get_dof_indices(dofs);
  PointStencil s;
  for (unsigned i = 0; i < n; ++i) {
    const unsigned c = fe->system_to_component_index(i).first;
    if (c >= 3) continue;
    s.dofs.push_back(dofs[i]);
    s.components.push_back(c);
    s.weights.push_back(fe->shape_value(i, ref));
  }
  return s;
}

std::vector<Vec3> ElasticitySolver::displacement_at(const std::vector<Vec3>& points,
                                                    double outside_tolerance) const {
  const auto& im = *impl_;
  if (!im.solved) throw std::logic_error("displacement_at called before solve()");
  std::vector<Vec3> out;
  out.reserve(points.size());
  for (const auto& x : points) {
    const auto st = im.point_stencil(x, outside_tolerance);
    Vec3 u = Vec3::Zero();
    for (std::size_t i = 0; i < st.dofs.size(); ++i)
      u[st.components[i]] += im.solution(st.dofs[i]) * st.weights[i];
    out.push_back(u);
  }
  return out;
}

}  // namespace vessel::fem
