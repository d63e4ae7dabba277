/// The serial static solve: assembly of the weak form (detail/weak_form), the linear solvers
/// (CHOLMOD, UMFPACK, CG with AMG; the mixed system's FGMRES is in mixed_block_solve.cpp) and the
/// post-processing (nodal displacement, energy, strains, stresses, reactions).
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparse_direct.h>

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "fem_reference/cholmod_solve.hpp"
#include "fem_reference/detail/constraints.hpp"
#include "fem_reference/detail/serial_solver.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/foundation/solver_threads.hpp"

namespace vessel::fem {

void ElasticitySolver::Impl::assemble() {
  ensure_matrix();
  detail::CellValues values(*mapping, *fe, degree);
  const unsigned n = fe->n_dofs_per_cell();
  dl::FullMatrix<double> k(n, n);
  dl::Vector<double> f(n);
  std::vector<Index> dofs(n);
  Vec3 applied = Vec3::Zero();
  for (const auto& cell : dof.active_cell_iterators()) {
    form->local_system(cell, values, k, f, &applied);
    cell->get_dof_indices(dofs);
    constraints.distribute_local_to_global(k, f, dofs, matrix, rhs);
  }
  result.applied_load = applied;
}

namespace detail {

namespace {

/// `automatic`'s rule: the matrix-free p-multigrid for the linear reference's P2 solve on
/// straight-sided tets from matrix_free_min_dofs; otherwise a direct solve up to the direct
/// limit and an iterative one beyond.
SolverChoice automatic_solver(const SolverOptions& o, const SystemShape& shape) {
  const std::string dofs = std::to_string(shape.n_dofs) + " DoFs";
  if (!shape.mixed && shape.linear_static && shape.degree == 2 && !shape.curved && !o.keep_factor &&
      o.matrix_free_min_dofs > 0 && shape.n_dofs >= o.matrix_free_min_dofs) {
    return {LinearSolver::matrix_free, "auto: " + dofs + " >= matrix-free-min-dofs " +
                                           std::to_string(o.matrix_free_min_dofs) +
                                           " (P2 on straight-sided tets, no kept factor)"};
  }
  const std::size_t limit = shape.mixed ? o.direct_max_mixed_dofs : o.direct_max_dofs;
  const std::string limit_name = shape.mixed ? "direct-max-mixed-dofs " : "direct-max-dofs ";
  if (shape.n_dofs <= limit) {
    return {LinearSolver::direct, "auto: " + dofs + " <= " + limit_name + std::to_string(limit)};
  }
  return {shape.mixed ? LinearSolver::gmres_block : LinearSolver::cg_amg,
          "auto: " + dofs + " > " + limit_name + std::to_string(limit)};
}

}  // namespace

SolverChoice chosen_solver(const SolverOptions& o, const SystemShape& shape) {
  const bool mixed = shape.mixed;
  const SolverChoice choice = o.solver == LinearSolver::automatic
                                  ? automatic_solver(o, shape)
                                  : SolverChoice{o.solver, "requested"};
  const LinearSolver s = choice.solver;
  if (s == LinearSolver::cg_amg && mixed) {
    throw InputError(
        "solver cg-amg is for the symmetric positive definite displacement system; the mixed "
        "(Taylor-Hood) system is indefinite: use gmres-block (block-preconditioned FGMRES) or "
        "direct");
  }
  if (s == LinearSolver::matrix_free && mixed) {
    throw InputError(
        "solver matrix-free is for the displacement system (P1, P2); the mixed (Taylor-Hood) "
        "system needs gmres-block or direct");
  }
  if (s == LinearSolver::gmres_block && !mixed) {
    throw InputError(
        "solver gmres-block is for the mixed (Taylor-Hood) system; the displacement system is "
        "symmetric positive definite: use cg-amg or direct");
  }
  return choice;
}

}  // namespace detail

void ElasticitySolver::Impl::solve_linear(bool symmetric, DirectReuse reuse) {
  const SolverChoice choice =
      detail::chosen_solver(problem.options, {mixed, dof.n_dofs(), degree, false, false});
  LinearSolver s = choice.solver;
  if (!symmetric && !mixed && s == LinearSolver::cg_amg) {
    if (problem.options.solver == LinearSolver::cg_amg) {
      throw InputError(
          "solver cg-amg needs a symmetric matrix; the finite-strain tangent with follower "
          "pressure is not symmetric: use direct (UMFPACK)");
    }
    s = LinearSolver::direct;
  }
  if (s == LinearSolver::matrix_free) {
    // The linear reference's solve() and the finite-strain Newton take it before this.
    throw std::logic_error("solve_linear: the matrix-free solver is not an assembled one");
  }
  result.solver = s;
  result.solver_reason =
      s == choice.solver ? choice.reason : choice.reason + "; direct: the matrix is not symmetric";
  if (rhs.l2_norm() == 0.0) {
    solution = 0.0;  // no load and homogeneous constraints: u = 0
  } else if (s == LinearSolver::direct && !mixed && symmetric) {
    solve_displacement_direct(reuse);
  } else if (s == LinearSolver::direct) {
    // UMFPACK for the indefinite mixed (Taylor–Hood) system and for a nonsymmetric matrix.
    apply_solver_threads();  // UMFPACK's dense kernels are OpenBLAS's
    dl::SparseDirectUMFPACK direct;
    direct.initialize(matrix);
    direct.vmult(solution, rhs);
  } else if (s == LinearSolver::gmres_block) {
    solve_mixed_iterative();
  } else {
    solve_displacement_cg_amg();
  }
  constraints.distribute(solution);
}

void ElasticitySolver::Impl::solve_displacement_direct(DirectReuse reuse) {
  // CHOLMOD (supernodal Cholesky) for the SPD displacement system: the constraints keep K
  // symmetric with positive diagonal entries on constrained rows.
  const Index n = dof.n_dofs();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(matrix.n_nonzero_elements());
  // The entries: the nonzero values; for a sequence of one pattern (DirectReuse::analysis), every
  // coupling of two free DoFs whatever its value, so that the pattern stays that of the first
  // matrix (a tangent at u = 0 has zeros a deformed one fills in) and is analysed once.
  const bool structural = reuse == DirectReuse::analysis;
  for (Index row = 0; row < n; ++row) {
    const bool row_free = !constraints.is_constrained(row);
    for (auto it = matrix.begin(row); it != matrix.end(row); ++it) {
      const Index col = it->column();
      const bool keep = structural ? (row == col || (row_free && !constraints.is_constrained(col)))
                                   : it->value() != 0.0;
      if (keep) entries.emplace_back(static_cast<int>(row), static_cast<int>(col), it->value());
    }
  }
  Eigen::SparseMatrix<double> K(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  K.setFromTriplets(entries.begin(), entries.end());
  const Eigen::Map<const Eigen::VectorXd> b(rhs.begin(), static_cast<Eigen::Index>(n));
  Eigen::VectorXd x;
  if (reuse == DirectReuse::factor) {
    x = solve_spd_cholmod_keeping_factor(K, b);
  } else if (reuse == DirectReuse::analysis) {
    if (!same_pattern) same_pattern = std::make_unique<CholmodSamePattern>();
    x = same_pattern->solve(K, b);
  } else {
    x = solve_spd_cholmod(K, b);
  }
  std::copy(x.data(), x.data() + x.size(), solution.begin());
}

std::vector<unsigned> ElasticitySolver::Impl::dof_components() const {
  std::vector<unsigned> component(dof.n_dofs(), 0);
  std::vector<Index> dofs(fe->n_dofs_per_cell());
  for (const auto& cell : dof.active_cell_iterators()) {
    cell->get_dof_indices(dofs);
    for (unsigned i = 0; i < dofs.size(); ++i)
      component[dofs[i]] = fe->system_to_component_index(i).first;
  }
  return component;
}

detail::DisplacementRows ElasticitySolver::Impl::displacement_rows(
    const std::vector<Index>& rows) const {
  std::vector<dl::Point<kDim>> x(dof.n_dofs());
  dl::DoFTools::map_dofs_to_support_points(*mapping, dof, x);
  const auto component = dof_components();
  detail::DisplacementRows out;
  if (rows.empty()) {
    out.support = std::move(x);
    out.component = component;
    return out;
  }
  for (const Index d : rows) {
    out.support.push_back(x[d]);
    out.component.push_back(component[d]);
  }
  return out;
}

void ElasticitySolver::Impl::solve_displacement_cg_amg() {
  const auto& o = problem.options;
  detail::ensure_mpi_initialized();  // before any Trilinos object is made
  dl::TrilinosWrappers::SparseMatrix trilinos_matrix;
  trilinos_matrix.reinit(matrix);
  dl::TrilinosWrappers::PreconditionAMG amg;
  std::vector<double> modes_storage;  // must outlive amg
  detail::initialize_elasticity_amg(amg, trilinos_matrix, displacement_rows({}),
                                    detail::node_centroid(mesh), degree > 1,
                                    o.amg_rigid_body_modes, detail::AmgProlongator::plain,
                                    modes_storage);
  dl::SolverControl control(o.max_iterations, o.cg_relative_tolerance * rhs.l2_norm());
  dl::SolverCG<dl::Vector<double>> cg(control);
  try {
    cg.solve(matrix, solution, rhs, amg);
  } catch (const dl::SolverControl::NoConvergence& e) {
    std::ostringstream m;
    m << "CG with AMG did not converge in " << e.last_step << " iterations (residual "
      << e.last_residual << "); try --solver direct or more --max-iterations";
    throw std::runtime_error(m.str());
  }
  result.iterations = control.last_step();
}

namespace {

/// ε and σ = 2μ ε − p I at the centroid of `cell`, as (xx, yy, zz, xy, yz, xz).
void centroid_strain_stress(const detail::WeakForm& form, dl::FEValues<kDim>& centre,
                            const detail::CellIterator& cell, const dl::Vector<double>& u,
                            std::array<double, 6>& strain, std::array<double, 6>& stress) {
  const dl::FEValuesExtractors::Vector disp(0);
  const dl::FEValuesExtractors::Scalar pres(kDim);
  centre.reinit(cell);
  std::vector<dl::SymmetricTensor<2, kDim>> e1(1);
  std::vector<double> p1(1, 0.0);
  centre[disp].get_function_symmetric_gradients(u, e1);
  if (form.mixed()) centre[pres].get_function_values(u, p1);
  const double pc = form.mixed() ? p1[0] : -form.lambda() * dl::trace(e1[0]);
  const dl::SymmetricTensor<2, kDim> sigma =
      2.0 * form.mu() * e1[0] - pc * dl::unit_symmetric_tensor<kDim>();
  constexpr std::array<std::array<unsigned, 2>, 6> kVoigt{
      {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}}};
  for (unsigned v = 0; v < 6; ++v) {
    strain[v] = e1[0][kVoigt[v][0]][kVoigt[v][1]];
    stress[v] = sigma[kVoigt[v][0]][kVoigt[v][1]];
  }
}

}  // namespace

void ElasticitySolver::Impl::postprocess() {
  result.nodal_displacement = nodal([&](Index d) { return solution(d); });

  // Energy and principal strains at the assembly quadrature points; ε, σ at each centroid; the
  // residual K_e u_e − f_e of the unconstrained system: the support reactions at Dirichlet DoFs.
  detail::CellValues values(*mapping, *fe, degree);
  dl::FEValues<kDim> centre(*mapping, *fe, dl::Quadrature<kDim>(dl::Point<kDim>(0.25, 0.25, 0.25)),
                            dl::update_values | dl::update_gradients);
  detail::StrainSummary strain;
  result.tet_strain.assign(mesh.tets.size(), {});
  result.tet_stress.assign(mesh.tets.size(), {});
  dl::Vector<double> r_local, residual(dof.n_dofs());
  std::vector<Index> dofs;
  for (const auto& cell : dof.active_cell_iterators()) {
    detail::element_residual(*form, cell, values, solution, dofs, r_local);  // values.cell on cell
    for (unsigned i = 0; i < dofs.size(); ++i) residual(dofs[i]) += r_local(i);
    detail::add_cell_strain(*form, values.cell, solution, strain);
    const auto idx = cell->active_cell_index();
    centroid_strain_stress(*form, centre, cell, solution, result.tet_strain[idx],
                           result.tet_stress[idx]);
  }
  result.strain_energy = strain.energy;
  result.max_principal_strain = strain.max_principal;
  result.max_abs_principal_strain = strain.max_abs_principal;

  result.reactions.clear();
  const dl::IndexSet all = dof.locally_owned_dofs();
  std::vector<std::string> seen;
  for (const auto& bc : problem.dirichlet) {
    if (std::find(seen.begin(), seen.end(), bc.group) != seen.end()) continue;
    seen.push_back(bc.group);
    result.reactions.push_back(
        {bc.group, detail::group_reaction(dof, constraints, detail::group_boundary_id(mesh, bc.group),
                                          all, residual)});
  }
}

}  // namespace vessel::fem
