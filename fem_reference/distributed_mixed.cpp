/// The distributed solver's mixed (Taylor–Hood P2–P1) system, ν up to 0.5, in deal.II step-55's
/// layout: the DoFs renumbered by block (u, then p), Trilinos block matrices and vectors, FGMRES
/// with the serial solver's block-triangular preconditioner (mixed_block_solve.cpp): one AMG
/// V-cycle on the displacement block (all six rigid-body modes), a Jacobi-CG solve with the
/// scaled pressure mass matrix Ŝ = (1/(2μ) + 1/λ) M_p for the Schur complement (Klawonn 1998,
/// SIAM J. Sci. Comput. 19:172), and the same symmetric scaling ω of the pressure rows.
#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_renumbering.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/block_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "fem_reference/detail/distributed_solver.hpp"
#include "fem_reference/detail/memory_probe.hpp"

namespace vessel::fem::detail {

namespace {

/// P = [Â  ωBᵀ; 0  −ω²Ŝ] applied to the scaled system [A  ωBᵀ; ωB  −ω²C] (the serial
/// BlockTriangularPreconditioner on block vectors): p̃ = −(ω²Ŝ)⁻¹ r_p by Jacobi-CG to a relative
/// 1e-6, then u = Â⁻¹ (r_u − ωBᵀ p̃) by one AMG V-cycle. Inexact inner solves: use with FGMRES.
class BlockPreconditioner {
 public:
  BlockPreconditioner(const dl::TrilinosWrappers::SparseMatrix& scaled_bt,
                      const dl::TrilinosWrappers::PreconditionAMG& amg,
                      const dl::TrilinosWrappers::SparseMatrix& schur, double omega,
                      const dl::IndexSet& owned_u, MPI_Comm comm)
      : bt_(scaled_bt), amg_(amg), schur_(schur), omega_(omega), ru_(owned_u, comm) {
    jacobi_.initialize(schur_);
  }
  void vmult(BlockVectorT& dst, const BlockVectorT& src) const {
    dst.block(1) = 0.0;
    if (src.block(1).l2_norm() > 0.0) {
      dl::ReductionControl control(1000, 1e-300, 1e-6);
      dl::SolverCG<VectorT> cg(control);
      cg.solve(schur_, dst.block(1), src.block(1), jacobi_);
      inner_iterations_ += control.last_step();
    }
    dst.block(1) *= -1.0 / (omega_ * omega_);
    bt_.vmult(ru_, dst.block(1));
    ru_.sadd(-1.0, 1.0, src.block(0));  // r_u − ωBᵀ p̃
    amg_.vmult(dst.block(0), ru_);
    ++applications_;
  }
  [[nodiscard]] double mean_inner_iterations() const {
    return applications_ ? static_cast<double>(inner_iterations_) /
                               static_cast<double>(applications_)
                         : 0.0;
  }

 private:
  const dl::TrilinosWrappers::SparseMatrix& bt_;
  const dl::TrilinosWrappers::PreconditionAMG& amg_;
  const dl::TrilinosWrappers::SparseMatrix& schur_;
  double omega_;
  dl::TrilinosWrappers::PreconditionJacobi jacobi_;
  mutable VectorT ru_;
  mutable unsigned long inner_iterations_ = 0;
  mutable unsigned long applications_ = 0;
};

/// Mean of the diagonal entries of `m` over all ranks (its owned rows `rows`, block numbering).
double mean_diagonal(const dl::TrilinosWrappers::SparseMatrix& m, const dl::IndexSet& rows,
                     MPI_Comm comm) {
  double sum = 0.0;
  for (const auto i : rows) sum += m.diag_element(i);
  return dl::Utilities::MPI::sum(sum, comm) / static_cast<double>(rows.size());
}

}  // namespace

void Distributed::setup_mixed_system() {
  const std::vector<unsigned> block_component{0, 0, 0, 1};
  dl::DoFRenumbering::component_wise(dof_, block_component);
  const auto per_block = dl::DoFTools::count_dofs_per_fe_block(dof_, block_component);
  const auto n_u = per_block[0], n_p = per_block[1];
  owned_ = dof_.locally_owned_dofs();
  dl::DoFTools::extract_locally_relevant_dofs(dof_, relevant_);
  owned_blocks_ = {owned_.get_view(0, n_u), owned_.get_view(n_u, n_u + n_p)};
  relevant_blocks_ = {relevant_.get_view(0, n_u), relevant_.get_view(n_u, n_u + n_p)};
  out_.fem.n_pressure_dofs = n_p;
  support_constraints(dof_, constraints_);

  dl::BlockDynamicSparsityPattern dsp(relevant_blocks_);
  dl::DoFTools::make_sparsity_pattern(dof_, dsp, constraints_, false);
  dl::SparsityTools::distribute_sparsity_pattern(dsp, owned_, comm_, relevant_);
  block_matrix_.reinit(owned_blocks_, dsp, comm_);

  // The Schur approximation couples pressures only.
  dl::Table<2, dl::DoFTools::Coupling> coupling(kDim + 1, kDim + 1);
  coupling.fill(dl::DoFTools::none);
  coupling[kDim][kDim] = dl::DoFTools::always;
  dl::BlockDynamicSparsityPattern pdsp(relevant_blocks_);
  dl::DoFTools::make_sparsity_pattern(dof_, coupling, pdsp, constraints_, false);
  dl::SparsityTools::distribute_sparsity_pattern(pdsp, owned_, comm_, relevant_);
  schur_.reinit(owned_blocks_, pdsp, comm_);

  block_rhs_.reinit(owned_blocks_, comm_);
  solution_.reinit(owned_, comm_);
  ghosted_.reinit(owned_, relevant_, comm_);
}

void Distributed::assemble_mixed() {
  assemble_into(block_matrix_, block_rhs_);
  assemble_schur_approximation();
}

void Distributed::assemble_schur_approximation() {
  // Ŝ = (1/(2μ) + 1/λ) M_p (mixed_block_solve.cpp: its derivation and sources).
  const double inv_lambda = std::isinf(form_->lambda()) ? 0.0 : 1.0 / form_->lambda();
  const double scale = 1.0 / (2.0 * form_->mu()) + inv_lambda;
  const dl::FEValuesExtractors::Scalar pressure(kDim);
  dl::FEValues<kDim> fev(mapping_, *fe_, cell_quadrature(2),
                         dl::update_values | dl::update_JxW_values);
  const unsigned n = fe_->n_dofs_per_cell();
  std::vector<dl::types::global_dof_index> dofs(n);
  std::vector<unsigned> local_p;
  for (unsigned i = 0; i < n; ++i)
    if (fe_->system_to_component_index(i).first == kDim) local_p.push_back(i);
  dl::FullMatrix<double> m(local_p.size(), local_p.size());
  for (const auto& cell : dof_.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    fev.reinit(cell);
    cell->get_dof_indices(dofs);
    m = 0.0;
    for (unsigned q = 0; q < fev.n_quadrature_points; ++q) {
      const double w = scale * fev.JxW(q);
      for (unsigned a = 0; a < local_p.size(); ++a)
        for (unsigned b = 0; b < local_p.size(); ++b)
          m(a, b) += w * fev[pressure].value(local_p[a], q) * fev[pressure].value(local_p[b], q);
    }
    for (unsigned a = 0; a < local_p.size(); ++a)
      for (unsigned b = 0; b < local_p.size(); ++b)
        schur_.add(dofs[local_p[a]], dofs[local_p[b]], m(a, b));
  }
  schur_.compress(dl::VectorOperation::add);
}

void Distributed::solve_mixed() {
  const auto& o = problem_.options;
  out_.fem.solver = LinearSolver::gmres_block;
  out_.fem.solver_reason = "the mixed (Taylor-Hood) system: FGMRES with the block preconditioner";
  auto& a = block_matrix_.block(0, 0);
  auto& s = schur_.block(1, 1);
  // ω² = mean diag(A) / mean diag(Ŝ): balances the blocks (as the serial solver).
  const double omega = std::sqrt(mean_diagonal(a, owned_blocks_[0], comm_) /
                                 mean_diagonal(s, owned_blocks_[1], comm_));
  block_matrix_.block(0, 1) *= omega;
  block_matrix_.block(1, 0) *= omega;
  block_matrix_.block(1, 1) *= omega * omega;
  block_rhs_.block(1) *= omega;

  dl::TrilinosWrappers::PreconditionAMG amg;
  std::vector<double> modes_storage;  // must outlive amg
  initialize_elasticity_amg(amg, a, displacement_rows(mapping_, dof_, owned_blocks_[0]),
                            part_.centroid, true, o.amg_rigid_body_modes, AmgProlongator::smoothed,
                            modes_storage);
  release_free_memory();  // ML's set-up temporaries
  report_memory(static_cast<int>(rank_), "AMG hierarchy built");
  const BlockPreconditioner prec(block_matrix_.block(0, 1), amg, s, omega, owned_blocks_[0],
                                 comm_);
  BlockVectorT y(owned_blocks_, comm_);
  const double b_norm = block_rhs_.l2_norm();
  if (b_norm > 0.0) {
    dl::SolverControl control(o.max_iterations, o.cg_relative_tolerance * b_norm);
    dl::SolverFGMRES<BlockVectorT> gmres(
        control, dl::SolverFGMRES<BlockVectorT>::AdditionalData(o.gmres_restart));
    try {
      gmres.solve(block_matrix_, y, block_rhs_, prec);
    } catch (const dl::SolverControl::NoConvergence& e) {
      std::ostringstream m;
      m << "distributed FGMRES with the block preconditioner did not converge in " << e.last_step
        << " iterations (residual " << e.last_residual << " of " << b_norm
        << "): raise --max-iterations";
      throw std::runtime_error(m.str());
    }
    out_.fem.iterations = control.last_step();
    out_.fem.inner_iterations = prec.mean_inner_iterations();
  }
  y.block(1) *= omega;  // p = ω p̃
  for (const auto i : owned_) solution_(i) = y(i);
  solution_.compress(dl::VectorOperation::insert);
  constraints_.distribute(solution_);
  ghosted_ = solution_;
}

}  // namespace vessel::fem::detail
