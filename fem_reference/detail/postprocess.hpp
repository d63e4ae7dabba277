#pragma once
/// Private to fem_reference: what both solvers compute from a solution — strain energy and
/// principal strains, the element residual behind the support reactions, each group's reaction,
/// and the displacement at the mesh's nodes. Templates over the solution vector (deal.II's serial
/// Vector or Trilinos' distributed one), instantiated in postprocess.cpp for both.
#include <deal.II/base/index_set.h>
#include <deal.II/lac/affine_constraints.h>

#include <limits>
#include <utility>
#include <vector>

#include "fem_reference/detail/weak_form.hpp"

namespace vessel::fem::detail {

/// Strain energy ½∫σ:ε dV (J) and the extreme principal strains over quadrature points.
struct StrainSummary {
  double energy = 0.0;
  double max_principal = -std::numeric_limits<double>::infinity();
  double max_abs_principal = 0.0;
};

/// Adds the cell's energy and principal strains at the quadrature points of `fev` (reinit'ed on the
/// cell): W = ½ λ (tr ε)² + μ ε:ε (displacement), ½ (2μ ε:ε + p²/λ) (mixed, p = −λ tr ε).
template <class VectorType>
void add_cell_strain(const WeakForm& form, const dl::FEValues<kDim>& fev, const VectorType& u,
                     StrainSummary& summary);

/// The element residual K_e u_e − f_e of the unconstrained system on `cell` (its DoFs in `dofs`):
/// at constrained DoFs, summed over cells, the supports' reactions. values.cell is left on `cell`.
template <class VectorType>
void element_residual(const WeakForm& form, const CellIterator& cell, CellValues& values,
                      const VectorType& u, std::vector<dl::types::global_dof_index>& dofs,
                      dl::Vector<double>& residual);

/// The reaction (N) of the supports of the group with boundary id `id`: the residual summed over
/// the group's constrained displacement DoFs among `owned` (this rank's part; sum over ranks).
template <class VectorType>
Vec3 group_reaction(const dl::DoFHandler<kDim>& dof, const dl::AffineConstraints<double>& constraints,
                    dl::types::boundary_id id, const dl::IndexSet& owned, const VectorType& residual);

/// (mesh node, u) at each vertex of the locally owned cells, once per vertex; u from the vector
/// through `value(dof)`.
template <class ValueOfDof>
std::vector<std::pair<int, Vec3>> vertex_values(const dl::DoFHandler<kDim>& dof,
                                                const std::vector<int>& vertex_node,
                                                const ValueOfDof& value) {
  std::vector<std::pair<int, Vec3>> out;
  std::vector<char> seen(dof.get_triangulation().n_vertices(), 0);
  for (const auto& cell : dof.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    for (unsigned v = 0; v < 4; ++v) {
      const auto vi = cell->vertex_index(v);
      if (seen[vi]) continue;
      seen[vi] = 1;
      Vec3 u;
      for (unsigned c = 0; c < 3; ++c) u[static_cast<int>(c)] = value(cell->vertex_dof_index(v, c));
      out.emplace_back(vertex_node[vi], u);
    }
  }
  return out;
}

/// Per TetMesh node (n_nodes of them), its displacement from vertex_values (zero elsewhere).
template <class ValueOfDof>
std::vector<Vec3> nodal_values(const dl::DoFHandler<kDim>& dof, const std::vector<int>& vertex_node,
                               std::size_t n_nodes, const ValueOfDof& value) {
  std::vector<Vec3> out(n_nodes, Vec3::Zero());
  for (const auto& [node, u] : vertex_values(dof, vertex_node, value))
    out[static_cast<std::size_t>(node)] = u;
  return out;
}

}  // namespace vessel::fem::detail
