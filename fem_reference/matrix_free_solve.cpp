/// The serial matrix-free displacement solve: the load vector assembled cell by cell without the
/// stiffness matrix, then CG on the matrix-free operator with the p-multigrid of
/// detail/matrix_free_elasticity.
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/multigrid/mg_transfer_global_coarsening.h>

#include <algorithm>
#include <random>
#include <string>

#include "fem_reference/detail/matrix_free_elasticity.hpp"
#include "fem_reference/detail/serial_solver.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/foundation/solver_threads.hpp"

namespace vessel::fem {

void ElasticitySolver::Impl::assemble_load() {
  result.applied_load =
      detail::assemble_load_vector(*form, *mapping, dof, degree, constraints, rhs);
}

void ElasticitySolver::Impl::solve_displacement_matrix_free() {
  const auto& o = problem.options;
  result.solver = linear_choice.solver;
  result.solver_reason = linear_choice.reason;
  solution = 0.0;
  for (const auto& line : constraints.get_lines()) rhs(line.index) = 0.0;
  if (rhs.l2_norm() != 0.0) {
    detail::PMultigridSettings settings;
    settings.direct_coarse_max_dofs = o.matrix_free_direct_coarse_max_dofs;
    const detail::MatrixFreeElasticitySolver wall(
        *mapping, dof,
        [this](const dl::DoFHandler<kDim>& d, dl::AffineConstraints<double>& c) {
          support_constraints(d, c);
        },
        degree, form->lambda(), form->mu(), detail::node_centroid(mesh), settings);
    result.iterations =
        wall.solve(rhs, solution, o.cg_relative_tolerance, o.max_iterations).iterations;
    result.matrix_free = wall.profile();
  }
  constraints.distribute(solution);
}

namespace {
void require_displacement(bool mixed, const char* what) {
  if (mixed) {
    throw InputError(std::string(what) +
                     ": the matrix-free operator is for the displacement "
                     "formulation (P1, P2), not the mixed one");
  }
}
}  // namespace

std::vector<double> ElasticitySolver::matrix_free_diagonal() const {
  const auto& im = *impl_;
  require_displacement(im.mixed, "matrix_free_diagonal");
  detail::ensure_mpi_initialized();
  const auto homogeneous = detail::homogeneous_copy(im.constraints);
  const detail::ElasticityOperator op(*im.mapping, im.dof, homogeneous, im.degree,
                                      im.form->lambda(), im.form->mu());
  const auto d = op.diagonal();
  return {d.begin(), d.end()};
}

namespace {
/// A u by the matrix-free operator itself or (`by_matrix`) by the matrix built from its kernel;
/// `Impl` is ElasticitySolver's (private, so deduced).
template <typename Impl>
std::vector<double> operator_product(const Impl& im, const std::vector<double>& u, bool by_matrix,
                                     const char* what) {
  require_displacement(im.mixed, what);
  if (u.size() != im.dof.n_dofs()) {
    throw std::invalid_argument(std::string(what) + ": " + std::to_string(u.size()) +
                                " values for a solver with " + std::to_string(im.dof.n_dofs()) +
                                " DoFs");
  }
  detail::ensure_mpi_initialized();
  const auto homogeneous = detail::homogeneous_copy(im.constraints);
  const detail::ElasticityOperator op(*im.mapping, im.dof, homogeneous, im.degree,
                                      im.form->lambda(), im.form->mu(), solver_threads());
  detail::MfVector src, dst;
  op.initialize_dof_vector(src);
  op.initialize_dof_vector(dst);
  std::copy(u.begin(), u.end(), src.begin());
  if (by_matrix) {
    dl::TrilinosWrappers::SparseMatrix matrix;
    op.compute_matrix(matrix);
    matrix.vmult(dst, src);
  } else {
    op.vmult(dst, src);
  }
  return {dst.begin(), dst.end()};
}
}  // namespace

std::vector<double> ElasticitySolver::matrix_free_product(const std::vector<double>& u) const {
  return operator_product(*impl_, u, false, "matrix_free_product");
}

std::vector<double> ElasticitySolver::matrix_free_matrix_product(
    const std::vector<double>& u) const {
  return operator_product(*impl_, u, true, "matrix_free_matrix_product");
}

namespace {
/// max |a − b| / max |b|.
double relative_difference(const detail::MfVector& a, const detail::MfVector& b) {
  detail::MfVector d = a;
  d -= b;
  return d.linfty_norm() / b.linfty_norm();
}

/// Uniform random entries in [−1, 1], zero on the constrained DoFs.
void randomise(detail::MfVector& v, const dl::AffineConstraints<double>& constraints,
               unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (unsigned i = 0; i < v.size(); ++i) {
    v.local_element(i) = constraints.is_constrained(i) ? 0.0 : uniform(rng);
  }
}
}  // namespace

std::array<double, 2> ElasticitySolver::matrix_free_transfer_difference(unsigned seed) const {
  const auto& im = *impl_;
  require_displacement(im.mixed, "matrix_free_transfer_difference");
  if (im.degree != 2) throw std::invalid_argument("matrix_free_transfer_difference: P2 only");
  detail::ensure_mpi_initialized();
  const auto fine_constraints = detail::homogeneous_copy(im.constraints);
  dl::DoFHandler<kDim> p1(im.dof.get_triangulation());
  p1.distribute_dofs(dl::FESystem<kDim>(dl::FE_SimplexP<kDim>(1), kDim));
  dl::AffineConstraints<double> c;
  im.support_constraints(p1, c);
  c.close();
  const auto coarse_constraints = detail::homogeneous_copy(c);
  const dl::Utilities::MPI::Partitioner p2_layout(im.dof.n_dofs()), p1_layout(p1.n_dofs());
  const detail::P1ToP2Embedding embedding(im.dof, p1, fine_constraints, coarse_constraints,
                                          p2_layout, p1_layout);
  dl::MGTwoLevelTransfer<kDim, detail::MfVector> dealii;
  dealii.reinit_polynomial_transfer(im.dof, p1, fine_constraints, coarse_constraints);
  detail::MfVector x(p1.n_dofs()), y(im.dof.n_dofs());
  randomise(x, coarse_constraints, seed);
  randomise(y, fine_constraints, seed + 1);
  detail::MfVector px(im.dof.n_dofs()), px_dealii(im.dof.n_dofs());
  embedding.prolongate_and_add(px, x);
  dealii.prolongate_and_add(px_dealii, x);
  detail::MfVector ry(p1.n_dofs()), ry_dealii(p1.n_dofs());
  embedding.restrict_and_add(ry, y);
  dealii.restrict_and_add(ry_dealii, y);
  return {relative_difference(px, px_dealii), relative_difference(ry, ry_dealii)};
}

}  // namespace vessel::fem
