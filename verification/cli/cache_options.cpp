#include "verification/cli/cache_options.hpp"

#include "meshes/mesh_cache.hpp"

namespace vessel::cli {

std::filesystem::path CacheOptions::mesh_dir() const {
  return no_cache ? std::filesystem::path() : cache_dir;
}

std::unique_ptr<fem::SolutionCache> CacheOptions::solution_cache(std::ostream& log) const {
  return std::make_unique<fem::SolutionCache>(
      no_cache ? std::filesystem::path() : cache_dir / "fem-solutions", &log);
}

std::filesystem::path outcome_cache_dir(const std::filesystem::path& cache_dir) {
  return cache_dir / "model-outcomes";
}

std::unique_ptr<OutcomeCache> CacheOptions::outcome_cache(std::ostream& log) const {
  return std::make_unique<OutcomeCache>(
      no_cache ? std::filesystem::path() : outcome_cache_dir(cache_dir), retime, &log);
}

void add_retime_option(CLI::App& cmd, bool& retime) {
  cmd.add_flag("--retime", retime,
               "Measure every model again (and replace its entry in the outcome cache) instead of "
               "taking the outcomes and timings a run of the same executable on this machine "
               "stored");
}

void add_cache_options(CLI::App& cmd, CacheOptions& o) {
  o.cache_dir = default_cache_dir();
  cmd.add_option("--cache-dir", o.cache_dir,
                 "Cache of generated meshes, solved FEM references (<dir>/fem-solutions) and "
                 "measured model outcomes (<dir>/model-outcomes); default $VESSELVERIFY_CACHE_DIR, "
                 "else $XDG_CACHE_HOME/vesselverify, else ~/.cache/vesselverify");
  cmd.add_flag("--no-cache", o.no_cache,
               "Neither read nor write the cache: mesh every vessel, solve every reference and "
               "measure every model");
}

}  // namespace vessel::cli
