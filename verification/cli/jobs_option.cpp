#include "verification/cli/jobs_option.hpp"

#include "verification/harness/parallel.hpp"

namespace vessel::cli {

int default_jobs() { return machine_cores(); }

void add_jobs_option(CLI::App& cmd, int& jobs, const std::string& what) {
  jobs = default_jobs();
  // The default is this machine's core count, which each `what` states in words: printing the
  // number would make the help (and the command reference generated from it) machine-dependent.
  cmd.add_option("--jobs,-j", jobs, what)->check(CLI::Range(1, 1024));
}

void add_threads_option(CLI::App& cmd, int& threads, const std::string& what) {
  threads = default_jobs();  // stated in words in `what`, as --jobs
  cmd.add_option("--threads", threads, what)->check(CLI::Range(1, 1024));
}

void add_timing_options(CLI::App& cmd, int& repeats, int& updates) {
  cmd.add_option("--repeats", repeats, "Timed repeats per model solve (median reported)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd.add_option("--updates", updates,
                 "Static and linear mass-spring models: timed as a simulator runs them, set-up "
                 "(assembly, factorisation at rest) apart, then this many warm-started updates "
                 "ramping the load to each case's magnitude; the time per update is their median")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
}

}  // namespace vessel::cli
