/// The serial displacement system on its unconstrained DoFs as Eigen matrices (stiffness,
/// consistent mass, load), for the modal analysis, the Newmark transient and a simulator's
/// prefactored linear FEM (free_displacement_system).
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include <algorithm>
#include <stdexcept>

#include "fem_reference/detail/serial_solver.hpp"
#include "meshes/foundation/errors.hpp"

namespace vessel::fem {

namespace {

/// Consistent mass M_ij = ∫ ρ φ_i·φ_j dV of the cell at `fev` (nonzero only between equal
/// components).
void cell_mass(const dl::FEValues<kDim>& fev, const std::vector<unsigned>& component, double rho,
               dl::FullMatrix<double>& m) {
  const unsigned n = fev.dofs_per_cell;
  m = 0.0;
  for (unsigned q = 0; q < fev.n_quadrature_points; ++q) {
    const double w = rho * fev.JxW(q);
    for (unsigned i = 0; i < n; ++i) {
      const double ni = fev.shape_value(i, q) * w;
      for (unsigned j = 0; j < n; ++j) {
        if (component[i] == component[j]) m(i, j) += ni * fev.shape_value(j, q);
      }
    }
  }
}

}  // namespace

Eigen::SparseMatrix<double> ElasticitySolver::Impl::free_block(const dl::SparseMatrix<double>& a,
                                                               const std::vector<int>& free_index,
                                                               int n_free) {
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(a.n_nonzero_elements());
  for (Index row = 0; row < a.m(); ++row) {
    const int fr = free_index[row];
    if (fr < 0) continue;
    for (auto it = a.begin(row); it != a.end(row); ++it) {
      const int fc = free_index[it->column()];
      if (fc >= 0 && it->value() != 0.0) t.emplace_back(fr, fc, it->value());
    }
  }
  Eigen::SparseMatrix<double> e(n_free, n_free);
  e.setFromTriplets(t.begin(), t.end());
  return e;
}

ElasticitySolver::Impl::FreeSystem ElasticitySolver::Impl::assemble_free_system(
    bool with_mass) const {
  // The same local systems and constraint condensation as the static assemble(), into matrices
  // of their own (this is const); then the unconstrained rows and columns are kept.
  detail::CellValues values(*mapping, *fe, degree);
  const unsigned n = fe->n_dofs_per_cell();
  dl::FullMatrix<double> k(n, n), m(n, n);
  dl::Vector<double> f(n);
  std::vector<Index> dofs(n);
  std::vector<unsigned> comp(n);
  for (unsigned i = 0; i < n; ++i) comp[i] = fe->system_to_component_index(i).first;
  dl::SparsityPattern own;  // the matrix-free solver builds no pattern of its own
  if (sparsity.empty()) {
    dl::DynamicSparsityPattern dsp(dof.n_dofs(), dof.n_dofs());
    dl::DoFTools::make_sparsity_pattern(dof, dsp, constraints, false);
    own.copy_from(dsp);
  }
  const dl::SparsityPattern& pattern = sparsity.empty() ? own : sparsity;
  dl::SparseMatrix<double> kd(pattern), md;
  if (with_mass) md.reinit(pattern);
  dl::Vector<double> fd(dof.n_dofs());
  for (const auto& cell : dof.active_cell_iterators()) {
    form->local_system(cell, values, k, f, nullptr);  // leaves values.cell on this cell
    cell->get_dof_indices(dofs);
    constraints.distribute_local_to_global(k, f, dofs, kd, fd);
    if (!with_mass) continue;
    cell_mass(values.cell, comp, problem.material.density, m);
    constraints.distribute_local_to_global(m, dofs, md);
  }
  FreeSystem out;
  const Index n_all = dof.n_dofs();
  out.free_index.assign(n_all, -1);
  out.constrained_value.assign(n_all, 0.0);
  int n_free = 0;
  for (Index d = 0; d < n_all; ++d) {
    if (!constraints.is_constrained(d)) {
      out.free_index[d] = n_free++;
      continue;
    }
    // Only Dirichlet-type lines (u_d = g) exist here: no hanging nodes on this unrefined mesh.
    const auto* entries = constraints.get_constraint_entries(d);
    if (entries != nullptr && !entries->empty()) {
      throw std::logic_error("constraint couples DoFs: not supported by the free-DoF system");
    }
    out.constrained_value[d] = constraints.get_inhomogeneity(d);
  }
  out.K = free_block(kd, out.free_index, n_free);
  kd.clear();
  if (with_mass) out.M = free_block(md, out.free_index, n_free);
  out.f.resize(n_free);
  for (Index d = 0; d < n_all; ++d) {
    if (out.free_index[d] >= 0) out.f[out.free_index[d]] = fd(d);
  }
  return out;
}

FreeDisplacementSystem ElasticitySolver::free_displacement_system() const {
  if (impl_->mixed) {
    throw InputError(
        "the free displacement system is for the displacement formulation; the mixed "
        "(Taylor-Hood) system is indefinite");
  }
  Impl::FreeSystem sys = impl_->assemble_free_system(false);
  std::vector<std::array<int, 3>> rows = impl_->node_rows(sys.free_index);
  return {std::move(sys.K), std::move(sys.f), std::move(sys.free_index), std::move(rows), {}, {}};
}

void ElasticitySolver::set_row_points(FreeDisplacementSystem& system) const {
  impl_->set_row_points(system);
}

void ElasticitySolver::Impl::set_row_points(FreeDisplacementSystem& system) const {
  const detail::DisplacementRows all = displacement_rows({});
  const auto n = static_cast<std::size_t>(std::count_if(
      system.free_index.begin(), system.free_index.end(), [](int r) { return r >= 0; }));
  system.row_points.assign(n, Vec3::Zero());
  system.row_components.assign(n, 0);
  for (std::size_t d = 0; d < system.free_index.size(); ++d) {
    const int r = system.free_index[d];
    if (r < 0) continue;
    const auto& x = all.support[d];
    system.row_points[static_cast<std::size_t>(r)] = Vec3(x[0], x[1], x[2]);
    system.row_components[static_cast<std::size_t>(r)] = static_cast<int>(all.component[d]);
  }
}

Eigen::VectorXd interpolate_rows(const FreeDisplacementSystem& system,
                                 const std::function<Vec3(const Vec3&)>& field) {
  Eigen::VectorXd out(static_cast<Eigen::Index>(system.row_points.size()));
  for (std::size_t r = 0; r < system.row_points.size(); ++r) {
    out[static_cast<Eigen::Index>(r)] = field(system.row_points[r])[system.row_components[r]];
  }
  return out;
}

std::vector<std::array<int, 3>> ElasticitySolver::Impl::node_rows(
    const std::vector<int>& free_index) const {
  // Each node's rows through its vertex DoFs, shifted by one so that a node no cell uses (left at
  // zero by nodal()) reads −1 like a constrained one (rows fit a double exactly).
  const std::vector<Vec3> rows =
      nodal([&](Index i) { return static_cast<double>(free_index[i] + 1); });
  std::vector<std::array<int, 3>> out(rows.size());
  for (std::size_t n = 0; n < rows.size(); ++n) {
    for (int c = 0; c < 3; ++c) out[n][c] = static_cast<int>(rows[n][c]) - 1;
  }
  return out;
}

}  // namespace vessel::fem
