#pragma once
/// Private to fem_reference: the state of the distributed (MPI) solver, shared by the files that
/// implement it: distributed_elasticity.cpp (triangulation, displacement system, CG-AMG, post-
/// processing), distributed_mixed.cpp (Taylor–Hood on Trilinos block matrices, FGMRES) and
/// distributed_gather.cpp (what rank 0 collects: nodal field, the solution in the serial solver's
/// DoF numbering, point values).
#include <deal.II/base/index_set.h>
#include <deal.II/distributed/fully_distributed_tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_block_sparse_matrix.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <mpi.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fem_reference/detail/amg.hpp"
#include "fem_reference/detail/boundary.hpp"
#include "fem_reference/detail/postprocess.hpp"
#include "fem_reference/detail/rank_part.hpp"
#include "fem_reference/detail/weak_form.hpp"
#include "fem_reference/distributed_elasticity.hpp"

namespace vessel::fem::detail {

using VectorT = dl::TrilinosWrappers::MPI::Vector;
using BlockVectorT = dl::TrilinosWrappers::MPI::BlockVector;

/// The displacement system's solver on several ranks: matrix-free where the serial `automatic`
/// rule (or the request) takes it, CG with AMG otherwise (there is no distributed direct solve).
SolverChoice distributed_displacement_solver(const SolverOptions& o, std::size_t n_dofs,
                                             int degree);

class Distributed {
 public:
  /// `mesh` and `problem`: the whole mesh and the problem on rank 0 (validated); other ranks'
  /// mesh is not read and their problem only supplies the functions (rank_part.hpp).
  Distributed(const TetMesh& mesh, const ElasticityProblem& problem, MPI_Comm comm);

  DistributedResult run(const DistributedOptions& options);

 private:
  // distributed_elasticity.cpp
  /// Rank 0 partitions the whole mesh (METIS) and sends each rank its cells with a ghost layer
  /// and its part of the mesh and problem (part_); the whole mesh is read on rank 0 only.
  void build_triangulation(const DistributedOptions& options);
  /// Frees what the solve needed and the post-processing does not (the matrices).
  void release_system();
  void setup_dofs();
  /// The supports (Dirichlet groups and point constraints) on `dof` (this rank's relevant DoFs),
  /// closed: the solution's DoFHandler or the p-multigrid's P1 level.
  void support_constraints(const dl::DoFHandler<kDim>& dof,
                           dl::AffineConstraints<double>& constraints) const;
  void assemble();
  /// The locally owned cells' weak form into `matrix` and `rhs` (plain or block, Trilinos),
  /// compressed; the applied load summed over the ranks into out_.
  template <class Matrix, class Vector>
  void assemble_into(Matrix& matrix, Vector& rhs) {
    CellValues values(mapping_, *fe_, degree_);
    const unsigned n = fe_->n_dofs_per_cell();
    dl::FullMatrix<double> k(n, n);
    dl::Vector<double> f(n);
    std::vector<dl::types::global_dof_index> dofs(n);
    Vec3 applied = Vec3::Zero();
    for (const auto& cell : dof_.active_cell_iterators()) {
      if (!cell->is_locally_owned()) continue;
      form_->local_system(cell, values, k, f, &applied);
      cell->get_dof_indices(dofs);
      constraints_.distribute_local_to_global(k, f, dofs, matrix, rhs);
    }
    matrix.compress(dl::VectorOperation::add);
    rhs.compress(dl::VectorOperation::add);
    out_.fem.applied_load = sum_over_ranks(applied);
  }
  void solve_linear();
  /// CG on the matrix-free operator with the p-multigrid (the serial solver's, on this rank's
  /// cells): rhs_ → solution_.
  void solve_matrix_free();
  void postprocess();
  [[nodiscard]] VectorT residual(StrainSummary& strain) const;
  [[nodiscard]] double max_over_ranks(double v) const;
  [[nodiscard]] Vec3 sum_over_ranks(const Vec3& v) const;

  // distributed_mixed.cpp: the Taylor–Hood system in two blocks (u, p), step-55's layout.
  void setup_mixed_system();
  void assemble_mixed();
  void assemble_schur_approximation();
  void solve_mixed();

  // distributed_gather.cpp
  void gather_nodal_displacement();
  /// Rank 0: the solution in the serial ElasticitySolver's DoF numbering (empty elsewhere).
  [[nodiscard]] std::vector<double> gather_serial_dofs() const;
  /// Rank 0: `value[k]` put at the serial DoF of (tet, local index) `where[k]` = tet·n + i, on a
  /// serial DoFHandler numbered as ElasticitySolver's; `failure` says so if not every serial DoF
  /// got exactly one value.
  [[nodiscard]] std::vector<double> place_in_serial_numbering(const std::vector<std::int64_t>& where,
                                                              const std::vector<double>& value,
                                                              std::string& failure) const;
  /// Every rank: u at every evaluation point (each evaluated by the rank owning its tet, found
  /// once by rank 0), and which rank evaluated it.
  [[nodiscard]] std::vector<Vec3> evaluate(std::vector<int>& point_rank) const;

  const TetMesh& input_;                    // the whole mesh: rank 0 only
  const ElasticityProblem& input_problem_;  // rank 0's problem; elsewhere its functions only
  RankPart part_;                           // this rank's part (distributed_parts.cpp)
  const TetMesh& mesh_ = part_.mesh;
  const ElasticityProblem& problem_ = part_.problem;
  MPI_Comm comm_;
  unsigned rank_, n_ranks_;
  bool mixed_ = false;
  bool matrix_free_ = false;  // the displacement system without its matrix
  int degree_ = 1;

  dl::FE_SimplexP<kDim> linear_;
  dl::MappingFE<kDim> mapping_;
  dl::parallel::fullydistributed::Triangulation<kDim> tria_;
  MeshCorrespondence mesh_map_;  // for the local cells (ghosts included)
  std::unique_ptr<WeakForm> form_;
  std::unique_ptr<dl::FiniteElement<kDim>> fe_;
  dl::DoFHandler<kDim> dof_;
  dl::IndexSet owned_, relevant_;
  dl::AffineConstraints<double> constraints_;
  // Displacement formulation: one matrix. Mixed: the (u, p) blocks and the Schur approximation.
  dl::TrilinosWrappers::SparseMatrix matrix_;
  std::vector<dl::IndexSet> owned_blocks_, relevant_blocks_;
  dl::TrilinosWrappers::BlockSparseMatrix block_matrix_, schur_;
  BlockVectorT block_rhs_;
  // The solution (both formulations) in one vector for post-processing.
  VectorT rhs_, solution_, ghosted_;

  DistributedResult out_;
};

}  // namespace vessel::fem::detail
