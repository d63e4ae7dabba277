#pragma once
/// Private to fem_reference: Trilinos ML algebraic multigrid for the elasticity matrix, with the
/// rigid-body modes as near-null space; shared by the serial CG / block preconditioner and the
/// distributed CG.
#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

#include <optional>
#include <vector>

#include "fem_reference/detail/common.hpp"

namespace vessel::fem::detail {

/// Trilinos (Epetra/ML) is built with MPI: it needs MPI initialised even on one process. The
/// program may not have done so (a serial run): initialise once and finalise at exit. Safe to
/// call from several threads at once.
void ensure_mpi_initialized();

/// The displacement DoFs a preconditioner works on, in the matrix's (local) row order: each row's
/// support point (m) and displacement component (0..2).
struct DisplacementRows {
  std::vector<dl::Point<kDim>> support;
  std::vector<unsigned> component;
};

/// The rows of `dof` (a displacement FESystem) in `rows` that this rank's cells hold, in the
/// IndexSet's order (a matrix's row map: `rows` = its locally owned DoFs).
DisplacementRows displacement_rows(const dl::Mapping<kDim>& mapping,
                                   const dl::DoFHandler<kDim>& dof, const dl::IndexSet& rows);

/// How ML builds the prolongators from the aggregates. `plain`: the tentative prolongator itself
/// (unsmoothed aggregation): sparse coarse operators and a small set-up, for the displacement
/// system's CG. `smoothed`: one damped Jacobi step on it (Vaněk, Mandel & Brezina 1996), a
/// stronger single V-cycle, for the Taylor–Hood block preconditioner (measured in
/// docs/measurements/cluster_scaling.md).
enum class AmgProlongator { smoothed, plain };

/// Aggregation AMG (ML) of `matrix`, its prolongators as `prolongator` says. With
/// `rigid_body_modes` all six rigid-body modes of `rows` (translations, rotations about `centre`)
/// are ML's near-null space (AdditionalData only passes constant modes, so the ML parameter list is
/// filled first and the modes added as pre-computed vectors; `storage` holds them and must outlive
/// `amg`); without, only the three translations. `aggregation_threshold`: ML drops connections
/// weaker than this fraction of the diagonal when aggregating (none: the prolongator's own
/// default, default_aggregation_threshold). `aggregate_across_ranks`: ML's MIS aggregation, whose
/// aggregates may span the ranks, instead of each rank aggregating its own rows (Uncoupled).
void initialize_elasticity_amg(dl::TrilinosWrappers::PreconditionAMG& amg,
                               const dl::TrilinosWrappers::SparseMatrix& matrix,
                               const DisplacementRows& rows, const Vec3& centre, bool higher_order,
                               bool rigid_body_modes, AmgProlongator prolongator,
                               std::vector<double>& storage,
                               std::optional<double> aggregation_threshold = std::nullopt,
                               bool aggregate_across_ranks = false);

/// The aggregation threshold that gave the fewest CG iterations with `prolongator` on the P2
/// displacement system (plain 0.1, smoothed 0.02).
double default_aggregation_threshold(AmgProlongator prolongator);

/// The centroid of the mesh's nodes: the rotation centre of the rigid-body modes (the same point
/// on every MPI rank).
Vec3 node_centroid(const TetMesh& mesh);

}  // namespace vessel::fem::detail
