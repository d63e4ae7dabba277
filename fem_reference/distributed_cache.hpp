#pragma once
/// A reference solved on the MPI ranks and kept in the FEM solution cache as a serial solve would
/// keep it: the same key, the same payload (the result and the DoF values in the serial
/// ElasticitySolver's numbering), so that a serial program later restores it instead of solving.
/// Collective over MPI_COMM_WORLD. Plain data only (no deal.II, no mpi.h).
#include "fem_reference/distributed_elasticity.hpp"
#include "fem_reference/solution_cache.hpp"

namespace vessel::fem {

struct CacheFill {
  bool was_cached = false;  ///< found in the cache: nothing solved
  /// When solved (every rank): the distributed result without its gathered vectors.
  ElasticityResult fem;
  int n_ranks = 1;
  double seconds = 0.0;  ///< wall clock of the solve, gathering and storing
};

/// Rank 0 looks (mesh, problem) up in `cache` (only rank 0's is used; the others pass nullptr);
/// if it is missing, every rank solves it with solve_elasticity_distributed and rank 0 stores the
/// solution. Only rank 0's mesh and problem are read (as by solve_elasticity_distributed: the
/// other ranks may pass an empty mesh and a default problem). InputError (on every rank)
/// when the problem cannot be keyed or rank 0 has no enabled cache: a reference job that stores
/// nothing would be wasted.
CacheFill fill_solution_cache(SolutionCache* cache, const TetMesh& mesh,
                              const ElasticityProblem& problem);

}  // namespace vessel::fem
