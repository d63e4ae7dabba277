#pragma once
/// The FEM reference in parallel with MPI, P1, P2 and Taylor–Hood on deal.II's fully distributed
/// triangulation with Trilinos matrices and vectors. The displacement formulation by the
/// matrix-free p-multigrid CG (where the serial `automatic` rule takes it, or on request) or by
/// CG with ML AMG (all six rigid-body modes as near-null space), the mixed one (ν up to 0.5) by
/// FGMRES with the block-triangular AMG / pressure-mass preconditioner. Plain data only: deal.II
/// and mpi.h stay inside fem_reference's .cpp files and detail/ headers. SI units throughout.
///
/// Every function here is collective over MPI_COMM_WORLD (or over the single calling rank with
/// DistributedOptions::self_only). Only rank 0 needs the whole mesh: it partitions it and sends
/// each rank its own cells, a ghost layer and the loads and supports on them.
#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include "fem_reference/elasticity.hpp"
#include "meshes/tet_mesh.hpp"

namespace vessel::fem {

/// MPI for the lifetime of the object (deal.II's MPI_InitFinalize: also p4est, PETSc, Zoltan),
/// one thread per rank. Create it once, before any distributed call; not needed by the serial
/// ElasticitySolver. Throws std::logic_error if MPI is already initialised (it can be once per
/// process only).
class MpiSession {
 public:
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  /// This process's rank in MPI_COMM_WORLD and the number of ranks.
  [[nodiscard]] int rank() const;
  [[nodiscard]] int size() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Collective: calls `work` on rank 0 only (e.g. meshing and building the problem before
/// solve_elasticity_distributed); if it throws, rank 0 rethrows its exception and every other rank
/// throws InputError with the same message, so no rank is left waiting.
void run_on_rank0(const std::function<void()>& work);

/// Collective: rank 0's `values` on every rank (the other ranks' are replaced).
std::vector<int> broadcast_from_rank0(std::vector<int> values);

/// Collective: calls `make` on rank 0 only and sends its mesh to every rank, so all ranks solve
/// the same mesh (a generated mesh is read from the cache or meshed once, not once per rank). If
/// `make` throws on rank 0, rank 0 rethrows its exception and every other rank throws InputError
/// with the same message, so no rank is left waiting.
TetMesh make_mesh_on_rank0(const std::function<TetMesh()>& make);

struct DistributedOptions {
  /// Solve on MPI_COMM_SELF (this rank alone) instead of MPI_COMM_WORLD: a one-rank reference
  /// inside a multi-rank run (the 1-vs-2-rank test). Not collective over the world then.
  bool self_only = false;
  /// Points (m) at which the FE displacement is evaluated (e.g. the contact point or a model's
  /// nodes), in the tet ElasticitySolver::displacement_at would use; InputError naming the first
  /// point outside the mesh by more than `outside_tolerance` (barycentric, as displacement_at's).
  /// Rank 0's points and tolerance are used (it locates them in the whole mesh once and each is
  /// evaluated by the rank owning its tet); the other ranks' are ignored.
  std::vector<Vec3> evaluation_points;
  double outside_tolerance = 1e-9;
  /// Gather the solution on rank 0 in the serial ElasticitySolver's DoF numbering
  /// (DistributedResult::serial_dofs). Rank 0's choice is used.
  bool serial_dofs = false;
};

struct DistributedResult {
  /// Same meaning as the serial result's fields, with these differences: nodal_displacement (every
  /// TetMesh node, m) is filled on rank 0 only (gathered there; empty on other ranks);
  /// tet_strain and tet_stress are empty (not gathered); solver is matrix_free or cg_amg
  /// (displacement) or gmres_block (mixed), with solver_reason; timings are the slowest rank's
  /// per phase, matrix_free (the profile) this rank's; applied_load, reactions,
  /// strain_energy and the principal strains are global (reduced over the ranks) on every rank.
  ElasticityResult fem;
  int n_ranks = 1;
  std::vector<std::size_t> cells_per_rank;  ///< locally owned tets of each rank (every rank)
  std::vector<std::size_t> dofs_per_rank;   ///< locally owned DoFs of each rank (every rank)
  /// Tets of the mesh each rank held (owned and ghosts; every rank): below the mesh's tet count
  /// on more than one rank, since only rank 0 holds the whole mesh.
  std::vector<std::size_t> local_tets_per_rank;
  /// Each rank's peak resident memory (VmHWM) at the end of the solve, bytes (every rank; 0
  /// where /proc is missing).
  std::vector<std::size_t> peak_memory_per_rank;
  std::vector<Vec3>
      point_displacement;       ///< at DistributedOptions::evaluation_points, m (every rank)
  std::vector<int> point_rank;  ///< the rank that evaluated each point (every rank)
  /// With DistributedOptions::serial_dofs, on rank 0: the solved DoF values (displacement, and
  /// pressure for the mixed formulation) in the numbering of ElasticitySolver(mesh, problem), so
  /// that ElasticitySolver::restore(fem, serial_dofs) (and fem::SolutionCache) take them.
  std::vector<double> serial_dofs;
};

/// Solves `problem` on `mesh` distributed over the ranks. Only rank 0's `mesh` and `problem` are
/// read: rank 0 validates them, partitions the mesh with METIS (GridTools::partition_triangulation
/// on a serial triangulation that lives only while partitioning) and sends each rank its cells and
/// one layer of ghosts (parallel::fullydistributed::Triangulation) with the part of the TetMesh,
/// loads and supports on them. The other ranks may pass an empty mesh and a default problem,
/// except for the functions, which cannot be sent: if rank 0's problem has a DirichletCondition
/// value or a body_force, every rank's problem must have it at the same place (std::logic_error
/// on every rank otherwise). The displacement system: the matrix-free p-multigrid CG where the
/// serial `automatic` rule picks it (P2 from matrix_free_min_dofs DoFs) or options.solver asks
/// for it, else CG with Trilinos ML AMG, to options.cg_relative_tolerance (the mixed system: FGMRES
/// to the same relative residual of the scaled system, as the serial gmres_block). Supports P1 and
/// P2 displacement elements and the Taylor–Hood element (chosen as the serial solver chooses:
/// options.formulation and mixed_threshold), clamped and roller Dirichlet groups, point
/// constraints, pressures, traction patches, gravity and body forces. InputError (the same on every
/// rank) for invalid parameters, a missing group, a point constraint off the nodes, an evaluation
/// point off the mesh, and what is not distributed: curved surfaces and the direct solver. With the
/// environment variable VESSELVERIFY_MEMORY set, each rank prints its resident and peak memory
/// after each phase to stderr. std::runtime_error if the Krylov solver does not converge.
DistributedResult solve_elasticity_distributed(const TetMesh& mesh,
                                               const ElasticityProblem& problem,
                                               const DistributedOptions& options = {});

}  // namespace vessel::fem
