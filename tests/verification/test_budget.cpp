// The [budget] table and roi_radius: values read, defaults, and refusals naming file, line and
// key with what was found and what was expected.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "meshes/foundation/errors.hpp"
#include "test_paths.hpp"
#include "verification/scene.hpp"

using namespace vessel;

namespace {

const char* kContact = R"(name = "t"
[vessel]
kind = "straight"
level = 0
[load]
type = "contact"
magnitudes = [1e-5, 1e-4, 1e-3]
point = [3e-3, 0, 20e-3]
[[models]]
name = "v"
kind = "volume_msm"
stiffness = "seed001"
solver = "static"
)";

const char* kPressure = R"(name = "p"
[vessel]
kind = "straight"
level = 0
[load]
type = "pressure"
magnitudes = [10.0]
[[models]]
name = "v"
kind = "volume_msm"
solver = "static"
)";

std::string error_of(const std::string& text) {
  try {
    (void)parse_scene(text, "scene.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// kContact plus a [budget] table with these lines.
std::string budget(const std::string& lines) {
  return std::string(kContact) + "[budget]\n" + lines + "\n";
}

}  // namespace

TEST(Budget, AbsentMeansNotStated) {
  const Scene s = parse_scene(kContact, "scene.toml");
  EXPECT_FALSE(s.budget.stated);
  EXPECT_EQ(s.models.front().roi_radius, 0.0);
}

TEST(Budget, DefaultsAreTheContactPointAtSeed000sThreshold) {
  const Scene s = parse_scene(budget("rate_hz = 30"), "scene.toml");
  ASSERT_TRUE(s.budget.stated);
  EXPECT_EQ(s.budget.quantity, BudgetQuantity::contact_point);
  EXPECT_DOUBLE_EQ(s.budget.tolerance, 0.1);
  EXPECT_DOUBLE_EQ(s.budget.rate_hz, 30.0);
  EXPECT_DOUBLE_EQ(s.budget.seconds_per_update(), 1.0 / 30.0);
  EXPECT_DOUBLE_EQ(s.budget.update_period(), 1.0 / 30.0);
  EXPECT_EQ(s.budget.magnitude, 0.0);
  EXPECT_STREQ(budget_unit(s.budget.quantity), "mm");
}

TEST(Budget, ToleranceDefaultsToTheScenesTolerancesTable) {
  const Scene s =
      parse_scene(budget("rate_hz = 1000") + "[tolerances]\nmax_error_mm = 0.05\n", "scene.toml");
  EXPECT_DOUBLE_EQ(s.budget.tolerance, 0.05);
}

TEST(Budget, EveryKeyIsRead) {
  const Scene s = parse_scene(budget("quantity = \"patch\"\nradius = 0.004\ntolerance_mm = 0.2\n"
                                     "rate_hz = 1000\ntime_budget_s = 2e-4\nmagnitude = 1e-4"),
                              "scene.toml");
  EXPECT_EQ(s.budget.quantity, BudgetQuantity::patch);
  EXPECT_DOUBLE_EQ(s.budget.radius, 0.004);
  EXPECT_DOUBLE_EQ(s.budget.tolerance, 0.2);
  EXPECT_DOUBLE_EQ(s.budget.seconds_per_update(), 2e-4);  // the time budget, not 1 ms
  EXPECT_DOUBLE_EQ(s.budget.update_period(), 1e-3);       // the rate's period
  EXPECT_DOUBLE_EQ(s.budget.magnitude, 1e-4);
  // A time budget alone is also the update period.
  const Scene t = parse_scene(budget("quantity = \"field\"\ntime_budget_s = 0.01"), "scene.toml");
  EXPECT_DOUBLE_EQ(t.budget.update_period(), 0.01);
  EXPECT_EQ(t.budget.quantity, BudgetQuantity::field);
}

TEST(Budget, ReactionTakesAForceTolerance) {
  const Scene s =
      parse_scene(budget("quantity = \"reaction\"\ntolerance_mN = 0.01\nrate_hz = 1000"), "s");
  EXPECT_EQ(s.budget.quantity, BudgetQuantity::reaction);
  EXPECT_DOUBLE_EQ(s.budget.tolerance, 0.01);
  EXPECT_STREQ(budget_unit(s.budget.quantity), "mN");
}

TEST(Budget, ContactForceTakesAForceToleranceAndAGuidewireInContact) {
  std::ifstream in(std::string(VESSEL_SCENES_DIR) + "/guidewire_straight.toml");
  std::stringstream text;
  text << in.rdbuf();
  ASSERT_NE(text.str().find("coupling = \"contact\""), std::string::npos);
  const std::string table =
      "[budget]\nquantity = \"contact_force\"\ntolerance_mN = 0.5\nrate_hz = 60\n";
  const Scene s = parse_scene(text.str() + table, "guidewire_straight.toml");
  EXPECT_EQ(s.budget.quantity, BudgetQuantity::contact_force);
  EXPECT_DOUBLE_EQ(s.budget.tolerance, 0.5);
  EXPECT_STREQ(budget_unit(s.budget.quantity), "mN");
  // The same wire coupled by series springs has no contact solve to judge by.
  std::string compliant = text.str();
  compliant.replace(compliant.find("coupling = \"contact\""), 20, "coupling = \"compliant\"");
  std::string e;
  try {
    (void)parse_scene(compliant + table, "scene.toml");
  } catch (const InputError& x) {
    e = x.what();
  }
  EXPECT_NE(e.find("budget.quantity"), std::string::npos) << e;
  EXPECT_NE(e.find("coupling = \"contact\""), std::string::npos) << e;
}

TEST(Budget, RefusalsNameTheKeyWhatWasFoundAndWhatWasExpected) {
  const auto refused = [](const std::string& text, const std::vector<std::string>& parts) {
    const std::string e = error_of(text);
    ASSERT_FALSE(e.empty()) << text;
    EXPECT_NE(e.find("scene.toml:"), std::string::npos) << e;
    for (const auto& p : parts) EXPECT_NE(e.find(p), std::string::npos) << e << "\nwanted: " << p;
  };
  refused(budget("quantity = \"speed\"\nrate_hz = 30"),
          {"budget.quantity", "\"speed\"", "contact_point, patch, field, reaction"});
  refused(budget("quantity = 3\nrate_hz = 30"), {"budget.quantity", "found 3"});
  refused(budget("tolerance_mm = 0.1"), {"budget.rate_hz", "missing", "time_budget_s"});
  refused(budget("rate_hz = 0\n"), {"budget.rate_hz", "found 0", "> 0"});
  refused(budget("rate_hz = -30"), {"budget.rate_hz", "found -30"});
  refused(budget("rate_hz = \"fast\""), {"budget.rate_hz", "\"fast\"", "a number"});
  refused(budget("time_budget_s = 0\nrate_hz = 30"), {"budget.time_budget_s", "found 0"});
  refused(budget("tolerance_mm = -0.1\nrate_hz = 30"), {"budget.tolerance_mm", "found -0.1"});
  refused(budget("quantity = \"patch\"\nrate_hz = 30"), {"budget.radius", "missing", "patch"});
  refused(budget("quantity = \"patch\"\nradius = 0\nrate_hz = 30"), {"budget.radius", "found 0"});
  refused(budget("radius = 0.004\nrate_hz = 30"),
          {"budget.radius", "contact_point", "only with quantity \"patch\""});
  refused(budget("quantity = \"reaction\"\nrate_hz = 30"), {"budget.tolerance_mN", "missing"});
  refused(budget("quantity = \"reaction\"\ntolerance_mm = 0.1\ntolerance_mN = 1\nrate_hz = 30"),
          {"budget.tolerance_mm", "tolerance_mN"});
  refused(budget("tolerance_mN = 1\nrate_hz = 30"), {"budget.tolerance_mN", "tolerance_mm"});
  refused(budget("magnitude = 0.5\nrate_hz = 30"),
          {"budget.magnitude", "found 0.5", "one of the load's magnitudes"});
  refused(budget("rate = 30"), {"budget.rate", "unknown key"});
  refused("budget = 3\n" + std::string(kContact), {"key 'budget'", "expected a table"});
  refused(budget("quantity = \"contact_force\"\ntolerance_mN = 1\nrate_hz = 30"),
          {"budget.quantity", "contact_force", "guidewire load"});
  refused(budget("quantity = \"contact_force\"\nrate_hz = 30"), {"budget.quantity"});
  refused(std::string(kPressure) +
              "[budget]\nquantity = \"reaction\"\ntolerance_mN = 1\n"
              "rate_hz = 30\n",
          {"budget.quantity", "pressure", "contact load"});
}

TEST(Roi, RadiusIsReadAndAnArraySweepsIt) {
  std::string text = kContact;
  text.insert(text.find("solver"), "roi_radius = [0.002, 0.004]\n");
  const Scene s = parse_scene(text, "scene.toml");
  ASSERT_EQ(s.models.size(), 2u);
  EXPECT_DOUBLE_EQ(s.models[0].roi_radius, 0.002);
  EXPECT_DOUBLE_EQ(s.models[1].roi_radius, 0.004);
  EXPECT_EQ(s.models[0].name, "v[roi_radius=0.002]");
  EXPECT_EQ(s.models[1].name, "v[roi_radius=0.004]");
}

TEST(Roi, RefusedWhereItMeansNothing) {
  std::string zero = kContact;
  zero.insert(zero.find("solver"), "roi_radius = 0.0\n");
  EXPECT_NE(error_of(zero).find("models[0].roi_radius': found 0, expected a number > 0 m"),
            std::string::npos)
      << error_of(zero);
  std::string pressure = kPressure;
  pressure.insert(pressure.find("solver"), "roi_radius = 0.004\n");
  EXPECT_NE(error_of(pressure).find("expected it only with a contact load"), std::string::npos)
      << error_of(pressure);
  std::string fem = std::string(kContact) +
                    "[[models]]\nname = \"f\"\nkind = \"fem\"\n"
                    "roi_radius = 0.004\n";
  EXPECT_NE(error_of(fem).find("models[1].roi_radius': unknown key"), std::string::npos)
      << error_of(fem);
}
