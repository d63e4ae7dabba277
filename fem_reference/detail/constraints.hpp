#pragma once
/// Private to fem_reference: the problem's supports as deal.II constraints (point constraints and
/// clamped / roller Dirichlet groups), shared by the serial and the distributed solver.
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/lac/affine_constraints.h>

#include <vector>

#include "fem_reference/detail/common.hpp"
#include "fem_reference/elasticity.hpp"

namespace vessel::fem::detail {

/// The mesh node (of a tet) at each constraint's point: InputError naming the point if none lies
/// within 1e-6 of a typical element length (cube root of the mean tet volume).
std::vector<int> point_constraint_nodes(const TetMesh& mesh,
                                        const std::vector<PointConstraint>& points);

/// u[component] = 0 at the mesh node at each constraint's point (point_constraint_nodes), on
/// every non-artificial cell's copy of it. Added before the Dirichlet groups, so a group over the
/// same node skips them (same value 0). InputError naming the point if no mesh node (of a tet) lies
/// within 1e-6 of a typical element length (cube root of the mean tet volume).
void add_point_constraints(const TetMesh& mesh, const std::vector<PointConstraint>& points,
                           const dl::DoFHandler<kDim>& dof, const std::vector<int>& vertex_node,
                           dl::AffineConstraints<double>& constraints);

/// Each group's condition, interpolated at its boundary DoFs (boundary id = the group's tag):
/// clamped, all three displacement components = value(x) (0 without a value); roller, the one
/// component = 0.
void add_dirichlet_constraints(const TetMesh& mesh, const std::vector<DirichletCondition>& groups,
                               const dl::Mapping<kDim>& mapping, const dl::DoFHandler<kDim>& dof,
                               dl::AffineConstraints<double>& constraints);

/// The boundary id of a Dirichlet or load group: its gmsh tag (InputError if missing; a group
/// without triangles is allowed: a distributed rank's part may hold none of a group's).
dl::types::boundary_id group_boundary_id(const TetMesh& mesh, const std::string& group);

}  // namespace vessel::fem::detail
