#pragma once
/// Wall-clock timing for reports and the gate: medians of repeated runs after a warm-up, so one
/// noisy run on a shared machine does not decide a result.
#include <chrono>
#include <functional>
#include <string>
#include <vector>

namespace vessel {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  [[nodiscard]] double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  void restart() { start_ = std::chrono::steady_clock::now(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

struct TimingSample {
  double median_s = 0.0;
  double min_s = 0.0;
  double max_s = 0.0;
  int repeats = 0;
};

/// Runs `fn` `warmup` times untimed, then `repeats` times timed (repeats ≥ 1).
TimingSample time_median(const std::function<void()>& fn, int repeats = 5, int warmup = 1);

/// Seconds of a fixed computation shaped like the models' work (a sparse Cholesky factorisation
/// and solve of a 3-D Laplacian, and a pass of spring forces over a fixed network), median of 5
/// after a warm-up. The gate divides solve times by it, so baselines recorded on one machine
/// remain comparable on another (Google Benchmark's practice of comparing ratios within one run).
double reference_kernel_seconds();

/// The current time, UTC, as "YYYY-MM-DDTHH:MM:SSZ".
std::string utc_now();

/// Median of a non-empty sample (std::invalid_argument if empty).
double median(std::vector<double> values);

}  // namespace vessel
