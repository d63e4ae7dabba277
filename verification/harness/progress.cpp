#include "verification/harness/progress.hpp"

#include <iomanip>
#include <sstream>

namespace vessel {

void Progress::begin(const std::string& what) {
  out_ << "[" << done_ + 1 << "/" << total_ << "] " << what << std::endl;
}

double Progress::estimated_remaining_s() const {
  if (done_ == 0) return 0.0;
  return clock_.seconds() / static_cast<double>(done_) * static_cast<double>(total_ - done_);
}

void Progress::end() {
  ++done_;
  // Formatted apart: the log's own precision and flags stay as its other writers set them.
  std::ostringstream line;
  line << "      done " << done_ << "/" << total_ << ", elapsed " << std::fixed
       << std::setprecision(1) << clock_.seconds() << " s, about " << estimated_remaining_s()
       << " s left";
  out_ << line.str() << std::endl;
}

}  // namespace vessel
