#pragma once
/// Private to fem_reference: the state of the serial ElasticitySolver (its pimpl), shared by the
/// files that implement it: elasticity.cpp (setup), static_solve.cpp, mixed_block_solve.cpp,
/// point_evaluation.cpp, free_system.cpp, modes.cpp and transient.cpp.
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>

#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "fem_reference/cholmod_solve.hpp"
#include "fem_reference/detail/amg.hpp"
#include "fem_reference/detail/boundary.hpp"
#include "fem_reference/detail/postprocess.hpp"
#include "fem_reference/detail/tet_locator.hpp"
#include "fem_reference/detail/weak_form.hpp"
#include "fem_reference/elasticity.hpp"

namespace vessel::fem {

namespace dl = dealii;

/// What a direct displacement solve keeps for the next: nothing; the factor, for an identical
/// matrix (solve_spd_cholmod_keeping_factor: a linear reference's other loads); or the symbolic
/// analysis, for the next matrix of the same pattern (a Newton method's tangents; held in
/// Impl::same_pattern until release_same_pattern()).
enum class DirectReuse { nothing, factor, analysis };
using detail::kDim;

namespace detail {
/// What chosen_solver needs to know of the system.
struct SystemShape {
  bool mixed = false;
  std::size_t n_dofs = 0;
  int degree = 1;
  /// P2 geometry on a curved surface (the matrix-free kernel is for straight tets)
  bool curved = false;
  /// the linear reference's one solve (ElasticitySolver::solve), not a Newton tangent
  bool linear_static = false;
};
/// The solver `automatic` picks for `shape` and why, or InputError for a solver that does not fit
/// the system.
SolverChoice chosen_solver(const SolverOptions& o, const SystemShape& shape);
}  // namespace detail
using Index = dealii::types::global_dof_index;

struct ElasticitySolver::Impl {
  TetMesh mesh;
  ElasticityProblem problem;
  bool mixed = false;
  int degree = 1;
  /// The linear reference's solver (solve()), chosen once the DoFs are distributed.
  SolverChoice linear_choice;

  dl::Triangulation<kDim> tria;
  detail::MeshCorrespondence mesh_map;
  std::unique_ptr<detail::WeakForm> form;
  std::unique_ptr<dl::FiniteElement<kDim>> fe;
  std::unique_ptr<dl::MappingFE<kDim>> linear_mapping;
  std::unique_ptr<dl::Mapping<kDim>> mapping;  // linear_mapping's copy, or the curved one
  std::unique_ptr<dl::FiniteElement<kDim>> geometry_fe;
  dl::DoFHandler<kDim> geometry_dof;
  dl::Vector<double> geometry_positions;  // absolute positions of the P2 geometry nodes
  dl::DoFHandler<kDim> dof;
  dl::AffineConstraints<double> constraints;
  dl::SparsityPattern sparsity;
  dl::SparseMatrix<double> matrix;
  dl::Vector<double> rhs, solution;

  std::vector<dl::DoFHandler<kDim>::active_cell_iterator> cells;  // by tet index
  std::unique_ptr<detail::TetLocator> locator;
  ElasticityResult result;
  bool solved = false;
  /// The matrix holds a finite-strain tangent (HyperelasticSolver), whose displacement block is
  /// not the linear 2μ ε:ε: the mixed block preconditioner then takes AMG on the block itself.
  bool tangent_systems = false;

  Impl(const TetMesh& m, ElasticityProblem p) : mesh(m), problem(std::move(p)) {}

  // elasticity.cpp: the triangulation, DoFs, constraints and sparsity.
  void build_triangulation();
  void setup_dofs();
  void setup_curved_mapping();

  // static_solve.cpp
  void assemble();
  /// Solves matrix · solution = rhs and distributes the constraints. `symmetric` false (the
  /// finite-strain tangent with follower pressure): UMFPACK instead of CHOLMOD, and automatic
  /// never picks CG-AMG.
  /// `reuse`: what a direct displacement solve (CHOLMOD) keeps for the next one.
  void solve_linear(bool symmetric = true, DirectReuse reuse = DirectReuse::nothing);
  void solve_displacement_direct(DirectReuse reuse);
  /// The analysis DirectReuse::analysis keeps (with its last factor): freed here.
  std::unique_ptr<CholmodSamePattern> same_pattern;
  void release_same_pattern() { same_pattern.reset(); }
  void solve_displacement_cg_amg();
  /// matrix_free: CG on the matrix-free operator with the p-multigrid (detail/
  /// matrix_free_elasticity), on rhs assembled without the matrix (assemble_load).
  void solve_displacement_matrix_free();
  /// rhs only (the matrix stays empty): the loads and −K u₀ of the prescribed values, cell by cell.
  void assemble_load();
  /// The sparsity pattern and matrix of the assembled path, built on first use (the matrix-free
  /// path never builds them).
  void ensure_matrix();
  /// The problem's supports on a displacement DoFHandler of this mesh (P1 or P2).
  void support_constraints(const dl::DoFHandler<kDim>& dof_handler,
                           dl::AffineConstraints<double>& c) const;
  void postprocess();
  /// Per DoF: its component (0..2 displacement, 3 pressure).
  [[nodiscard]] std::vector<unsigned> dof_components() const;
  /// The displacement DoFs `rows` (all when empty) with their support points and components.
  [[nodiscard]] detail::DisplacementRows displacement_rows(const std::vector<Index>& rows) const;

  // mixed_block_solve.cpp: FGMRES with the block-triangular preconditioner.
  void solve_mixed_iterative();
  /// The Schur complement's approximation (1/(2μ) + 1/λ) M_p on the pressure DoFs (`p_local`: a
  /// DoF's pressure row, −1 for displacement DoFs; n_p rows).
  void assemble_schur_approximation(const std::vector<int>& p_local, Index n_p,
                                    dl::SparsityPattern& pattern,
                                    dl::SparseMatrix<double>& schur) const;

  // point_evaluation.cpp
  /// The FE displacement at x as Σ w · u[dof]: the element's shape functions at x, per DoF and
  /// displacement component. InputError if x is outside the mesh (beyond `tol`, barycentric).
  struct PointStencil {
    std::vector<Index> dofs;
    std::vector<unsigned> components;
    std::vector<double> weights;
  };
  [[nodiscard]] PointStencil point_stencil(const Vec3& x, double tol) const;

  // free_system.cpp
  /// Stiffness (and mass) of the displacement formulation on the unconstrained DoFs, condensed
  /// like the static system (prescribed Dirichlet values moved to f), with `free_index` mapping
  /// each DoF to its row (−1: constrained) and `constrained_value` each constrained DoF's value.
  struct FreeSystem {
    std::vector<int> free_index;
    std::vector<double> constrained_value;
    Eigen::SparseMatrix<double> K, M;
    Eigen::VectorXd f;
  };
  [[nodiscard]] FreeSystem assemble_free_system(bool with_mass) const;
  /// Per TetMesh node, the rows of its x, y and z displacement (−1 where constrained) under
  /// `free_index` (FreeDisplacementSystem::node_rows).
  [[nodiscard]] std::vector<std::array<int, 3>> node_rows(const std::vector<int>& free_index) const;
  /// Fills `system`'s row_points and row_components from its free_index.
  void set_row_points(FreeDisplacementSystem& system) const;
  /// The rows and columns of `a` at free DoFs (free_index ≥ 0), renumbered by free_index.
  [[nodiscard]] static Eigen::SparseMatrix<double> free_block(const dl::SparseMatrix<double>& a,
                                                              const std::vector<int>& free_index,
                                                              int n_free);
  /// Per TetMesh node, the vertex DoFs' values value(dof).
  template <class ValueOfDof>
  [[nodiscard]] std::vector<Vec3> nodal(const ValueOfDof& value) const;
};

template <class ValueOfDof>
std::vector<Vec3> ElasticitySolver::Impl::nodal(const ValueOfDof& value) const {
  return detail::nodal_values(dof, mesh_map.vertex_node, mesh.nodes.size(), value);
}

}  // namespace vessel::fem
