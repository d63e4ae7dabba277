#include "verification/harness/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "meshes/foundation/solver_threads.hpp"

namespace vessel {

void parallel_for(std::size_t n, int jobs, const std::function<void(std::size_t)>& task) {
  std::atomic<std::size_t> next{0};
  std::mutex failure_mutex;
  std::exception_ptr failure;
  auto worker = [&] {
    for (std::size_t i = next++; i < n; i = next++) {
      try {
        task(i);
      } catch (...) {
        const std::lock_guard lock(failure_mutex);
        if (!failure) failure = std::current_exception();
      }
    }
  };
  std::vector<std::thread> threads;
  const auto extra = static_cast<std::size_t>(std::max(0, jobs - 1));
  for (std::size_t t = 0; t < std::min(extra, n); ++t) threads.emplace_back(worker);
  worker();
  for (std::thread& t : threads) t.join();
  if (failure) std::rethrow_exception(failure);
}

int machine_cores() { return static_cast<int>(std::max(1U, std::thread::hardware_concurrency())); }

int solver_threads_per_task(int cores, std::size_t running) {
  return std::max(1, cores / static_cast<int>(std::max<std::size_t>(1, running)));
}

void parallel_solves(std::size_t n, int jobs, const std::function<void(std::size_t)>& task,
                     int cores) {
  if (cores <= 0) cores = machine_cores();
  const auto width = static_cast<std::size_t>(std::max(1, jobs));
  const ScopedSolverThreads restore_at_end(solver_threads());
  std::mutex share_mutex;
  std::size_t unfinished = n;
  // The tasks running or waiting share the cores: set before the first and as each one ends.
  auto share = [&] {
    set_solver_threads(solver_threads_per_task(cores, std::min(width, unfinished)));
  };
  share();
  parallel_for(n, jobs, [&](std::size_t i) {
    struct AtEnd {  // counts the task out, also when it throws
      std::function<void()> run;
      ~AtEnd() { run(); }
    } const count_out{[&] {
      const std::lock_guard lock(share_mutex);
      --unfinished;
      share();
    }};
    task(i);
  });
}

}  // namespace vessel
