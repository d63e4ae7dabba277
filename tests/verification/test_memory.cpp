// The per-model memory probe against a known allocation.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "verification/harness/memory.hpp"

using namespace vessel;

TEST(Memory, ProbeSeesAnAllocationItsSizeAndNotAFreedOne) {
  if (resident_memory_mib() == 0.0) GTEST_FAIL() << "/proc/self/status unreadable on this system";
  {
    // Touch and free 200 MiB first: a later probe must not count it, and must still see new pages.
    std::vector<char> earlier(200u << 20);
    std::memset(earlier.data(), 1, earlier.size());
  }
  const MemoryProbe probe;
  std::vector<char> block(100u << 20);
  std::memset(block.data(), 1, block.size());  // resident only once written
  const double added = probe.added_mib();
  EXPECT_GT(added, 95.0);
  EXPECT_LT(added, 130.0);
  EXPECT_EQ(block[12345], 1);
}
