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

}  // namespace vessel
