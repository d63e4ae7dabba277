#include "fem_reference/detail/memory_probe.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace vessel::fem::detail {

MemoryUse memory_use() {
  MemoryUse m;
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return m;
  char line[256];
  while (std::fgets(line, sizeof line, f)) {
    unsigned long kb = 0;
    if (std::sscanf(line, "VmRSS: %lu kB", &kb) == 1) m.resident = kb * 1024;
    if (std::sscanf(line, "VmHWM: %lu kB", &kb) == 1) m.peak = kb * 1024;
  }
  std::fclose(f);
  return m;
}

void report_memory(int rank, const char* phase) {
  static const bool on = std::getenv("VESSELVERIFY_MEMORY") != nullptr;
  if (!on) return;
  const MemoryUse m = memory_use();
  std::fprintf(stderr, "memory: rank %d, %s: resident %.1f MB, peak %.1f MB\n", rank, phase,
               static_cast<double>(m.resident) / 1e6, static_cast<double>(m.peak) / 1e6);
}

void release_free_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace vessel::fem::detail
