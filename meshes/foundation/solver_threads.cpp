#include "meshes/foundation/solver_threads.hpp"

#include <dlfcn.h>

#include <atomic>
#include <string>

#include "meshes/foundation/errors.hpp"

namespace vessel {

namespace {

/// The threading entry points of the OpenMP runtime (libgomp, loaded by CHOLMOD) and of OpenBLAS,
/// found in the process's loaded libraries; null where absent (e.g. the reference BLAS).
struct ThreadingEntryPoints {
  void (*omp_set_max_active_levels)(int) = nullptr;
  void (*omp_set_num_threads)(int) = nullptr;
  void (*openblas_set_num_threads)(int) = nullptr;
};

const ThreadingEntryPoints& threading_entry_points() {
  static const ThreadingEntryPoints e = [] {
    ThreadingEntryPoints r;
    r.omp_set_max_active_levels =
        reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"));
    r.omp_set_num_threads =
        reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "omp_set_num_threads"));
    r.openblas_set_num_threads =
        reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    return r;
  }();
  return e;
}

std::atomic<int> g_solver_threads{1};
std::atomic<int> g_openblas_threads{0};  // what OpenBLAS was last given; 0: not yet

}  // namespace

/// Applies the setting before CHOLMOD runs, on the calling thread: OpenMP's nthreads-var and
/// max-active-levels-var belong to the calling thread's data environment (OpenMP 5.0, ICV
/// scopes), so they are set every time; OpenBLAS's count is process-wide and set only when it
/// changes.
void apply_solver_threads() {
  const ThreadingEntryPoints& e = threading_entry_points();
  const int n = g_solver_threads.load(std::memory_order_relaxed);
  if (e.omp_set_max_active_levels) e.omp_set_max_active_levels(n == 1 ? 0 : 1);
  if (e.omp_set_num_threads) e.omp_set_num_threads(n);
  if (e.openblas_set_num_threads && g_openblas_threads.exchange(n) != n) {
    e.openblas_set_num_threads(n);
  }
}

void set_solver_threads(int n) {
  if (n < 1) {
    throw InputError("solver threads: expected >= 1, got " + std::to_string(n));
  }
  g_solver_threads.store(n);
}

int solver_threads() { return g_solver_threads.load(); }

}  // namespace vessel
