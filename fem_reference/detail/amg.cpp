#include "fem_reference/detail/amg.hpp"

#include <Epetra_MultiVector.h>
#include <deal.II/fe/fe_values.h>
#include <mpi.h>

#include <Teuchos_ParameterList.hpp>
#include <algorithm>
#include <cstdlib>
#include <memory>
#include <mutex>

namespace vessel::fem::detail {

void ensure_mpi_initialized() {
  // Once per process even when the first solves start on several threads together: a second
  // MPI_Init_thread aborts the process (Open MPI).
  static std::once_flag once;
  std::call_once(once, [] {
    int initialized = 0;
    MPI_Initialized(&initialized);
    if (initialized) return;
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
    std::atexit([] {
      int finalized = 0;
      MPI_Finalized(&finalized);
      if (!finalized) MPI_Finalize();
    });
  });
}

Vec3 node_centroid(const TetMesh& mesh) {
  Vec3 centre = Vec3::Zero();
  for (const auto& p : mesh.nodes) centre += p;
  return centre / static_cast<double>(std::max<std::size_t>(mesh.nodes.size(), 1));
}

DisplacementRows displacement_rows(const dl::Mapping<kDim>& mapping,
                                   const dl::DoFHandler<kDim>& dof, const dl::IndexSet& rows) {
  const auto& fe = dof.get_fe();
  // The support points as deal.II's map_dofs_to_support_points finds them, without its map.
  dl::FEValues<kDim> values(mapping, fe, dl::Quadrature<kDim>(fe.get_unit_support_points()),
                            dl::update_quadrature_points);
  DisplacementRows out;
  out.support.resize(rows.n_elements());
  out.component.assign(rows.n_elements(), 0);
  std::vector<dl::types::global_dof_index> idx(fe.n_dofs_per_cell());
  for (const auto& cell : dof.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    values.reinit(cell);
    cell->get_dof_indices(idx);
    for (unsigned i = 0; i < idx.size(); ++i) {
      if (!rows.is_element(idx[i])) continue;
      const auto row = rows.index_within_set(idx[i]);
      out.support[row] = values.quadrature_point(i);
      out.component[row] = fe.system_to_component_index(i).first;
    }
  }
  return out;
}

namespace {

/// Column-major n × 6: translations along x, y, z, then rotations ω × r about x, y, z.
std::vector<double> rigid_body_mode_vectors(const DisplacementRows& rows, const Vec3& centre) {
  const std::size_t n = rows.support.size();
  std::vector<double> modes(6 * n, 0.0);
  for (std::size_t d = 0; d < n; ++d) {
    const Vec3 r = to_vec3(rows.support[d]) - centre;
    const unsigned c = rows.component[d];
    modes[c * n + d] = 1.0;  // translation along c
    // rotations ω × r about x, y, z: (0, −z, y), (z, 0, −x), (−y, x, 0)
    const double rot[3][3] = {{0, -r[2], r[1]}, {r[2], 0, -r[0]}, {-r[1], r[0], 0}};
    for (unsigned k = 0; k < 3; ++k) modes[(3 + k) * n + d] = rot[k][c];
  }
  return modes;
}

/// Whether the rows come as (x, y, z) triples of one support point on every rank: then ML may
/// aggregate nodes rather than single DoFs ("PDE equations" = 3).
bool rows_are_nodal_triples(const DisplacementRows& rows, MPI_Comm comm) {
  int triples = rows.support.size() % 3 == 0 ? 1 : 0;
  for (std::size_t d = 0; triples && d < rows.support.size(); ++d) {
    const std::size_t first = d - d % 3;
    triples = rows.component[d] == d % 3 && rows.support[d] == rows.support[first] ? 1 : 0;
  }
  MPI_Allreduce(MPI_IN_PLACE, &triples, 1, MPI_INT, MPI_MIN, comm);
  return triples == 1;
}

}  // namespace

void initialize_elasticity_amg(dl::TrilinosWrappers::PreconditionAMG& amg,
                               const dl::TrilinosWrappers::SparseMatrix& matrix,
                               const DisplacementRows& rows, const Vec3& centre, bool higher_order,
                               bool rigid_body_modes, AmgProlongator prolongator,
                               std::vector<double>& storage,
                               std::optional<double> aggregation_threshold,
                               bool aggregate_across_ranks) {
  ensure_mpi_initialized();
  dl::TrilinosWrappers::PreconditionAMG::AdditionalData data;
  data.elliptic = true;
  data.higher_order_elements = higher_order;
  data.smoother_sweeps = 2;
  const bool plain = prolongator == AmgProlongator::plain;
  data.aggregation_threshold =
      aggregation_threshold.value_or(default_aggregation_threshold(prolongator));
  const std::size_t n = rows.support.size();
  if (!rigid_body_modes) {
    data.constant_modes.assign(3, std::vector<bool>(n, false));
    for (std::size_t d = 0; d < n; ++d) data.constant_modes[rows.component[d]][d] = true;
  }
  Teuchos::ParameterList ml;
  std::unique_ptr<Epetra_MultiVector> constant_modes;  // ML copies the null space it is given
  data.set_parameters(ml, constant_modes, matrix);
  if (rigid_body_modes) {
    storage = rigid_body_mode_vectors(rows, centre);
    ml.set("null space: type", "pre-computed");
    ml.set("null space: dimension", 6);
    ml.set("null space: vectors", storage.data());
  }
  // Aggregating nodes (3 DoFs) instead of single DoFs cut the hierarchy's memory by a third with
  // the smoothed prolongator (P2, 204k DoFs: 0.70 GB against 1.06 GB), and the iterations fell
  // slightly (113 against 120).
  if (rows_are_nodal_triples(rows, matrix.get_mpi_communicator())) ml.set("PDE equations", 3);
  // Plain aggregation: the tentative prolongator, not smoothed by a damped Jacobi step (damping
  // 0). Smoothing fills each prolongator row with the matrix's stencil, and ML's set-up holds A·P
  // and a copy of it while forming the coarse operators: at P2 level 1 (204k DoFs, one rank) the
  // set-up peak is 687 MB against 1148 MB smoothed, the hierarchy left 71 against 217 MB, with 97
  // CG iterations against 112. As the single V-cycle of the Taylor–Hood block preconditioner it
  // is weaker: 212 FGMRES iterations against 125 at level 1.
  if (plain) ml.set("aggregation: damping factor", 0.0);
  // Aggregates across the ranks (ML's MIS) instead of within each (Uncoupled, deal.II's): on
  // the p-multigrid's P1 level of the P2 tube at level 2 (1.26 M P2 DoFs, ν 0.45, contact) on 2
  // ranks, 135 inner ML-CG iterations over 21 P1 solves against Uncoupled's 323 over 23 (one
  // rank: 133 over 21); on the assembled P2 matrix (CG-AMG) and in the Taylor–Hood block
  // preconditioner at level 1 it gave nothing (96 and 119 iterations against 95 and 115).
  if (aggregate_across_ranks) ml.set("aggregation: type", "MIS");
  amg.initialize(matrix, ml);
}

double default_aggregation_threshold(AmgProlongator prolongator) {
  // Dropping connections weaker than this fraction of the diagonal when aggregating. With plain
  // aggregation, 0.1 gave the fewest CG iterations of 0, 0.02, 0.05, 0.08, 0.1 and 0.2 (P2 level 1
  // of the straight tube: 137, 131, 116, 101, 97, 200); the smoothed prolongator keeps 0.02.
  return prolongator == AmgProlongator::plain ? 0.1 : 0.02;
}

}  // namespace vessel::fem::detail
