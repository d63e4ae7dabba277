#include "fem_reference/detail/constraints.hpp"

#include <deal.II/fe/component_mask.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "meshes/foundation/errors.hpp"

namespace vessel::fem::detail {

namespace {

/// The node of a tet nearest `point`; InputError if it is farther than `tol`.
std::size_t node_at_point(const TetMesh& mesh, const std::vector<char>& used, const Vec3& point,
                          double tol) {
  std::size_t best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    const double d = (mesh.nodes[n] - point).norm();
    if (used[n] && d < best_d) best_d = d, best = n;
  }
  if (best_d > tol) {
    std::ostringstream m;
    m << "point constraint at (" << point.x() * 1e3 << ", " << point.y() * 1e3 << ", "
      << point.z() * 1e3 << ") mm: no mesh node there (nearest " << best_d * 1e3
      << " mm away); expected a point on a mesh node";
    throw InputError(m.str());
  }
  return best;
}

}  // namespace

std::vector<int> point_constraint_nodes(const TetMesh& mesh,
                                        const std::vector<PointConstraint>& points) {
  if (points.empty()) return {};
  const double tol = 1e-6 * std::cbrt(mesh_volume(mesh) /
                                      static_cast<double>(std::max<std::size_t>(mesh.tets.size(), 1)));
  std::vector<char> used(mesh.nodes.size(), 0);
  for (const auto& tet : mesh.tets)
    for (int n : tet) used[static_cast<std::size_t>(n)] = 1;
  std::vector<int> nodes;
  for (const auto& pc : points)
    nodes.push_back(static_cast<int>(node_at_point(mesh, used, pc.point, tol)));
  return nodes;
}

void add_point_constraints(const TetMesh& mesh, const std::vector<PointConstraint>& points,
                           const dl::DoFHandler<kDim>& dof, const std::vector<int>& vertex_node,
                           dl::AffineConstraints<double>& constraints) {
  const std::vector<int> nodes = point_constraint_nodes(mesh, points);
  for (std::size_t k = 0; k < points.size(); ++k) {
    for (const auto& cell : dof.active_cell_iterators()) {
      if (cell->is_artificial()) continue;
      for (unsigned v = 0; v < 4; ++v) {
        if (vertex_node[cell->vertex_index(v)] != nodes[k]) continue;
        const auto d = cell->vertex_dof_index(v, static_cast<unsigned>(points[k].component));
        if (!constraints.is_constrained(d)) constraints.add_line(d);
      }
    }
  }
}

dl::types::boundary_id group_boundary_id(const TetMesh& mesh, const std::string& group) {
  if (const PhysicalGroup* g = mesh.find_group(group, 2)) {
    return static_cast<dl::types::boundary_id>(g->tag);
  }
  return static_cast<dl::types::boundary_id>(mesh.require_group(group, 2, "FEM").tag);  // throws
}

void add_dirichlet_constraints(const TetMesh& mesh, const std::vector<DirichletCondition>& groups,
                               const dl::Mapping<kDim>& mapping, const dl::DoFHandler<kDim>& dof,
                               dl::AffineConstraints<double>& constraints) {
  const unsigned n_components = dof.get_fe().n_components();
  for (const auto& bc : groups) {
    std::vector<bool> mask(n_components, false);
    const bool clamped = bc.kind == DirichletCondition::Kind::clamped;
    if (clamped) {
      mask[0] = mask[1] = mask[2] = true;
    } else {
      mask[static_cast<std::size_t>(bc.component)] = true;
    }
    const VectorFunction value(clamped ? bc.value : std::function<Vec3(const Vec3&)>(),
                               n_components);
    dl::VectorTools::interpolate_boundary_values(mapping, dof, group_boundary_id(mesh, bc.group),
                                                 value, constraints, dl::ComponentMask(mask));
  }
}

}  // namespace vessel::fem::detail
