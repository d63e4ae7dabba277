#include "verification/harness/memory.hpp"

#include <fstream>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <sstream>
#include <string>

namespace vessel {

namespace {

/// A "Name:   1234 kB" line of /proc/self/status, in MiB.
double status_field_mib(const std::string& name) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(name + ":", 0) != 0) continue;
    std::istringstream fields(line.substr(name.size() + 1));
    double kib = 0.0;
    fields >> kib;
    return kib / 1024.0;
  }
  return 0.0;
}

}  // namespace

double resident_memory_mib() { return status_field_mib("VmRSS"); }
double peak_resident_memory_mib() { return status_field_mib("VmHWM"); }

void reset_peak_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
  std::ofstream out("/proc/self/clear_refs");
  out << "5";  // resets VmHWM to VmRSS (proc(5), "clear_refs")
}

}  // namespace vessel
