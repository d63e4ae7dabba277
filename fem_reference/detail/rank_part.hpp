#pragma once
/// Private to fem_reference: the part of the mesh and of the problem one MPI rank of the
/// distributed solver holds. Rank 0 alone holds the whole TetMesh; after METIS has partitioned it,
/// rank 0 cuts out each rank's tets (its own and the ghost layer: every tet sharing a node with
/// one of its own), the loads and supports on them and the evaluation points whose tet it owns,
/// and sends them. Free of deal.II.
#include <mpi.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "fem_reference/distributed_elasticity.hpp"

namespace vessel::fem::detail {

struct RankPart {
  /// This rank's tets (owned and ghosts), their nodes, the boundary triangles among their
  /// faces and every group of the whole mesh (name, dimension, tag) with the elements restricted
  /// to these tets and triangles (possibly none). Local numbering throughout.
  TetMesh mesh;
  std::vector<int> global_tet;   ///< per local tet: its index in the whole mesh (ascending)
  std::vector<int> global_node;  ///< per local node: its index in the whole mesh
  /// Rank 0's problem on this part: patch points on the local triangles only, point constraints
  /// on local nodes only (at the node's exact position), the functions (Dirichlet values, body
  /// force) taken from this rank's own problem.
  ElasticityProblem problem;
  bool mixed = false;
  /// The evaluation points this rank evaluates (the owner of each point's tet).
  struct Point {
    std::int64_t index = 0;  ///< in DistributedOptions::evaluation_points
    int tet = 0;             ///< local tet
    Vec3 x = Vec3::Zero();
  };
  std::vector<Point> points;
  std::size_t n_points = 0;      ///< evaluation points in all
  std::size_t n_nodes = 0;       ///< nodes of the whole mesh
  std::size_t n_tets = 0;        ///< tets of the whole mesh
  Vec3 centroid = Vec3::Zero();  ///< of the whole mesh's nodes: AMG's rotation centre
  bool serial_dofs = false;      ///< DistributedOptions::serial_dofs (rank 0's)
};

/// Collective over `comm`: rank 0 runs `work`; if it throws, rank 0 rethrows its exception and
/// every other rank throws InputError with the same message, so that no rank is left waiting.
void run_on_root(MPI_Comm comm, const std::function<void()>& work);

/// Collective over `comm`. Rank 0 passes the whole mesh, its problem (validated), `owner` (per
/// tet, the rank that owns it: METIS's partition) and the options; it resolves the point
/// constraints to mesh nodes and locates the evaluation points in the whole mesh (InputError on
/// every rank naming the first one off the mesh), then sends each rank its part and keeps its
/// own. The other ranks' mesh and owner are not read; their `own` problem supplies the functions
/// (std::logic_error on every rank if rank 0's problem has a function a rank's lacks).
RankPart distribute_parts(const TetMesh& mesh, const ElasticityProblem& own,
                          const std::vector<unsigned>& owner, const DistributedOptions& options,
                          bool mixed, MPI_Comm comm);

}  // namespace vessel::fem::detail
