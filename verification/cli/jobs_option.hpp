#pragma once
/// --jobs of the commands that run scenes (run, recommend, gate): how many FEM references are
/// solved at a time.
#include <CLI/CLI.hpp>

namespace vessel::cli {

/// The machine's core count (at least 1): the default of --jobs.
[[nodiscard]] int default_jobs();

/// Adds --jobs N (N ≥ 1, default default_jobs()) writing into `jobs`.
void add_jobs_option(CLI::App& cmd, int& jobs);

}  // namespace vessel::cli
