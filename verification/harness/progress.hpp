#pragma once
/// Progress of a long run on one line per case: which case, how many are left, elapsed and
/// estimated remaining time (from the mean time per finished case).
#include <ostream>
#include <string>

#include "verification/harness/timing.hpp"

namespace vessel {

class Progress {
 public:
  Progress(std::ostream& out, std::size_t total) : out_(out), total_(total) {}
  /// Announces the start of the next case.
  void begin(const std::string& what);
  /// Marks the current case finished and prints the remaining-time estimate.
  void end();
  [[nodiscard]] std::size_t done() const { return done_; }
  /// Estimated seconds for the cases not yet finished (0 before the first one finishes).
  [[nodiscard]] double estimated_remaining_s() const;

 private:
  std::ostream& out_;
  std::size_t total_;
  std::size_t done_ = 0;
  Stopwatch clock_;
};

}  // namespace vessel
