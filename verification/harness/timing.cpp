#include "verification/harness/timing.hpp"

#include <Eigen/Sparse>
#include <ctime>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
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

double reference_kernel_seconds() {
  constexpr int n = 18;  // 18³ = 5832 unknowns: ~10 ms here
  const auto id = [](int i, int j, int k) { return (i * n + j) * n + k; };
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        entries.emplace_back(id(i, j, k), id(i, j, k), 6.0 + 1e-3);
        if (i + 1 < n) entries.emplace_back(id(i, j, k), id(i + 1, j, k), -1.0);
        if (i > 0) entries.emplace_back(id(i, j, k), id(i - 1, j, k), -1.0);
        if (j + 1 < n) entries.emplace_back(id(i, j, k), id(i, j + 1, k), -1.0);
        if (j > 0) entries.emplace_back(id(i, j, k), id(i, j - 1, k), -1.0);
        if (k + 1 < n) entries.emplace_back(id(i, j, k), id(i, j, k + 1), -1.0);
        if (k > 0) entries.emplace_back(id(i, j, k), id(i, j, k - 1), -1.0);
      }
    }
  }
  Eigen::SparseMatrix<double> a(n * n * n, n * n * n);
  a.setFromTriplets(entries.begin(), entries.end());
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(a.rows());
  // Spring forces on a chain of 200k springs (the mass-spring models' inner loop).
  const int springs = 200000;
  Eigen::VectorXd x(3 * (springs + 1));
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = std::sin(0.1 * static_cast<double>(i));
  volatile double sink = 0.0;
  const TimingSample t = time_median([&] {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(a);
    const Eigen::VectorXd u = ldlt.solve(b);
    Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
    for (int s = 0; s < springs; ++s) {
      const Eigen::Vector3d d = x.segment<3>(3 * (s + 1)) - x.segment<3>(3 * s);
      const double len = d.norm();
      const Eigen::Vector3d force = (len - 1.0) / std::max(len, 1e-12) * d;
      f.segment<3>(3 * s) += force;
      f.segment<3>(3 * (s + 1)) -= force;
    }
    sink = sink + u[0] + f[1];
  });
  return t.median_s;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

}  // namespace vessel
