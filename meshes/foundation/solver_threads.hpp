#pragma once
/// The program's own threading of the sparse direct solvers (CHOLMOD and UMFPACK with OpenBLAS),
/// shared by the FEM reference and the mass-spring solvers: the program's choice, not the user's
/// environment.
namespace vessel {

/// Threads a CHOLMOD (or UMFPACK) factorisation or solve may use; the program's choice, not the user's
/// environment. Default 1: the harness runs cases side by side on separate cores, and on 2 cores
/// Debian's CHOLMOD (SuiteSparse 5.12) with its compiled-in 4 OpenMP threads
/// (CHOLMOD_OMP_NUM_THREADS in cholmod_core.h, which ignores OMP_NUM_THREADS) spent a third of an
/// implicit step in futex waits (issue 13). What is set, at every factorisation and solve:
/// - OpenMP (CHOLMOD's parallel regions): n = 1 allows no active parallel region
///   (omp_set_max_active_levels(0)); n > 1 allows one level of n threads (omp_set_num_threads),
///   but SuiteSparse 5.12 has no run-time thread count (cholmod_common's nthreads_max arrived in
///   CHOLMOD 4 / SuiteSparse 6), so its regions then take their compiled-in 4 threads.
/// - OpenBLAS (the supernodal factorisation's dense kernels): openblas_set_num_threads(n).
/// Both entry points are looked up in the loaded libraries at run time; a BLAS or OpenMP runtime
/// without them is left as it is. The setting is process-wide (OpenBLAS's thread count is).
void set_solver_threads(int n);
/// The current setting of set_solver_threads (1 unless changed).
[[nodiscard]] int solver_threads();
/// Applies the setting on the calling thread; every factorisation and solve calls it first.
void apply_solver_threads();

/// set_solver_threads(n) while it lives; the setting before it restored when it ends, also when
/// the scope is left by an exception.
class ScopedSolverThreads {
 public:
  explicit ScopedSolverThreads(int n) : saved_(solver_threads()) { set_solver_threads(n); }
  ~ScopedSolverThreads() { set_solver_threads(saved_); }
  ScopedSolverThreads(const ScopedSolverThreads&) = delete;
  ScopedSolverThreads& operator=(const ScopedSolverThreads&) = delete;

 private:
  int saved_;
};

}  // namespace vessel
