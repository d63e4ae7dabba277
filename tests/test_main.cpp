/// The main of every test program: the tests and the programs they start never read or write the
/// user's cache (~/.cache/vesselverify, or their VESSELVERIFY_CACHE_DIR), only the build tree's
/// own (test_paths.hpp).
#include <gtest/gtest.h>

#include <cstdlib>

#include "test_paths.hpp"

int main(int argc, char** argv) {
  setenv("VESSELVERIFY_CACHE_DIR", vessel::test::paths::test_cache_dir().c_str(), 1);
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
