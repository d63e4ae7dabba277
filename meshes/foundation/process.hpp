#pragma once
/// Running another program: its own process group, a time-out, its output appended to a log. The
/// suite runs a user's own simulator (verification/harness/external_model.hpp) and a user's own
/// wire model (verification/guidewire/wire_exchange.hpp) this way.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace vessel {

/// How a process ended.
struct ProcessResult {
  int exit_code = -1;   ///< the exit status (−1 if killed by a signal)
  int signal = 0;       ///< the signal that ended it, 0 if none
  bool timed_out = false;
  double wall_seconds = 0.0;
};

/// Runs argv[0] (looked up on PATH unless it contains a '/', then relative to `working_dir`) with
/// argv in `working_dir`, with the extra environment variables `env`, stdout and stderr appended
/// to `log`; its own process group, killed (SIGKILL to the group) when it runs longer than
/// `timeout_s`; the group is killed after a normal exit too, so nothing it started outlives it. A
/// program that cannot be executed (not found, not executable, no such working directory) gives
/// exit code 127 and says why in the log.
ProcessResult run_process(const std::vector<std::string>& argv,
                          const std::filesystem::path& working_dir,
                          const std::vector<std::pair<std::string, std::string>>& env,
                          double timeout_s, const std::filesystem::path& log);

/// The last `lines` lines of a text file joined by '|' (a failed command's log, for its reason).
std::string log_tail(const std::filesystem::path& path, int lines);

}  // namespace vessel
