// The model outcome cache (issue 16): a hit gives the outcomes a fresh run gives (apart from
// timings, which are the cached ones and marked so), a changed model parameter misses, --retime
// measures again, and a corrupt entry is measured again with a message.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>

#include "../test_helpers.hpp"

#include "fem_reference/solution_cache.hpp"
#include "verification/harness/harness.hpp"
#include "verification/harness/outcome_cache.hpp"

using namespace vessel;

namespace {

/// A straight structured tube at level 0 under internal pressure with its reference on the same
/// level (one quick P2 solve), a FEM model and two mass-spring models, one static (Newton, timed
/// over a load ramp) and one linear.
const char* kScene = R"(name = "outcome_cache_test"
[vessel]
kind = "straight"
mesh = "structured"
level = 0
reference_level = 0
[material]
E = 14.24e3
nu = 0.3
[boundary]
inlet = "clamped"
outlet = "clamped"
[load]
type = "pressure"
magnitudes = [10.0, 20.0]
[[models]]
name = "p1"
kind = "fem"
degree = 1
[[models]]
name = "volume_static"
kind = "volume_msm"
stiffness = "seed001"
solver = "static"
[[models]]
name = "volume_linear"
kind = "volume_msm"
stiffness = "seed001"
solver = "linear"
)";

std::string read_bytes(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

/// Every outcome field but the timings, memory and provenance, equal within `rtol` (0: bitwise).
void expect_same_outcomes(const SceneResult& a, const SceneResult& b, double rtol) {
  ASSERT_EQ(a.outcomes.size(), b.outcomes.size());
  const auto near = [rtol](double x, double y) {
    return x == y || std::abs(x - y) <= rtol * std::max(std::abs(x), std::abs(y));
  };
  for (std::size_t i = 0; i < a.outcomes.size(); ++i) {
    const ModelOutcome &x = a.outcomes[i], &y = b.outcomes[i];
    SCOPED_TRACE(x.model + " at " + std::to_string(x.magnitude));
    EXPECT_EQ(x.model, y.model);
    EXPECT_EQ(x.detail, y.detail);
    EXPECT_EQ(x.magnitude, y.magnitude);
    EXPECT_EQ(x.ok, y.ok);
    EXPECT_EQ(x.nodes, y.nodes);
    EXPECT_EQ(x.unknowns, y.unknowns);
    EXPECT_EQ(x.updates, y.updates);
    EXPECT_PRED2(near, x.error.max_mm, y.error.max_mm);
    EXPECT_PRED2(near, x.error.relative_l2, y.error.relative_l2);
    EXPECT_PRED2(near, x.qoi_displacement_mm, y.qoi_displacement_mm);
    EXPECT_PRED2(near, x.qoi_reference_mm, y.qoi_reference_mm);
    EXPECT_PRED2(near, x.max_strain, y.max_strain);
    EXPECT_PRED2(near, x.quantities.field_mm, y.quantities.field_mm);
    ASSERT_EQ(x.wall_profile.model_mm.size(), y.wall_profile.model_mm.size());
    for (std::size_t k = 0; k < x.wall_profile.model_mm.size(); ++k) {
      EXPECT_PRED2(near, x.wall_profile.model_mm[k], y.wall_profile.model_mm[k]);
    }
    // No budget: NaN both times (the cache keeps non-finite values).
    EXPECT_EQ(std::isnan(x.budget_error), std::isnan(y.budget_error));
  }
}

struct Fixture {
  test::TempDir dir;
  std::ostringstream log;
  Scene scene = parse_scene(kScene, "outcome_cache_test.toml");
  std::filesystem::path outcomes = dir.path() / "outcomes";
  fem::SolutionCache references{dir.path() / "fem", &log};  // the reference solved once
  /// Harness options with both caches.
  HarnessOptions options(OutcomeCache& cache) {
    HarnessOptions o;
    o.solution_cache = &references;
    o.outcome_cache = &cache;
    return o;
  }
};

}  // namespace

TEST(OutcomeCache, AHitGivesTheFreshRunsOutcomesWithTheCachedTimingsMarkedAsCached) {
  Fixture f;
  OutcomeCache cache(f.outcomes, false, &f.log);
  HarnessOptions o = f.options(cache);
  o.fields_dir = f.dir.path() / "fields1";
  const SceneResult first = run_scene(f.scene, o);
  EXPECT_EQ(cache.statistics().misses, 3);  // one entry per model (ν and level)
  EXPECT_EQ(cache.statistics().hits, 0);
  for (const ModelOutcome& x : first.outcomes) {
    EXPECT_FALSE(x.timing.cached);
    EXPECT_EQ(x.timing.measured_at.size(), 20u) << x.timing.measured_at;  // YYYY-MM-DDTHH:MM:SSZ
  }
  o.fields_dir = f.dir.path() / "fields2";
  const SceneResult second = run_scene(f.scene, o);
  EXPECT_EQ(cache.statistics().misses, 3);
  EXPECT_EQ(cache.statistics().hits, 3);
  expect_same_outcomes(first, second, 0.0);
  for (std::size_t i = 0; i < first.outcomes.size(); ++i) {
    const ModelOutcome &x = first.outcomes[i], &y = second.outcomes[i];
    EXPECT_TRUE(y.timing.cached);
    EXPECT_EQ(y.timing.measured_at, x.timing.measured_at);
    EXPECT_EQ(y.setup_seconds, x.setup_seconds);  // the cached timings, not new ones
    EXPECT_EQ(y.solve_seconds, x.solve_seconds);
  }
  // The hit writes the VTU fields the measurement wrote, byte for byte.
  int files = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(f.dir.path() / "fields1")) {
    if (!e.is_regular_file()) continue;
    ++files;
    const auto twin = f.dir.path() / "fields2" /
                      std::filesystem::relative(e.path(), f.dir.path() / "fields1");
    EXPECT_EQ(read_bytes(e.path()), read_bytes(twin)) << twin;
  }
  EXPECT_EQ(files, 3);  // one per model at the representative load
  // A run without the cache measures afresh: the same outcomes (its FEM solves may differ in the
  // last bits: threaded sums).
  const SceneResult fresh = run_scene(f.scene, HarnessOptions{});
  expect_same_outcomes(fresh, second, 1e-10);
  EXPECT_FALSE(fresh.outcomes.front().timing.cached);
  EXPECT_EQ(f.log.str(), "");
}

TEST(OutcomeCache, AChangedModelParameterMissesAndTheUnchangedModelsStillHit) {
  Fixture f;
  OutcomeCache cache(f.outcomes, false, &f.log);
  HarnessOptions o = f.options(cache);
  (void)run_scene(f.scene, o);
  Scene changed = f.scene;
  changed.models[1].stiffness = msm::StiffnessRule::van_gelder;  // volume_static only
  const SceneResult r = run_scene(changed, o);
  EXPECT_EQ(cache.statistics().misses, 4);
  EXPECT_EQ(cache.statistics().hits, 2);
  for (const ModelOutcome& x : r.outcomes) EXPECT_EQ(x.timing.cached, x.model != "volume_static");
  // So do a changed load, ν and ramp length (every model).
  Scene other_load = f.scene;
  other_load.load.magnitudes = {10.0, 30.0};
  (void)run_scene(other_load, o);
  EXPECT_EQ(cache.statistics().misses, 7);
  HarnessOptions longer = o;
  longer.ramp_updates = 4;
  (void)run_scene(f.scene, longer);
  EXPECT_EQ(cache.statistics().misses, 10);
  EXPECT_EQ(cache.statistics().hits, 2);
}

TEST(OutcomeCache, RetimeMeasuresAgainAndReplacesTheEntries) {
  Fixture f;
  OutcomeCache cache(f.outcomes, false, &f.log);
  HarnessOptions o = f.options(cache);
  const SceneResult first = run_scene(f.scene, o);
  OutcomeCache retime(f.outcomes, true, &f.log);
  o.outcome_cache = &retime;
  const SceneResult again = run_scene(f.scene, o);
  EXPECT_EQ(retime.statistics().hits, 0);
  EXPECT_EQ(retime.statistics().misses, 3);
  expect_same_outcomes(first, again, 1e-10);
  bool any_new_timing = false;
  for (std::size_t i = 0; i < again.outcomes.size(); ++i) {
    EXPECT_FALSE(again.outcomes[i].timing.cached);
    any_new_timing |= again.outcomes[i].solve_seconds != first.outcomes[i].solve_seconds;
  }
  EXPECT_TRUE(any_new_timing);  // measured, not read back
  // The next plain run reads the re-measured entries.
  OutcomeCache after(f.outcomes, false, &f.log);
  o.outcome_cache = &after;
  const SceneResult third = run_scene(f.scene, o);
  EXPECT_EQ(after.statistics().hits, 3);
  for (std::size_t i = 0; i < third.outcomes.size(); ++i) {
    EXPECT_EQ(third.outcomes[i].solve_seconds, again.outcomes[i].solve_seconds);
  }
}

TEST(OutcomeCache, ACorruptEntryIsMeasuredAgainWithAMessage) {
  Fixture f;
  OutcomeCache cache(f.outcomes, false, &f.log);
  HarnessOptions o = f.options(cache);
  const SceneResult first = run_scene(f.scene, o);
  int damaged = 0;
  for (const auto& e : std::filesystem::directory_iterator(f.outcomes)) {
    std::string bytes = read_bytes(e.path());
    if (damaged == 0) {
      bytes[bytes.size() / 2] ^= 0x5a;  // a flipped byte
    } else if (damaged == 1) {
      bytes.resize(bytes.size() / 3);  // truncated
    } else {
      continue;
    }
    std::ofstream(e.path(), std::ios::binary | std::ios::trunc) << bytes;
    ++damaged;
  }
  ASSERT_EQ(damaged, 2);
  const SceneResult second = run_scene(f.scene, o);
  EXPECT_EQ(cache.statistics().corrupt, 2);
  EXPECT_EQ(cache.statistics().hits, 1);
  EXPECT_EQ(cache.statistics().misses, 5);
  EXPECT_NE(f.log.str().find("model outcome cache: entry "), std::string::npos) << f.log.str();
  EXPECT_NE(f.log.str().find("is corrupt"), std::string::npos);
  expect_same_outcomes(first, second, 1e-10);
}

TEST(OutcomeCache, TheProvenanceLineCountsTheCachedTimingsAndTheirDates) {
  std::vector<ModelOutcome> outcomes(3);
  outcomes[0].timing = {true, "2026-11-25T05:00:00Z"};
  outcomes[1].timing = {true, "2026-11-24T05:00:00Z"};
  outcomes[2].timing = {false, "2026-11-25T06:00:00Z"};
  EXPECT_EQ(timing_provenance_line(outcomes),
            "2 of 3 timings from the cache, measured 2026-11-24T05:00:00Z to "
            "2026-11-25T05:00:00Z by the same executable on this machine; --retime to measure "
            "again");
  outcomes.resize(1);
  outcomes[0].timing.cached = false;
  EXPECT_EQ(timing_provenance_line(outcomes), "");
}
