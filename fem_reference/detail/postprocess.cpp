#include "fem_reference/detail/postprocess.hpp"

#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/lac/trilinos_vector.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace vessel::fem::detail {

template <class VectorType>
void add_cell_strain(const WeakForm& form, const dl::FEValues<kDim>& fev, const VectorType& u,
                     StrainSummary& summary) {
  const dl::FEValuesExtractors::Vector disp(0);
  const dl::FEValuesExtractors::Scalar pres(kDim);
  const unsigned nq = fev.n_quadrature_points;
  std::vector<dl::SymmetricTensor<2, kDim>> eps(nq);
  std::vector<double> p(nq, 0.0);
  fev[disp].get_function_symmetric_gradients(u, eps);
  if (form.mixed()) fev[pres].get_function_values(u, p);
  const double lambda = form.lambda(), mu = form.mu();
  const double inv_lambda = std::isinf(lambda) ? 0.0 : 1.0 / lambda;
  for (unsigned q = 0; q < nq; ++q) {
    const double tr = dl::trace(eps[q]);
    const double w = form.mixed() ? 2.0 * mu * (eps[q] * eps[q]) + inv_lambda * p[q] * p[q]
                                  : lambda * tr * tr + 2.0 * mu * (eps[q] * eps[q]);
    summary.energy += 0.5 * w * fev.JxW(q);
    const auto ev = dl::eigenvalues(eps[q]);  // descending
    summary.max_principal = std::max(summary.max_principal, ev[0]);
    summary.max_abs_principal =
        std::max({summary.max_abs_principal, std::abs(ev[0]), std::abs(ev[2])});
  }
}

template <class VectorType>
void element_residual(const WeakForm& form, const CellIterator& cell, CellValues& values,
                      const VectorType& u, std::vector<dl::types::global_dof_index>& dofs,
                      dl::Vector<double>& residual) {
  const unsigned n = cell->get_fe().n_dofs_per_cell();
  dl::Vector<double> u_local(n);
  dofs.resize(n);
  cell->get_dof_indices(dofs);
  for (unsigned i = 0; i < n; ++i) u_local(i) = u(dofs[i]);
  form.local_residual(cell, values, u_local, residual);
}

template <class VectorType>
Vec3 group_reaction(const dl::DoFHandler<kDim>& dof, const dl::AffineConstraints<double>& constraints,
                    dl::types::boundary_id id, const dl::IndexSet& owned, const VectorType& residual) {
  const auto& fe = dof.get_fe();
  std::map<dl::types::global_dof_index, unsigned> on_group;  // owned DoF → component
  std::vector<dl::types::global_dof_index> face_dofs(fe.n_dofs_per_face());
  for (const auto& cell : dof.active_cell_iterators()) {
    if (cell->is_artificial()) continue;
    for (unsigned f = 0; f < cell->n_faces(); ++f) {
      const auto face = cell->face(f);
      if (!face->at_boundary() || face->boundary_id() != id) continue;
      face->get_dof_indices(face_dofs);
      for (unsigned i = 0; i < face_dofs.size(); ++i) {
        const auto d = face_dofs[i];
        const unsigned c = fe.face_system_to_component_index(i).first;
        if (c < 3 && owned.is_element(d) && constraints.is_constrained(d)) on_group[d] = c;
      }
    }
  }
  Vec3 force = Vec3::Zero();
  for (const auto& [d, c] : on_group) force[static_cast<int>(c)] += residual(d);
  return force;
}

template void add_cell_strain(const WeakForm&, const dl::FEValues<kDim>&,
                              const dl::Vector<double>&, StrainSummary&);
template void add_cell_strain(const WeakForm&, const dl::FEValues<kDim>&,
                              const dl::TrilinosWrappers::MPI::Vector&, StrainSummary&);
template void element_residual(const WeakForm&, const CellIterator&, CellValues&,
                               const dl::Vector<double>&,
                               std::vector<dl::types::global_dof_index>&, dl::Vector<double>&);
template void element_residual(const WeakForm&, const CellIterator&, CellValues&,
                               const dl::TrilinosWrappers::MPI::Vector&,
                               std::vector<dl::types::global_dof_index>&, dl::Vector<double>&);
template Vec3 group_reaction(const dl::DoFHandler<kDim>&, const dl::AffineConstraints<double>&,
                             dl::types::boundary_id, const dl::IndexSet&,
                             const dl::Vector<double>&);
template Vec3 group_reaction(const dl::DoFHandler<kDim>&, const dl::AffineConstraints<double>&,
                             dl::types::boundary_id, const dl::IndexSet&,
                             const dl::TrilinosWrappers::MPI::Vector&);

}  // namespace vessel::fem::detail
