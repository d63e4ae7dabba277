#include "verification/timing.hpp"

#include <algorithm>
#include <stdexcept>

namespace vessel {

double median(std::vector<double> values) {
  if (values.empty()) throw std::invalid_argument("median of an empty sample");
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<long>(mid), values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  const double lower = *std::max_element(values.begin(), values.begin() + static_cast<long>(mid));
  return 0.5 * (lower + upper);
}

TimingSample time_median(const std::function<void()>& fn, int repeats, int warmup) {
  if (repeats < 1) throw std::invalid_argument("time_median: repeats must be ≥ 1");
  for (int i = 0; i < warmup; ++i) fn();
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    Stopwatch w;
    fn();
    t.push_back(w.seconds());
  }
  TimingSample s;
  s.repeats = repeats;
  s.min_s = *std::min_element(t.begin(), t.end());
  s.max_s = *std::max_element(t.begin(), t.end());
  s.median_s = median(t);
  return s;
}

}  // namespace vessel
