/// The serial solver's mixed (Taylor–Hood) system by FGMRES with the block-triangular
/// preconditioner of detail/block_preconditioner.hpp: on the displacement block the matrix-free
/// p-multigrid's V-cycle (straight-sided tets) or AMG (curved walls), a scaled pressure mass
/// matrix for the Schur complement.
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_gmres.h>

#include <cmath>
#include <memory>
#include <sstream>

#include "fem_reference/detail/block_preconditioner.hpp"
#include "fem_reference/detail/matrix_free_elasticity.hpp"
#include "fem_reference/detail/serial_solver.hpp"

namespace vessel::fem {

namespace {

/// The DoFs split into displacement (component < 3) and pressure, with each DoF's position in its
/// list (−1 in the other).
struct BlockSplit {
  std::vector<Index> u_dofs, p_dofs;
  std::vector<int> u_local, p_local;
  std::vector<bool> is_pressure;
};

BlockSplit split_blocks(const std::vector<unsigned>& component) {
  const auto n = static_cast<Index>(component.size());
  BlockSplit s;
  s.u_local.assign(n, -1);
  s.p_local.assign(n, -1);
  s.is_pressure.assign(n, false);
  for (Index d = 0; d < n; ++d) {
    if (component[d] < 3) {
      s.u_local[d] = static_cast<int>(s.u_dofs.size());
      s.u_dofs.push_back(d);
    } else {
      s.p_local[d] = static_cast<int>(s.p_dofs.size());
      s.p_dofs.push_back(d);
      s.is_pressure[d] = true;
    }
  }
  return s;
}

/// Per displacement DoF of the mixed system (u_dofs' order), its DoF in `p2`: the P2 vector
/// element alone on the same triangulation.
std::vector<Index> displacement_in_p2(const dl::DoFHandler<kDim>& mixed,
                                      const dl::DoFHandler<kDim>& p2, const BlockSplit& blocks) {
  const auto& fe = mixed.get_fe();
  const auto& fe2 = p2.get_fe();
  std::vector<Index> out(blocks.u_dofs.size()), dofs(fe.n_dofs_per_cell()),
      dofs2(fe2.n_dofs_per_cell());
  for (const auto& cell : mixed.active_cell_iterators()) {
    const dl::DoFHandler<kDim>::active_cell_iterator cell2(&p2.get_triangulation(), cell->level(),
                                                           cell->index(), &p2);
    cell->get_dof_indices(dofs);
    cell2->get_dof_indices(dofs2);
    for (unsigned i = 0; i < dofs.size(); ++i) {
      const auto [base, shape] = fe.system_to_base_index(i);
      if (base.first != 0) continue;  // the pressure
      out[static_cast<std::size_t>(blocks.u_local[dofs[i]])] =
          dofs2[fe2.component_to_system_index(base.second, shape)];
    }
  }
  return out;
}

/// Â⁻¹ of the block preconditioner and what it holds. On straight-sided tets one V-cycle of the
/// matrix-free p-multigrid on the same form (the displacement operator with λ = 0) on the P2
/// element alone, its constrained rows by A's diagonal; on curved walls (where its kernel does
/// not run) and for a finite-strain tangent (whose block is not that form) one
/// smoothed-aggregation AMG V-cycle on A itself.
struct DisplacementBlockInverse {
  detail::BlockTriangularPreconditioner::DisplacementInverse apply;
  dl::TrilinosWrappers::SparseMatrix a_trilinos;
  std::vector<double> modes_storage;  // must outlive amg (declared after: destroyed first)
  dl::TrilinosWrappers::PreconditionAMG amg;
  std::unique_ptr<dl::DoFHandler<kDim>> p2;
  std::unique_ptr<detail::MatrixFreeElasticitySolver> multigrid;
  std::vector<Index> to_p2;                  // per displacement DoF its P2 DoF
  std::vector<double> constrained_diagonal;  // per displacement DoF: A_ii if constrained, else 0
};

/// Fills `out` (which `apply` refers to: it must stay where it is) for ElasticitySolver's `im`
/// (private: deduced) and the displacement block `a` of its mixed matrix.
template <typename Impl>
void make_displacement_block_inverse(const Impl& im, const BlockSplit& blocks,
                                     const dl::SparseMatrix<double>& a,
                                     DisplacementBlockInverse& out) {
  const auto& o = im.problem.options;
  if (!im.problem.curved_surfaces.empty() || im.tangent_systems) {
    out.a_trilinos.reinit(a);
    detail::initialize_elasticity_amg(out.amg, out.a_trilinos, im.displacement_rows(blocks.u_dofs),
                                      detail::node_centroid(im.mesh), true, o.amg_rigid_body_modes,
                                      detail::AmgProlongator::smoothed, out.modes_storage);
    out.apply = [&amg = out.amg](dl::Vector<double>& x, const dl::Vector<double>& r) {
      amg.vmult(x, r);
    };
    return;
  }
  out.p2 = std::make_unique<dl::DoFHandler<kDim>>(im.tria);
  out.p2->distribute_dofs(dl::FESystem<kDim>(dl::FE_SimplexP<kDim>(2), kDim));
  out.to_p2 = displacement_in_p2(im.dof, *out.p2, blocks);
  out.constrained_diagonal.assign(blocks.u_dofs.size(), 0.0);
  for (Index i = 0; i < blocks.u_dofs.size(); ++i) {
    if (im.constraints.is_constrained(blocks.u_dofs[i])) {
      out.constrained_diagonal[i] = a.diag_element(i);
    }
  }
  detail::PMultigridSettings settings;
  settings.direct_coarse_max_dofs = o.matrix_free_direct_coarse_max_dofs;
  out.multigrid = std::make_unique<detail::MatrixFreeElasticitySolver>(
      *im.mapping, *out.p2,
      [&im](const dl::DoFHandler<kDim>& d, dl::AffineConstraints<double>& c) {
        im.support_constraints(d, c);
      },
      2, 0.0, im.form->mu(), detail::node_centroid(im.mesh), settings);
  const auto n2 = out.p2->n_dofs();
  out.apply = [&out, r2 = dl::Vector<double>(n2), x2 = dl::Vector<double>(n2)](
                  dl::Vector<double>& x, const dl::Vector<double>& r) mutable {
    for (Index i = 0; i < out.to_p2.size(); ++i) r2(out.to_p2[i]) = r(i);
    out.multigrid->precondition(x2, r2);
    for (Index i = 0; i < out.to_p2.size(); ++i) {
      const double d = out.constrained_diagonal[i];
      x(i) = d != 0.0 ? r(i) / d : x2(out.to_p2[i]);
    }
  };
}

}  // namespace

/// Ŝ = (1/(2μ) + 1/λ) M_p on the pressure DoFs. Schur complement S = C + B A⁻¹ Bᵀ of
/// [A Bᵀ; B −C] (C = M_p/λ, B = −∫ q div v): B A⁻¹ Bᵀ is spectrally equivalent to M_p/(2μ) for an
/// inf-sup stable pair (Taylor–Hood), so Ŝ is uniformly equivalent to S in λ and h (Klawonn 1998,
/// SIAM J. Sci. Comput. 19:172, "Block-triangular preconditioners for saddle point problems with a
/// penalty term"; Elman, Silvester & Wathen 2014, §4.2 for the Stokes limit λ → ∞).
void ElasticitySolver::Impl::assemble_schur_approximation(const std::vector<int>& p_local,
                                                          Index n_p, dl::SparsityPattern& pattern,
                                                          dl::SparseMatrix<double>& schur) const {
  const auto& im = *this;
  const double inv_lambda = std::isinf(im.form->lambda()) ? 0.0 : 1.0 / im.form->lambda();
  const double schur_scale = 1.0 / (2.0 * im.form->mu()) + inv_lambda;
  std::vector<Index> dofs(im.fe->n_dofs_per_cell());
  dl::DynamicSparsityPattern p_dsp(n_p, n_p);
  for (const auto& cell : im.dof.active_cell_iterators()) {
    cell->get_dof_indices(dofs);
    for (auto i : dofs)
      for (auto j : dofs)
        if (p_local[i] >= 0 && p_local[j] >= 0)
          p_dsp.add(static_cast<Index>(p_local[i]), static_cast<Index>(p_local[j]));
  }
  pattern.copy_from(p_dsp);
  schur.reinit(pattern);
  const dl::FEValuesExtractors::Scalar pres(kDim);
  dl::FEValues<kDim> fev(*im.mapping, *im.fe, detail::cell_quadrature(2),
                         dl::update_values | dl::update_JxW_values);
  std::vector<unsigned> local_p;
  for (const auto& cell : im.dof.active_cell_iterators()) {
    fev.reinit(cell);
    cell->get_dof_indices(dofs);
    local_p.clear();
    for (unsigned i = 0; i < dofs.size(); ++i)
      if (p_local[dofs[i]] >= 0) local_p.push_back(i);
    for (unsigned q = 0; q < fev.n_quadrature_points; ++q) {
      const double w = schur_scale * fev.JxW(q);
      for (unsigned i : local_p)
        for (unsigned j : local_p)
          schur.add(static_cast<Index>(p_local[dofs[i]]), static_cast<Index>(p_local[dofs[j]]),
                    w * fev[pres].value(i, q) * fev[pres].value(j, q));
    }
  }
}

void ElasticitySolver::Impl::solve_mixed_iterative() {
  const auto& o = problem.options;
  const Index n = dof.n_dofs();
  const BlockSplit blocks = split_blocks(dof_components());

  // Displacement block A = ∫ 2μ ε:ε (with the constrained rows' diagonal).
  dl::SparsityPattern a_pattern;
  dl::SparseMatrix<double> a_block;
  detail::extract_block(matrix, blocks.u_dofs, blocks.u_local, a_pattern, a_block);
  detail::ensure_mpi_initialized();  // before any Trilinos object is made
  DisplacementBlockInverse a_inverse;
  make_displacement_block_inverse(*this, blocks, a_block, a_inverse);

  dl::SparsityPattern p_pattern;
  dl::SparseMatrix<double> schur;
  assemble_schur_approximation(blocks.p_local, static_cast<Index>(blocks.p_dofs.size()),
                               p_pattern, schur);

  // ω² = mean diag(A) / mean diag(Ŝ): balances the two blocks of the scaled system.
  double diag_a = 0.0, diag_s = 0.0;
  for (Index i = 0; i < blocks.u_dofs.size(); ++i) diag_a += a_block.diag_element(i);
  for (Index i = 0; i < blocks.p_dofs.size(); ++i) diag_s += schur.diag_element(i);
  const double omega = std::sqrt((diag_a / static_cast<double>(blocks.u_dofs.size())) /
                                 (diag_s / static_cast<double>(blocks.p_dofs.size())));
  a_block.clear();

  const detail::ScaledMixedOperator op(matrix, blocks.is_pressure, omega);
  const detail::BlockTriangularPreconditioner prec(op, a_inverse.apply, schur, blocks.u_dofs,
                                                   blocks.p_dofs, omega);
  dl::Vector<double> b = rhs;
  op.scale(b);
  dl::Vector<double> y(n);
  dl::SolverControl control(o.max_iterations, o.cg_relative_tolerance * b.l2_norm());
  dl::SolverFGMRES<dl::Vector<double>> gmres(
      control, dl::SolverFGMRES<dl::Vector<double>>::AdditionalData(o.gmres_restart));
  try {
    gmres.solve(op, y, b, prec);
  } catch (const dl::SolverControl::NoConvergence& e) {
    std::ostringstream m;
    m << "FGMRES with the block preconditioner did not converge in " << e.last_step
      << " iterations (residual " << e.last_residual << " of " << b.l2_norm()
      << "); try --solver direct or more --max-iterations";
    throw std::runtime_error(m.str());
  }
  op.scale(y);  // p = ω p̃
  solution = y;
  result.iterations = control.last_step();
  result.inner_iterations = prec.mean_inner_iterations();
}

}  // namespace vessel::fem
