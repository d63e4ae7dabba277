// Error statistics and timing helpers against hand-computed values.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include <cmath>
#include <sstream>

#include "verification/harness/metrics.hpp"
#include "verification/harness/progress.hpp"
#include "verification/harness/timing.hpp"

using namespace vessel;

TEST(Metrics, SeedStatisticsByHand) {
  // Nodal errors of 3 mm, 4 mm and 0: |e| = {0.003, 0.004, 0} m.
  const std::vector<Vec3> ref{Vec3(0.01, 0, 0), Vec3(0, 0.01, 0), Vec3(0, 0, 0.01)};
  std::vector<Vec3> model = ref;
  model[0].x() += 0.003;
  model[1].y() -= 0.004;
  const ErrorStatistics s = compare_displacements(model, ref);
  EXPECT_EQ(s.points, 3u);
  EXPECT_NEAR(s.max_mm, 4.0, 1e-12);
  EXPECT_NEAR(s.mean_mm, 7.0 / 3.0, 1e-12);
  EXPECT_NEAR(s.rms_mm, std::sqrt(25.0 / 3.0), 1e-12);
  // Population std of {3, 4, 0}: sqrt(25/3 − 49/9) = sqrt(26/9).
  EXPECT_NEAR(s.stddev_mm, std::sqrt(26.0) / 3.0, 1e-12);
  // sqrt(25e-6 / 3e-4) = sqrt(1/12).
  EXPECT_NEAR(s.relative_l2, std::sqrt(1.0 / 12.0), 1e-12);
  // |u|² = 0.013² + 0.006² + 0.01² = 3.05e-4 against the reference's 3e-4.
  EXPECT_NEAR(s.model_l2_over_reference, std::sqrt(3.05 / 3.0), 1e-12);
}

TEST(Metrics, IdenticalFieldsHaveZeroErrorAndSizeMismatchThrows) {
  const std::vector<Vec3> u{Vec3(1e-3, 2e-3, 3e-3)};
  const ErrorStatistics s = compare_displacements(u, u);
  EXPECT_EQ(s.max_mm, 0.0);
  EXPECT_EQ(s.relative_l2, 0.0);
  EXPECT_THROW(compare_displacements(u, {}), std::invalid_argument);
}

TEST(Timing, MedianOfOddAndEvenSamples) {
  EXPECT_DOUBLE_EQ(median({5.0, 1.0, 3.0}), 3.0);
  EXPECT_DOUBLE_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_THROW(median({}), std::invalid_argument);
}

TEST(Timing, TimeMedianRunsWarmupPlusRepeats) {
  int calls = 0;
  const TimingSample t = time_median([&] { ++calls; }, 4, 2);
  EXPECT_EQ(calls, 6);
  EXPECT_EQ(t.repeats, 4);
  EXPECT_LE(t.min_s, t.median_s);
  EXPECT_LE(t.median_s, t.max_s);
}

TEST(Progress, CountsCasesAndPrintsWhatIsLeft) {
  std::ostringstream out;
  Progress p(out, 2);
  EXPECT_EQ(p.estimated_remaining_s(), 0.0);  // nothing done: no estimate
  p.begin("case A");
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  p.end();
  EXPECT_EQ(p.done(), 1u);
  EXPECT_NE(out.str().find("[1/2] case A"), std::string::npos);
  EXPECT_NE(out.str().find("done 1/2"), std::string::npos);
  // One case of two took at least the 20 ms slept: about as long again is left.
  EXPECT_GE(p.estimated_remaining_s(), 0.020);
  p.begin("case B");
  p.end();
  EXPECT_EQ(p.estimated_remaining_s(), 0.0);  // all done
}

// A progress line leaves the log's number format as it found it: the lines after it (a contact
// solve's forces in mN) printed one significant digit ("force 2 mN", "3e+02 s").
TEST(Progress, LeavesTheLogsNumberFormatAsItFoundIt) {
  std::ostringstream out;
  Progress p(out, 1);
  p.begin("case");
  p.end();
  EXPECT_NE(out.str().find("s left"), std::string::npos);
  out << 1.7841 << " mN";
  EXPECT_NE(out.str().find("1.7841 mN"), std::string::npos) << out.str();
}
