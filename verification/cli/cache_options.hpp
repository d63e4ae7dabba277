#pragma once
/// The cache options of the commands that solve FEM references (run, recommend, gate): one cache
/// directory for generated meshes and FEM solutions, and --no-cache to bypass both.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <memory>

#include "fem_reference/solution_cache.hpp"

namespace vessel::cli {

struct CacheOptions {
  std::filesystem::path cache_dir;  ///< default_cache_dir() unless --cache-dir
  bool no_cache = false;

  /// Where generated meshes go ("" with --no-cache).
  [[nodiscard]] std::filesystem::path mesh_dir() const;
  /// The FEM solution cache in <cache-dir>/fem-solutions (off with --no-cache), logging to `log`.
  [[nodiscard]] std::unique_ptr<fem::SolutionCache> solution_cache(std::ostream& log) const;
};

/// Adds --cache-dir and --no-cache.
void add_cache_options(CLI::App& cmd, CacheOptions& o);

}  // namespace vessel::cli
