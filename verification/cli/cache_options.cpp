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

void add_cache_options(CLI::App& cmd, CacheOptions& o) {
  o.cache_dir = default_cache_dir();
  cmd.add_option("--cache-dir", o.cache_dir,
                 "Cache of generated meshes and solved FEM references (<dir>/fem-solutions); "
                 "env VESSELVERIFY_CACHE_DIR")
      ->capture_default_str();
  cmd.add_flag("--no-cache", o.no_cache,
               "Neither read nor write the cache: mesh every vessel and solve every reference");
}

}  // namespace vessel::cli
