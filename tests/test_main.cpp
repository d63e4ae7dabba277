/// The main of every test program: the tests and the programs they start never read or write the
/// user's cache (~/.cache/vesselverify, or their VESSELVERIFY_CACHE_DIR), only the build tree's
/// own (VESSEL_TEST_CACHE_DIR, set by tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <cstdlib>

int main(int argc, char** argv) {
  setenv("VESSELVERIFY_CACHE_DIR", VESSEL_TEST_CACHE_DIR, 1);
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
