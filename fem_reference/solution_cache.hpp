#pragma once
/// FEM solutions (and FEM transients) kept on disk, so that every study (run, recommend, stability,
/// gate) and every repeated run solves each reference once. An entry is keyed by a hash of
/// everything that determines the solution: the mesh (nodes, elements, groups), the problem
/// (material, supports, pins, loads with their quadrature points, curved walls, gravity, solver
/// options) and the version of the reference code (a hash of fem_reference's sources, made at build
/// time). The entries live in the project's checksummed store (meshes/foundation/content_store.hpp):
/// a corrupt or truncated entry is detected, reported and recomputed.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "fem_reference/elasticity.hpp"
#include "fem_reference/hyperelastic.hpp"
#include "meshes/foundation/content_store.hpp"

namespace vessel::fem {

/// The canonical key of (mesh, problem), or nullopt when the problem cannot be keyed: a body
/// force or a prescribed Dirichlet value given as a function. A curved wall's projection is keyed
/// by its images of the midpoints of the wall's triangle edges, the points it moves.
std::optional<std::string> solution_cache_key(const TetMesh& mesh,
                                              const ElasticityProblem& problem);

/// The key of a finite-strain continuation on (mesh, problem): solution_cache_key's plus every
/// hyperelastic option (load stepping, Newton, tolerances, follower pressure, the checkpoints) and
/// `what`, the caller's description of what it keeps of the continuation (e.g. a hash of the
/// points it samples). nullopt when the problem cannot be keyed.
std::optional<std::string> continuation_cache_key(const TetMesh& mesh,
                                                  const ElasticityProblem& problem,
                                                  const HyperelasticOptions& options,
                                                  std::string_view what);

class SolutionCache {
 public:
  /// Entries live in `dir` (created on the first write). An empty path disables the cache:
  /// solve() then always solves. `log` receives a line per corrupt entry (nullptr: std::cerr).
  /// `name` starts those lines and summary() (another store built on these entries, such as the
  /// harness's model outcomes, names itself).
  explicit SolutionCache(std::filesystem::path dir, std::ostream* log = nullptr,
                         std::string name = "FEM solution cache");

  /// solver.solve(), or the stored solution of the same mesh and problem restored into `solver`.
  /// The mesh and problem must be those `solver` was built from.
  const ElasticityResult& solve(ElasticitySolver& solver, const TetMesh& mesh,
                                const ElasticityProblem& problem);

  /// Whether a readable entry of (mesh, problem) is stored (false when the cache is off or the
  /// problem cannot be keyed). A found entry counts as a hit.
  bool contains(const TetMesh& mesh, const ElasticityProblem& problem);

  /// Stores `result` and `dofs` (in the numbering of ElasticitySolver(mesh, problem)) as the
  /// solution of (mesh, problem), replacing any entry: what a solve elsewhere (the distributed
  /// solver's reference job) leaves for solve() to restore. Nothing when off or unkeyable.
  void store(const TetMesh& mesh, const ElasticityProblem& problem, const ElasticityResult& result,
             const std::vector<double>& dofs);

  /// solver.transient(options), or the stored history of the same mesh, problem and options.
  TransientResult transient(const ElasticitySolver& solver, const TetMesh& mesh,
                            const ElasticityProblem& problem, const TransientOptions& options);

  /// A payload of the caller's own (e.g. what a finite-strain continuation gave at its
  /// checkpoints) under `key` (from continuation_cache_key): ContentStore::payload.
  std::string payload(const std::string& key, const std::function<std::string()>& compute,
                      const std::function<double(std::string_view)>& original_seconds,
                      bool refresh = false) {
    return store_.payload(key, compute, original_seconds, refresh);
  }

  [[nodiscard]] bool enabled() const { return store_.enabled(); }
  [[nodiscard]] const std::filesystem::path& directory() const { return store_.directory(); }
  [[nodiscard]] ContentStoreStatistics statistics() const { return store_.statistics(); }
  /// One line: "<name> (DIR): H hits, M misses, C corrupt entries recomputed, S s saved".
  [[nodiscard]] std::string summary() const { return store_.summary(); }

 private:
  /// The problem's key, or nullopt (counted as uncacheable when the cache is on).
  std::optional<std::string> key_or_count(const TetMesh& mesh, const ElasticityProblem& problem);

  ContentStore store_;
};

/// cache->solve(solver, mesh, problem), or solver.solve() without a cache.
const ElasticityResult& solve_with(SolutionCache* cache, ElasticitySolver& solver,
                                   const TetMesh& mesh, const ElasticityProblem& problem);

}  // namespace vessel::fem
