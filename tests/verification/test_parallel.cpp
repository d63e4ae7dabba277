// parallel_for: every index runs exactly once on the threads asked for, and a failing task's
// exception reaches the caller after the other tasks have run.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "meshes/foundation/solver_threads.hpp"
#include "verification/harness/parallel.hpp"

using namespace vessel;

TEST(ParallelFor, EveryIndexRunsExactlyOnce) {
  for (const int jobs : {1, 2, 5}) {
    for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{3}, std::size_t{100}}) {
      std::vector<std::atomic<int>> runs(n);
      parallel_for(n, jobs, [&](std::size_t i) { ++runs[i]; });
      for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(runs[i].load(), 1) << jobs << " " << i;
    }
  }
}

TEST(ParallelFor, UsesAsManyThreadsAsJobsAndOneWithOneJob) {
  std::mutex m;
  std::set<std::thread::id> ids;
  std::atomic<int> waiting{0};
  // Each of the first two tasks waits until both have started: only two threads can finish it.
  parallel_for(2, 2, [&](std::size_t) {
    {
      const std::lock_guard lock(m);
      ids.insert(std::this_thread::get_id());
    }
    ++waiting;
    while (waiting.load() < 2) std::this_thread::yield();
  });
  EXPECT_EQ(ids.size(), 2u);
  ids.clear();
  parallel_for(10, 1, [&](std::size_t) { ids.insert(std::this_thread::get_id()); });
  EXPECT_EQ(ids, std::set<std::thread::id>{std::this_thread::get_id()});
}

TEST(ParallelFor, TheFirstFailureIsRethrownAfterTheOthersRan) {
  std::atomic<int> ran{0};
  EXPECT_THROW(parallel_for(20, 2,
                            [&](std::size_t i) {
                              ++ran;
                              if (i == 3) throw std::runtime_error("task 3 failed");
                            }),
               std::runtime_error);
  EXPECT_EQ(ran.load(), 20);
}

// parallel_solves shares the cores among the solves running or waiting: two side by side on two
// cores get one thread each, and the one left running gets both once the other has ended; the
// process's setting is restored afterwards.
TEST(ParallelSolves, TheCoresAreSharedAndALoneTaskGetsThemAll) {
  set_solver_threads(1);
  std::atomic<int> started{0};
  std::vector<int> side_by_side(2);
  int alone = 0;
  parallel_solves(
      2, 2,
      [&](std::size_t i) {
        ++started;
        while (started < 2) std::this_thread::yield();  // both are running
        side_by_side[i] = solver_threads();
        if (i == 0) return;
        // Task 1 waits (at most 10 s) for task 0 to be counted out.
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
        while (solver_threads() != 2 && std::chrono::steady_clock::now() < deadline) {
          std::this_thread::yield();
        }
        alone = solver_threads();
      },
      2);
  EXPECT_EQ(side_by_side, (std::vector<int>{1, 1}));
  EXPECT_EQ(alone, 2);
  EXPECT_EQ(solver_threads(), 1);
}

TEST(ParallelSolves, OneTaskAtATimeGetsEveryCore) {
  set_solver_threads(1);
  std::vector<int> seen;
  parallel_solves(3, 1, [&](std::size_t) { seen.push_back(solver_threads()); }, 4);
  EXPECT_EQ(seen, (std::vector<int>{4, 4, 4}));
  EXPECT_EQ(solver_threads_per_task(2, 3), 1);  // never below one thread
  EXPECT_EQ(solver_threads(), 1);
}

// A task that throws: the error reaches the caller and the process's setting is restored.
TEST(ParallelSolves, TheSettingIsRestoredWhenATaskThrows) {
  set_solver_threads(1);
  EXPECT_THROW(parallel_solves(
                   2, 1, [](std::size_t) { throw std::runtime_error("a failed solve"); }, 4),
               std::runtime_error);
  EXPECT_EQ(solver_threads(), 1);
}
