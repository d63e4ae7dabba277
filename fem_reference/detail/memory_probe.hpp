#pragma once
/// Private to fem_reference: this process's memory (Linux /proc/self/status), for the distributed
/// solver's per-rank figures and its per-phase report. Free of deal.II.
#include <cstddef>

namespace vessel::fem::detail {

/// Resident set size now (VmRSS) and its peak so far (VmHWM), bytes; 0 where /proc is missing.
struct MemoryUse {
  std::size_t resident = 0;
  std::size_t peak = 0;
};
MemoryUse memory_use();

/// With the environment variable VESSELVERIFY_MEMORY set (to anything), prints one line
/// "memory: rank R, <phase>: resident X MB, peak Y MB" to stderr; else nothing.
void report_memory(int rank, const char* phase);

/// Gives the heap's free pages back to the system (glibc's malloc_trim), so that what a phase
/// freed is not counted in the next phases' resident set.
void release_free_memory();

}  // namespace vessel::fem::detail
