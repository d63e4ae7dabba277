#pragma once
/// Wall-clock timing for reports and the gate: medians of repeated runs after a warm-up, so one
/// noisy run on a shared machine does not decide a result.
#include <chrono>
#include <functional>
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

/// Median of a non-empty sample (std::invalid_argument if empty).
double median(std::vector<double> values);

}  // namespace vessel
