#pragma once
/// A reference job: the scenes' static references solved over the MPI ranks into the FEM
/// solution cache (`mpirun -np N vesselverify reference SCENES`), so that a serial `run`, `gate`
/// or `recommend` on the same cache restores them instead of solving. The entries are those a
/// serial run writes (same keys, same payloads), so the serial run's results are the same files.
#include <ostream>
#include <vector>

#include "verification/harness/options.hpp"
#include "verification/scene.hpp"

namespace vessel {

struct ReferenceJobSummary {
  int solved = 0;  ///< solved on the ranks and stored
  int cached = 0;  ///< already in the cache
};

/// Collective over MPI_COMM_WORLD (a fem::MpiSession must exist): every rank calls it with the
/// same scenes. Rank 0 (`root`) alone reads or generates the meshes (mesh cache o.cache_dir) and
/// makes the problems (the solver sends each other rank its cells and their loads), owns
/// o.solution_cache (the other ranks' is ignored) and prints to `log`.
/// For each scene and ν, the solves of reference_solves (fine level, the level below, the one
/// below that) are looked up and, when missing, solved distributed and stored. InputError (every
/// rank) without a solution cache; an exception on any solve ends the job on every rank.
ReferenceJobSummary solve_references_into_cache(const std::vector<Scene>& scenes,
                                                const HarnessOptions& o, bool root,
                                                std::ostream& log);

}  // namespace vessel
