#pragma once
/// Private to fem_reference: the block-triangular preconditioner of the serial solver's mixed
/// (Taylor–Hood) system for FGMRES, and the symmetric scaling of that system it works with.
#include <deal.II/lac/precondition.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/vector.h>

#include <functional>
#include <vector>

#include "fem_reference/detail/common.hpp"

namespace vessel::fem::detail {

using Index = dl::types::global_dof_index;

/// The rows and columns `rows` of `a` (renumbered 0..rows.size()−1 by `local`, −1 elsewhere).
void extract_block(const dl::SparseMatrix<double>& a, const std::vector<Index>& rows,
                   const std::vector<int>& local, dl::SparsityPattern& pattern,
                   dl::SparseMatrix<double>& out);

/// The mixed matrix with its pressure rows and columns scaled by ω (D K D, D = diag(1, ω)), so
/// that the residual's displacement and pressure parts weigh alike in GMRES.
class ScaledMixedOperator {
 public:
  ScaledMixedOperator(const dl::SparseMatrix<double>& k, const std::vector<bool>& is_pressure,
                      double omega)
      : k_(k), is_pressure_(is_pressure), omega_(omega), tmp_(k.m()) {}
  void vmult(dl::Vector<double>& dst, const dl::Vector<double>& src) const {
    tmp_ = src;
    scale(tmp_);
    k_.vmult(dst, tmp_);
    scale(dst);
  }
  void scale(dl::Vector<double>& v) const {
    for (Index i = 0; i < v.size(); ++i)
      if (is_pressure_[i]) v(i) *= omega_;
  }

 private:
  const dl::SparseMatrix<double>& k_;
  const std::vector<bool>& is_pressure_;
  double omega_;
  mutable dl::Vector<double> tmp_;
};

/// Block upper-triangular preconditioner P = [Â  ωBᵀ; 0  −ω²Ŝ] for the scaled Taylor–Hood
/// system [A  ωBᵀ; ωB  −ω²C] (step-22 / step-56 pattern): Â⁻¹ one V-cycle on the displacement
/// block (the matrix-free p-multigrid's or AMG's), Ŝ⁻¹ a Jacobi-CG solve with
/// Ŝ = (1/(2μ) + 1/λ) M_p. Inexact inner solves make P vary between applications: used with
/// FGMRES.
class BlockTriangularPreconditioner {
 public:
  /// x = Â⁻¹ r on the displacement block's numbering (u_dofs' order).
  using DisplacementInverse =
      std::function<void(dl::Vector<double>& x, const dl::Vector<double>& r)>;
  BlockTriangularPreconditioner(const ScaledMixedOperator& op, DisplacementInverse a_inverse,
                                const dl::SparseMatrix<double>& schur,
                                const std::vector<Index>& u_dofs, const std::vector<Index>& p_dofs,
                                double omega)
      : op_(op),
        a_inverse_(std::move(a_inverse)),
        schur_(schur),
        u_dofs_(u_dofs),
        p_dofs_(p_dofs),
        omega_(omega) {
    jacobi_.initialize(schur_);
    ru_.reinit(static_cast<Index>(u_dofs.size()));
    xu_.reinit(static_cast<Index>(u_dofs.size()));
    rp_.reinit(static_cast<Index>(p_dofs.size()));
    xp_.reinit(static_cast<Index>(p_dofs.size()));
  }
  void vmult(dl::Vector<double>& dst, const dl::Vector<double>& src) const {
    // p̃ = −(ω²Ŝ)⁻¹ r_p
    for (Index i = 0; i < p_dofs_.size(); ++i) rp_(i) = src(p_dofs_[i]);
    xp_ = 0.0;
    if (rp_.l2_norm() > 0.0) {
      dl::ReductionControl control(1000, 1e-300, 1e-6);
      dl::SolverCG<dl::Vector<double>> cg(control);
      cg.solve(schur_, xp_, rp_, jacobi_);
      inner_iterations_ += control.last_step();
    }
    xp_ *= -1.0 / (omega_ * omega_);
    // u = Â⁻¹ (r_u − ωBᵀ p̃): ωBᵀ p̃ is the displacement part of (D K D)[0; p̃].
    full_.reinit(src.size());
    for (Index i = 0; i < p_dofs_.size(); ++i) full_(p_dofs_[i]) = xp_(i);
    product_.reinit(src.size());
    op_.vmult(product_, full_);
    for (Index i = 0; i < u_dofs_.size(); ++i) ru_(i) = src(u_dofs_[i]) - product_(u_dofs_[i]);
    a_inverse_(xu_, ru_);
    for (Index i = 0; i < u_dofs_.size(); ++i) dst(u_dofs_[i]) = xu_(i);
    for (Index i = 0; i < p_dofs_.size(); ++i) dst(p_dofs_[i]) = xp_(i);
    ++applications_;
  }
  [[nodiscard]] double mean_inner_iterations() const {
    return applications_ ? static_cast<double>(inner_iterations_) / static_cast<double>(applications_)
                        : 0.0;
  }

 private:
  const ScaledMixedOperator& op_;
  DisplacementInverse a_inverse_;
  const dl::SparseMatrix<double>& schur_;
  const std::vector<Index>& u_dofs_;
  const std::vector<Index>& p_dofs_;
  double omega_;
  dl::PreconditionJacobi<dl::SparseMatrix<double>> jacobi_;
  mutable dl::Vector<double> ru_, xu_, rp_, xp_, full_, product_;
  mutable unsigned long inner_iterations_ = 0;
  mutable unsigned long applications_ = 0;
};

}  // namespace vessel::fem::detail
