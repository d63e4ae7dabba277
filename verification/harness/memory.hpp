#pragma once
/// Resident memory of this process, for the "peak memory" column of the results: Linux's
/// VmRSS / VmHWM from /proc/self/status, with the high-water mark reset through
/// /proc/self/clear_refs ("5", Linux ≥ 4.0) so each model's peak is measured on its own.

namespace vessel {

/// Current resident set size, MiB (0 where /proc is unavailable).
double resident_memory_mib();
/// Peak resident set size since the last reset_peak_memory() (or the start), MiB.
double peak_resident_memory_mib();
/// Resets the peak to the current resident size (no-op where unsupported). Returns the heap's
/// free pages to the system first (glibc's malloc_trim): otherwise a model reusing memory freed
/// by an earlier one would not raise the resident size and its memory would read as zero.
void reset_peak_memory();

/// Peak memory a piece of work added on top of what was resident when it started: construct
/// before, call added_mib() after.
class MemoryProbe {
 public:
  MemoryProbe() {
    reset_peak_memory();
    before_ = resident_memory_mib();
  }
  [[nodiscard]] double added_mib() const {
    const double peak = peak_resident_memory_mib();
    return peak > before_ ? peak - before_ : 0.0;
  }

 private:
  double before_ = 0.0;
};

}  // namespace vessel
