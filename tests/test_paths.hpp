#pragma once
/// Where the tests find the project's files and programs. The paths are absolute and differ from
/// one checkout to the next, so they live in one generated source (`test_paths.cpp` in the build
/// tree, written by tests/CMakeLists.txt) instead of compile definitions: a definition would change
/// every compile command of a test program, and ccache (whose CCACHE_BASEDIR rewrites path
/// arguments, not the values of -D) would then miss every object of that program in a clone in
/// another folder, as CI builds. The macros keep the names the tests use; each yields a
/// std::string.
#include <string>

namespace vessel::test::paths {
std::string vesselverify_exe();     ///< the vesselverify program built with the tests
std::string cpp_model_exe();        ///< examples/external's C++ model, built with the tests
std::string source_dir();           ///< the checkout's root
std::string tests_dir();            ///< the checkout's tests/ folder
std::string test_cache_dir();       ///< the build tree's cache for the tests (never the user's)
}  // namespace vessel::test::paths

#define VESSELVERIFY_EXE (::vessel::test::paths::vesselverify_exe())
#define VESSEL_CPP_MODEL (::vessel::test::paths::cpp_model_exe())
#define VESSEL_SCENES_DIR (::vessel::test::paths::source_dir() + "/verification/scenes")
#define VESSEL_EXAMPLES_DIR (::vessel::test::paths::source_dir() + "/examples")
#define VESSEL_BASELINE (::vessel::test::paths::source_dir() + "/reports/baseline.json")
#define VESSEL_RESULTS_SCHEMA (::vessel::test::paths::source_dir() + "/verification/results.schema.json")
#define VESSEL_EXCHANGE_SCHEMA (::vessel::test::paths::source_dir() + "/verification/exchange.schema.json")
#define VESSEL_RECOMMEND_SCHEMA \
  (::vessel::test::paths::source_dir() + "/verification/studies/recommend/recommend.schema.json")
#define VESSEL_CALIBRATE_SCHEMA \
  (::vessel::test::paths::source_dir() + "/verification/studies/calibrate/calibrate.schema.json")
#define VESSEL_STABILITY_SCHEMA \
  (::vessel::test::paths::source_dir() + "/verification/studies/stability/stability.schema.json")
#define VESSEL_VALIDITY_SCHEMA \
  (::vessel::test::paths::source_dir() + "/verification/studies/validity/validity.schema.json")
#define VESSEL_INSERTION_SCHEMA \
  (::vessel::test::paths::source_dir() + "/verification/harness/contact_insertion.schema.json")
#define VESSEL_SCREENSHOT_SCRIPT (::vessel::test::paths::source_dir() + "/scripts/report_screenshots.sh")
#define COMPARE_RESULTS (::vessel::test::paths::source_dir() + "/scripts/compare_results.py")
#define VESSEL_TEST_FIXTURES (::vessel::test::paths::tests_dir() + "/fixtures")
#define VESSEL_REPORT_FIXTURE (::vessel::test::paths::tests_dir() + "/fixtures/report_small")
#define VESSEL_BROWSER_PROBE (::vessel::test::paths::tests_dir() + "/reports/browser_probe.js")
#define VESSEL_FUZZ_CORPUS (::vessel::test::paths::tests_dir() + "/fuzz/corpus")
#define SHORT_SCENE (::vessel::test::paths::tests_dir() + "/fixtures/short_contact.toml")
