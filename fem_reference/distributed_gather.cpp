/// What the distributed solver's ranks send to rank 0: the displacement at the mesh's nodes, the
/// solution in the serial ElasticitySolver's DoF numbering (what fem::SolutionCache stores, so a
/// serial program restores a distributed solve), and the field at arbitrary points.
#include <deal.II/grid/tria.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "fem_reference/detail/distributed_solver.hpp"

namespace vessel::fem::detail {

namespace {

/// Every rank's `mine` concatenated on rank 0 (empty elsewhere).
template <class T>
std::vector<T> gather_on_rank0(const std::vector<T>& mine, MPI_Datatype type, MPI_Comm comm) {
  int rank = 0, n_ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &n_ranks);
  const int my_count = static_cast<int>(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(n_ranks), 0), offsets(counts.size(), 0);
  MPI_Gather(&my_count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  std::vector<T> all;
  if (rank == 0) {
    for (std::size_t i = 1; i < counts.size(); ++i) offsets[i] = offsets[i - 1] + counts[i - 1];
    all.resize(static_cast<std::size_t>(offsets.back() + counts.back()));
  }
  MPI_Gatherv(mine.data(), my_count, type, all.data(), counts.data(), offsets.data(), type, 0,
              comm);
  return all;
}

}  // namespace

void Distributed::gather_nodal_displacement() {
  // Each rank sends (node of the whole mesh, u) for the vertices of its cells; rank 0 gathers.
  std::vector<double> mine;
  for (const auto& [node, u] : vertex_values(
           dof_, mesh_map_.vertex_node, [&](dl::types::global_dof_index d) { return ghosted_(d); })) {
    const int global = part_.global_node[static_cast<std::size_t>(node)];
    mine.insert(mine.end(), {static_cast<double>(global), u[0], u[1], u[2]});
  }
  const std::vector<double> all = gather_on_rank0(mine, MPI_DOUBLE, comm_);
  if (rank_ == 0) {
    auto& nodal = out_.fem.nodal_displacement;
    nodal.assign(part_.n_nodes, Vec3::Zero());
    for (std::size_t i = 0; i + 4 <= all.size(); i += 4)
      nodal[static_cast<std::size_t>(all[i])] = Vec3(all[i + 1], all[i + 2], all[i + 3]);
  }
}

std::vector<double> Distributed::gather_serial_dofs() const {
  // Each owned DoF once, named by a cell holding it and its index in that cell: (tet, i). The
  // serial solver's triangulation has the same cells (TetMesh order) with the same vertex order
  // and numbers its DoFs by DoFHandler::distribute_dofs alone, so rank 0 rebuilds that numbering
  // (no matrix) and places each value.
  const unsigned n = fe_->n_dofs_per_cell();
  std::vector<std::int64_t> where;
  std::vector<double> value;
  std::vector<char> sent(owned_.n_elements(), 0);
  std::vector<dl::types::global_dof_index> dofs(n);
  for (const auto& cell : dof_.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    cell->get_dof_indices(dofs);
    const std::int64_t tet =
        part_.global_tet[static_cast<std::size_t>(mesh_map_.cell_tet[cell->active_cell_index()])];
    for (unsigned i = 0; i < n; ++i) {
      if (!owned_.is_element(dofs[i])) continue;
      char& s = sent[owned_.index_within_set(dofs[i])];
      if (s) continue;
      s = 1;
      where.push_back(tet * n + i);
      value.push_back(ghosted_(dofs[i]));
    }
  }
  const std::vector<std::int64_t> all_where = gather_on_rank0(where, MPI_INT64_T, comm_);
  const std::vector<double> all_value = gather_on_rank0(value, MPI_DOUBLE, comm_);
  std::vector<double> out;
  std::string failure;
  if (rank_ == 0) out = place_in_serial_numbering(all_where, all_value, failure);
  // Every rank learns whether rank 0 placed every DoF, so that none is left waiting.
  int failed = failure.empty() ? 0 : 1;
  MPI_Bcast(&failed, 1, MPI_INT, 0, comm_);
  if (failed) {
    throw std::logic_error("gather_serial_dofs: " +
                           (rank_ == 0 ? failure : std::string("rank 0 could not place the DoFs")));
  }
  return out;
}

std::vector<double> Distributed::place_in_serial_numbering(const std::vector<std::int64_t>& where,
                                                           const std::vector<double>& value,
                                                           std::string& failure) const {
  const unsigned n = fe_->n_dofs_per_cell();
  dl::Triangulation<kDim> serial;
  create_coarse_triangulation(input_, serial);  // rank 0 holds the whole mesh
  const auto fe = make_element(degree_, mixed_);
  dl::DoFHandler<kDim> dof(serial);
  dof.distribute_dofs(*fe);
  std::vector<dl::DoFHandler<kDim>::active_cell_iterator> cells(input_.tets.size());
  for (const auto& cell : dof.active_cell_iterators()) cells[cell->active_cell_index()] = cell;
  std::vector<double> out(dof.n_dofs(), std::numeric_limits<double>::quiet_NaN());
  std::vector<dl::types::global_dof_index> dofs(n);
  std::size_t placed = 0;
  for (std::size_t k = 0; k < where.size(); ++k) {
    const auto tet = static_cast<std::size_t>(where[k] / n);
    const auto i = static_cast<unsigned>(where[k] % n);
    cells[tet]->get_dof_indices(dofs);
    placed += std::isnan(out[dofs[i]]) ? 1 : 0;
    out[dofs[i]] = value[k];
  }
  if (placed != out.size() || where.size() != out.size()) {
    failure = std::to_string(placed) + " of " + std::to_string(out.size()) +
              " serial DoFs placed from " + std::to_string(where.size()) + " distributed ones";
  }
  return out;
}

std::vector<Vec3> Distributed::evaluate(std::vector<int>& point_rank) const {
  point_rank.clear();
  if (part_.n_points == 0) return {};
  // Rank 0 located each point in the whole mesh once (TetLocator, as the serial solver's
  // displacement_at) and sent it to the rank owning its tet; that rank evaluates, and one sum over
  // the ranks gives every rank every value.
  std::vector<CellIterator> cell_of_tet(mesh_.tets.size());
  for (const auto& cell : dof_.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    cell_of_tet[static_cast<std::size_t>(mesh_map_.cell_tet[cell->active_cell_index()])] = cell;
  }
  const unsigned n = fe_->n_dofs_per_cell();
  std::vector<dl::types::global_dof_index> dofs(n);
  const std::size_t n_points = part_.n_points;
  std::vector<double> mine(3 * n_points, 0.0), all(3 * n_points, 0.0);
  std::vector<int> rank_of(n_points, 0);
  for (const RankPart::Point& p : part_.points) {
    const auto k = static_cast<std::size_t>(p.index);
    const auto& cell = cell_of_tet[static_cast<std::size_t>(p.tet)];
    const auto ref =
        mapping_.transform_real_to_unit_cell(cell, dl::Point<kDim>(p.x.x(), p.x.y(), p.x.z()));
    cell->get_dof_indices(dofs);
    for (unsigned i = 0; i < n; ++i) {
      const unsigned c = fe_->system_to_component_index(i).first;
      if (c < 3) mine[3 * k + c] += ghosted_(dofs[i]) * fe_->shape_value(i, ref);
    }
    rank_of[k] = static_cast<int>(rank_);
  }
  MPI_Allreduce(mine.data(), all.data(), static_cast<int>(all.size()), MPI_DOUBLE, MPI_SUM, comm_);
  point_rank.assign(n_points, 0);
  MPI_Allreduce(rank_of.data(), point_rank.data(), static_cast<int>(n_points), MPI_INT, MPI_SUM,
                comm_);
  std::vector<Vec3> out(n_points);
  for (std::size_t k = 0; k < n_points; ++k)
    out[k] = Vec3(all[3 * k], all[3 * k + 1], all[3 * k + 2]);
  return out;
}

}  // namespace vessel::fem::detail
