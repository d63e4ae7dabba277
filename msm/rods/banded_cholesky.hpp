#pragma once
/// Cholesky factorisation of a symmetric positive definite band matrix (lower band stored row by
/// row: entry (i, j), i − b ≤ j ≤ i, at band[i·(b+1) + i − j]); O(n b²) to factorise and O(n b)
/// to solve. The XPBD rod's direct solver uses it on its chain-ordered constraint blocks (Deul,
/// Kugelstadt, Weiler & Bender 2018 solve the same tree-structured system in linear time).
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace vessel::msm::rods {

class BandedCholesky {
 public:
  /// An n × n matrix of half-bandwidth b, all zero.
  void resize(int n, int b) {
    n_ = n;
    b_ = b;
    band_.assign(static_cast<std::size_t>(n) * (b + 1), 0.0);
  }
  void set_zero() { std::fill(band_.begin(), band_.end(), 0.0); }
  [[nodiscard]] int size() const { return n_; }
  /// Adds v to entry (i, j) of the lower triangle (i ≥ j, i − j ≤ b).
  void add(int i, int j, double v) { band_[index(i, j)] += v; }

  /// Overwrites the band with its Cholesky factor L (A = L Lᵀ). Throws std::runtime_error if a
  /// pivot is not positive.
  void factorize() {
    for (int i = 0; i < n_; ++i) {
      const int first = std::max(0, i - b_);
      for (int j = first; j <= i; ++j) {
        double s = band_[index(i, j)];
        for (int k = std::max(first, j - b_); k < j; ++k) s -= band_[index(i, k)] * band_[index(j, k)];
        if (j < i) {
          band_[index(i, j)] = s / band_[index(j, j)];
        } else {
          if (!(s > 0.0)) {
            throw std::runtime_error("BandedCholesky: non-positive pivot at row " + std::to_string(i));
          }
          band_[index(i, i)] = std::sqrt(s);
        }
      }
    }
  }

  /// Solves L Lᵀ x = r in place.
  void solve(Eigen::VectorXd& r) const {
    for (int i = 0; i < n_; ++i) {
      double s = r[i];
      for (int k = std::max(0, i - b_); k < i; ++k) s -= band_[index(i, k)] * r[k];
      r[i] = s / band_[index(i, i)];
    }
    for (int i = n_ - 1; i >= 0; --i) {
      double s = r[i];
      for (int k = i + 1; k <= std::min(n_ - 1, i + b_); ++k) s -= band_[index(k, i)] * r[k];
      r[i] = s / band_[index(i, i)];
    }
  }

 private:
  [[nodiscard]] std::size_t index(int i, int j) const {
    return static_cast<std::size_t>(i) * (b_ + 1) + (i - j);
  }
  int n_ = 0, b_ = 0;
  std::vector<double> band_;
};

}  // namespace vessel::msm::rods
