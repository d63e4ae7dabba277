#include "fem_reference/distributed_cache.hpp"

#include <mpi.h>

#include <chrono>

#include "meshes/foundation/errors.hpp"

namespace vessel::fem {

CacheFill fill_solution_cache(SolutionCache* cache, const TetMesh& mesh,
                              const ElasticityProblem& problem) {
  const auto t0 = std::chrono::steady_clock::now();
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  // 0: solve, 1: cached, 2: no cache on rank 0, 3: not keyable (the same answer on every rank).
  int state = 0;
  if (rank == 0) {
    if (!cache || !cache->enabled()) {
      state = 2;
    } else if (!solution_cache_key(mesh, problem)) {
      state = 3;
    } else if (cache->contains(mesh, problem)) {
      state = 1;
    }
  }
  MPI_Bcast(&state, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (state == 2) throw InputError("a reference job needs the FEM solution cache: drop --no-cache");
  if (state == 3) {
    throw InputError("this reference cannot be cached (a load or support given as a function): "
                     "solve it in the serial run");
  }
  CacheFill out;
  if (state == 1) {
    out.was_cached = true;
    return out;
  }
  DistributedOptions options;
  options.serial_dofs = true;
  DistributedResult d = solve_elasticity_distributed(mesh, problem, options);
  if (rank == 0) cache->store(mesh, problem, d.fem, d.serial_dofs);
  out.fem = std::move(d.fem);
  out.fem.nodal_displacement.clear();
  out.n_ranks = d.n_ranks;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace vessel::fem
