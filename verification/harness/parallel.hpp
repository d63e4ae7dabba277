#pragma once
/// Independent work items on several threads (the harness's references, the stability study's
/// rows): untimed work only, because what runs beside a measurement distorts it.
#include <cstddef>
#include <functional>

namespace vessel {

/// Runs task(i) for every i in [0, n) on `jobs` threads (the calling thread one of them), each
/// taking the next unstarted index. Rethrows the first exception once every thread has stopped;
/// the other tasks still run.
void parallel_for(std::size_t n, int jobs, const std::function<void(std::size_t)>& task);

/// parallel_for for tasks that are sparse direct solves: the cores are shared among the tasks that
/// are running or still waiting (at most `jobs`), so each factorisation gets cores / that many
/// threads (set_solver_threads), and a task left running alone gets every core. The process's
/// setting is restored afterwards. `cores` defaults to the machine's core count.
void parallel_solves(std::size_t n, int jobs, const std::function<void(std::size_t)>& task,
                     int cores = 0);

/// The machine's cores (std::thread::hardware_concurrency, at least 1).
[[nodiscard]] int machine_cores();

/// The threads each of `running` concurrent solves gets on `cores` cores (at least 1).
[[nodiscard]] int solver_threads_per_task(int cores, std::size_t running);

}  // namespace vessel
