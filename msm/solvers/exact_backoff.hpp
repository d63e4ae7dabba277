#pragma once
/// When a Newton iteration tries the exact Hessian. A failed (indefinite) factorisation costs as
/// much as a good one, and the assembly before it too; where the exact Hessian keeps failing
/// (a compressed spring network, a wire pressed on a curved wall) the next 1, 2, 4 … (at most
/// `longest`) iterations go straight to the PSD-projected one, and an iteration that tries the
/// exact Hessian again restores Newton's quadratic rate near the solution.
#include <algorithm>

namespace vessel::msm {

class ExactBackoff {
 public:
  /// `longest`: the most iterations skipped after a failure (0: try every iteration).
  explicit ExactBackoff(int longest) : longest_(longest) {}
  /// Whether this iteration tries the exact Hessian.
  bool try_exact() {
    if (skip_ == 0) return true;
    --skip_;
    return false;
  }
  /// What the exact Hessian gave, at an iteration that tried it.
  void record(bool exact_worked) {
    length_ = exact_worked ? 0 : std::min(std::max(2 * length_, 1), longest_);
    skip_ = length_;
  }

 private:
  int longest_;
  int length_ = 0;
  int skip_ = 0;
};

}  // namespace vessel::msm
