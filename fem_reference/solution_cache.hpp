#pragma once
/// FEM solutions (and FEM transients) kept on disk, so that every study (run, recommend, stability,
/// gate) and every repeated run solves each reference once. An entry is keyed by a hash of
/// everything that determines the solution: the mesh (nodes, elements, groups), the problem
/// (material, supports, pins, loads with their quadrature points, curved walls, gravity, solver
/// options) and the version of the reference code (a hash of fem_reference's sources, made at build
/// time). Each file stores its full key and a checksum of its contents: a corrupt or truncated
/// entry is detected, reported and recomputed. Entries are written atomically (write, then rename),
/// so concurrent writers never leave a partial file.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>

#include "fem_reference/elasticity.hpp"
#include "fem_reference/hyperelastic.hpp"

namespace vessel::fem {

/// What a cache did over its life.
struct SolutionCacheStatistics {
  int hits = 0;
  int misses = 0;   ///< solved and stored (including the corrupt entries below)
  int corrupt = 0;  ///< entries found unreadable or failing their checksum, recomputed
  int uncacheable =
      0;  ///< problems with a load or support given as a function (solved, not stored)
  double seconds_saved = 0.0;  ///< the hits' original assembly + solve time, less their reading
};

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

  /// solver.transient(options), or the stored history of the same mesh, problem and options.
  TransientResult transient(const ElasticitySolver& solver, const TetMesh& mesh,
                            const ElasticityProblem& problem, const TransientOptions& options);

  /// A payload of the caller's own (e.g. what a finite-strain continuation gave at its
  /// checkpoints) under `key` (from continuation_cache_key): the stored one when `original_seconds`
  /// accepts it (it returns the seconds computing it took, and throws std::exception for a
  /// payload it cannot read, which is then recomputed as a corrupt entry), else compute()'s,
  /// stored. With the cache disabled, compute()'s. `refresh`: compute and replace the entry
  /// without reading it (counted as a miss).
  std::string payload(const std::string& key, const std::function<std::string()>& compute,
                      const std::function<double(std::string_view)>& original_seconds,
                      bool refresh = false);

  [[nodiscard]] bool enabled() const { return !dir_.empty(); }
  [[nodiscard]] const std::filesystem::path& directory() const { return dir_; }
  [[nodiscard]] SolutionCacheStatistics statistics() const;
  /// One line: "<name> (DIR): H hits, M misses, C corrupt entries recomputed, S s
  /// saved".
  [[nodiscard]] std::string summary() const;

 private:
  /// The problem's key, or nullopt (counted as uncacheable when the cache is on).
  std::optional<std::string> key_or_count(const TetMesh& mesh, const ElasticityProblem& problem);
  /// The entry for `key`: `use(payload)` restores a good one and returns the seconds its
  /// computation took; otherwise `compute()` computes and returns the payload, which is stored.
  void lookup(const std::string& key, const std::function<double(std::string_view)>& use,
              const std::function<std::string()>& compute, bool refresh = false);

  std::filesystem::path dir_;
  std::ostream* log_;
  std::string name_;
  mutable std::mutex mutex_;  // statistics only: entries are files written atomically
  SolutionCacheStatistics stats_;
};

/// cache->solve(solver, mesh, problem), or solver.solve() without a cache.
const ElasticityResult& solve_with(SolutionCache* cache, ElasticitySolver& solver,
                                   const TetMesh& mesh, const ElasticityProblem& problem);

}  // namespace vessel::fem
