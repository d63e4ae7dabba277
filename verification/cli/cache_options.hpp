#pragma once
/// The cache options of the commands that solve FEM references (run, recommend, gate): one cache
/// directory for generated meshes and FEM solutions, and --no-cache to bypass both.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <memory>

#include "fem_reference/solution_cache.hpp"
#include "verification/harness/outcome_cache.hpp"

namespace vessel::cli {

struct CacheOptions {
  std::filesystem::path cache_dir;  ///< default_cache_dir() unless --cache-dir
  bool no_cache = false;
  bool retime = false;  ///< measure the models again and replace their cached outcomes

  /// Where generated meshes go ("" with --no-cache).
  [[nodiscard]] std::filesystem::path mesh_dir() const;
  /// The FEM solution cache in <cache-dir>/fem-solutions (off with --no-cache), logging to `log`.
  [[nodiscard]] std::unique_ptr<fem::SolutionCache> solution_cache(std::ostream& log) const;
  /// The measured outcomes' cache in <cache-dir>/model-outcomes (off with --no-cache).
  [[nodiscard]] std::unique_ptr<OutcomeCache> outcome_cache(std::ostream& log) const;
};

/// Adds --cache-dir and --no-cache.
void add_cache_options(CLI::App& cmd, CacheOptions& o);
/// Adds --retime (the commands that keep measured outcomes: run, recommend, stability).
void add_retime_option(CLI::App& cmd, bool& retime);

/// <cache-dir>/model-outcomes, the measured outcomes' folder under a cache directory.
std::filesystem::path outcome_cache_dir(const std::filesystem::path& cache_dir);

}  // namespace vessel::cli
