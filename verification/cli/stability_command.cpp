/// `vesselverify stability`: predicted vs found critical time steps of the explicit integrators
/// and the hard cases of issue 6; writes stability.json and stability.md.
#include <filesystem>
#include <fstream>
#include <iostream>

#include "meshes/foundation/errors.hpp"
#include "meshes/mesh_cache.hpp"
#include "verification/cli/cache_options.hpp"
#include "verification/cli/commands.hpp"
#include "verification/cli/jobs_option.hpp"
#include "verification/studies/stability/stability.hpp"

namespace vessel::cli {

namespace fs = std::filesystem;

namespace {

struct StabilityCli {
  bool quick = false;
  fs::path output_dir = "results";
  fs::path cache_dir = default_cache_dir();
  bool no_cache = false;
  bool retime = false;
  int trial_steps = 0;
  long long long_run_steps = 0;
  int max_level = -1;
  bool no_hard_cases = false;
  bool no_rod_steps = false;
  bool no_tet_steps = false;
  int tet_max_level = 0;
  std::vector<std::string> only_cases;
  int jobs = 1;
};

/// Fails early (before minutes of work) when the output directory cannot be written: creates it
/// if missing and creates and removes a probe file in it.
void require_writable_dir(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw InputError("--output-dir " + dir.string() + ": cannot create the directory (" +
                     (ec ? ec.message() : "not a directory") + "); expected a writable directory");
  }
  const fs::path probe = dir / ".vesselverify-write-probe";
  {
    std::ofstream out(probe);
    if (!out) {
      throw InputError("--output-dir " + dir.string() +
                       ": cannot write into the directory; expected a writable directory");
    }
  }
  fs::remove(probe, ec);
}

}  // namespace

void add_stability_command(CLI::App& app, const std::string& command_line) {
  auto o = std::make_shared<StabilityCli>();
  CLI::App* cmd = app.add_subcommand(
      "stability",
      "Numerical stability: critical time step of each explicit integrator predicted from the "
      "largest eigenvalue of M^-1 K (Lanczos) vs found by bisection on dt, per model, "
      "integrator and mesh level, and the hard cases (nu -> 0.5, E from 1 kPa to 1 MPa, sliver "
      "tets, a refined contact patch, an inverting load, a long run, a tight arch bend, "
      "zero-length springs). Writes stability.json and stability.md (times in s, lengths in mm "
      "in the text).\n"
      "Examples:\n  vesselverify stability --quick --output-dir results\n"
      "  vesselverify stability            # levels 0..2 and a 10^6-step long run");
  cmd->add_flag("--quick", o->quick,
                "Levels 0..1, 500 steps per trial, a 2e4-step long run (a few minutes)");
  cmd->add_option("--output-dir", o->output_dir, "Where stability.json and stability.md go")
      ->capture_default_str();
  cmd->add_option("--cache-dir", o->cache_dir,
                  "Cache directory: meshes, and the measured rows and hard cases "
                  "(<dir>/model-outcomes); default $VESSELVERIFY_CACHE_DIR, else "
                  "$XDG_CACHE_HOME/vesselverify, else ~/.cache/vesselverify");
  cmd->add_flag("--no-cache", o->no_cache,
                "Do not read or write the cache (meshes, and the rows and hard cases measured "
                "before)");
  add_retime_option(*cmd, o->retime);
  cmd->add_option("--trial-steps", o->trial_steps,
                  "Steps per stability trial (default 500 quick, 1000 full)");
  cmd->add_option("--long-run-steps", o->long_run_steps,
                  "Steps of the long run (default 2e4 quick, 1e6 full)");
  cmd->add_option("--max-level", o->max_level, "Highest mesh level of the step table");
  add_jobs_option(*cmd, o->jobs,
                  "Rows of the critical-step table computed at a time, one (level, model) per "
                  "thread, and hard cases (default: the core count); the long run, whose steps are "
                  "timed, runs alone");
  cmd->add_flag("--no-hard-cases", o->no_hard_cases, "Only the critical-step table");
  cmd->add_flag("--no-rod-steps", o->no_rod_steps,
                "Leave out the guidewire's critical steps (a metal wire at 50 and 200 segments: "
                "about a minute)");
  cmd->add_flag("--no-tet-steps", o->no_tet_steps,
                "Leave out corotational P1's and XPBD FEM's critical steps (explicit, implicit "
                "Euler under a 70 mN load, XPBD)");
  cmd->add_option("--tet-max-level", o->tet_max_level,
                  "Highest mesh level of corotational P1's and XPBD FEM's rows (at most "
                  "--max-level)")
      ->capture_default_str();
  cmd->add_option("--hard-case", o->only_cases,
                  "Run only this hard case (repeatable): poisson, youngs_modulus, sliver, "
                  "refined_patch, inverting_load, long_run, tight_bend, zero_length");
  cmd->callback([o, command_line] {
    if (o->trial_steps < 0) {
      throw InputError("--trial-steps: expected ≥ 1, got " + std::to_string(o->trial_steps));
    }
    if (o->long_run_steps < 0 || o->long_run_steps > 2'000'000'000LL) {
      throw InputError("--long-run-steps: expected 1..2e9, got " +
                       std::to_string(o->long_run_steps));
    }
    require_writable_dir(o->output_dir);
    StabilityOptions so;
    so.quick = o->quick;
    so.cache_dir = o->no_cache ? fs::path() : o->cache_dir;
    so.log = &std::cout;
    so.command_line = command_line;
    so.trial_steps = o->trial_steps;
    so.long_run_steps = o->long_run_steps;
    so.max_level = o->max_level;
    so.hard_cases = !o->no_hard_cases;
    so.rod_steps = !o->no_rod_steps;
    so.tet_steps = !o->no_tet_steps;
    if (o->tet_max_level < 0) {
      throw InputError("--tet-max-level: expected ≥ 0, got " + std::to_string(o->tet_max_level));
    }
    so.tet_max_level = o->tet_max_level;
    so.only_cases = o->only_cases;
    so.jobs = o->jobs;
    OutcomeCache outcomes(o->no_cache ? fs::path() : outcome_cache_dir(o->cache_dir), o->retime,
                          &std::cout);
    so.outcome_cache = &outcomes;
    const StabilityReport report = run_stability(so);
    std::cout << outcomes.summary() << "\n";
    write_stability(o->output_dir, report);
    std::cout << "wrote " << (o->output_dir / "stability.json").string() << " and stability.md\n";
  });
}

}  // namespace vessel::cli
