#include "verification/cli/jobs_option.hpp"

#include <algorithm>
#include <thread>

namespace vessel::cli {

int default_jobs() { return static_cast<int>(std::max(1U, std::thread::hardware_concurrency())); }

void add_jobs_option(CLI::App& cmd, int& jobs, const std::string& what) {
  jobs = default_jobs();
  cmd.add_option("--jobs,-j", jobs, what)
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
}

}  // namespace vessel::cli
