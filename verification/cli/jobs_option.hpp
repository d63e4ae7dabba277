#pragma once
/// --jobs of the commands that run scenes (run, recommend, gate: FEM references solved at a time)
/// and of the stability study (rows of its critical-step table computed at a time); --threads of
/// the commands that solve one reference at a time; the timing options of the commands that run
/// scenes.
#include <CLI/CLI.hpp>
#include <string>

namespace vessel::cli {

/// The machine's core count (at least 1): the default of --jobs.
[[nodiscard]] int default_jobs();

/// Adds --jobs N (N ≥ 1, default default_jobs()) writing into `jobs`; `what` says what runs N at
/// a time (the help text).
void add_jobs_option(CLI::App& cmd, int& jobs, const std::string& what);

/// Adds --threads N (N ≥ 1, default default_jobs()) writing into `threads`: the solver threads
/// (set_solver_threads) of a command that solves one problem at a time; `what` says which solves
/// get them (the help text, which states the default in words).
void add_threads_option(CLI::App& cmd, int& threads, const std::string& what);

/// Adds the scene-running commands' timing options: --repeats (timed repeats per solve, median)
/// and --updates (the warm-started load ramp whose median is the time per update).
void add_timing_options(CLI::App& cmd, int& repeats, int& updates);

/// The help of the scene-running commands' --jobs.
inline constexpr const char* kReferencesAtATime =
    "FEM references solved at a time, before the models (default: the core count). The models "
    "always run one at a time: their times are measurements";

}  // namespace vessel::cli
