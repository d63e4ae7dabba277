#include "verification/metrics.hpp"

#include <cmath>
#include <stdexcept>

namespace vessel {

ErrorStatistics compare_displacements(const std::vector<Vec3>& model,
                                      const std::vector<Vec3>& reference) {
  if (model.size() != reference.size() || model.empty()) {
    throw std::invalid_argument("compare_displacements: " + std::to_string(model.size()) +
                                " model values vs " + std::to_string(reference.size()) +
                                " reference values; expected the same non-zero count");
  }
  ErrorStatistics s;
  s.points = model.size();
  const auto n = static_cast<double>(model.size());
  double sum = 0.0;
  double sum_sq = 0.0;
  double ref_sq = 0.0;
  for (std::size_t i = 0; i < model.size(); ++i) {
    const double e = (model[i] - reference[i]).norm();
    s.max_mm = std::max(s.max_mm, e);
    sum += e;
    sum_sq += e * e;
    ref_sq += reference[i].squaredNorm();
  }
  const double mean = sum / n;
  constexpr double kMm = 1e3;
  s.max_mm *= kMm;
  s.mean_mm = mean * kMm;
  s.rms_mm = std::sqrt(sum_sq / n) * kMm;
  s.stddev_mm = std::sqrt(std::max(0.0, sum_sq / n - mean * mean)) * kMm;
  s.relative_l2 = ref_sq > 0.0 ? std::sqrt(sum_sq / ref_sq) : 0.0;
  return s;
}

}  // namespace vessel
