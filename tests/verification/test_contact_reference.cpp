// The contact reference of a guidewire scene (verification/harness/contact_reference.hpp): bad
// input refused with the file named; on the shipped straight scene's floppy wire the force below
// the rigid wall's closed form and converging with the wall's refinement.
#include <gtest/gtest.h>

#include <algorithm>
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
  ContactReferenceOptions bad_rungs;
  bad_rungs.continuation_ratio = 1.0;
  expect_input_error([&] { (void)solve_contact_reference(wire, 4e-7, bad_rungs); },
                     {"continuation ratio > 1"});
  expect_input_error([] { (void)parse_contact_wall("hyperelastic"); },
                     {"linear", "neo-hookean", "hyperelastic"});
  EXPECT_EQ(parse_contact_wall("neo-hookean"), ContactWall::neo_hookean);
  // The stiffnesses default to the scene's sweep.
  EXPECT_EQ(contact_reference_stiffnesses(wire), (std::vector<double>{4e-7, 4e-6, 4e-5}));
}

// guidewire_straight's floppy wire (EI = 4e-7 N·m²) on its own wall at three levels (0.1, 0.08,
// 0.064 mm around the zone, P1): every level converges to a line of contact whose force is below
// the continuum wire's on the rigid lumen (F z²/EI = 0.470968, Kirchhoff shooting) and the
// discrete wire's; the levels agree within 0.2 %; Roache's GCI comes out small; the strain under
// the wire (a dent of more than the wire's radius) is flagged beyond the linear wall's validity.
// About 2 minutes with the load average at 6 on 2 cores.
TEST(ContactReferenceSlow, StraightSceneFloppyWireConverges) {
  const Scene scene = shipped("guidewire_straight.toml");
  const double EI = 4e-7;
  ContactReferenceOptions o;
  o.coarsest_size = 0.1e-3;
  o.ratio = 1.25;
  const ContactReference r = solve_contact_reference(scene, EI, o);
  print_contact_reference(r, std::cout);
  ASSERT_EQ(r.levels.size(), 3u);
  ASSERT_TRUE(r.continuum_rigid_force);
  // The scene's wire touches at z = 20 mm (L/z = 1.012498).
  EXPECT_NEAR(*r.continuum_rigid_force, 0.470968 * EI / (20e-3 * 20e-3),
              2e-3 * *r.continuum_rigid_force);
  double lo = 1.0, hi = 0.0;
  for (const ContactLevel& l : r.levels) {
    ASSERT_TRUE(l.converged) << l.failure;
    EXPECT_LT(l.force, *r.continuum_rigid_force);
    EXPECT_LT(l.force, r.rigid_force);
    EXPECT_GT(l.pressed, 1);  // a line of contact, not a point
    EXPECT_TRUE(l.zone_inside_patch);
    EXPECT_GT(l.dent, 0.5 * scene.load.guidewire->diameter);
    lo = std::min(lo, l.force);
    hi = std::max(hi, l.force);
  }
  EXPECT_LT(hi - lo, 2e-3 * hi);
  ASSERT_TRUE(r.order && r.estimate);
  EXPECT_LT(r.estimate->gci_fine, 0.02);
  EXPECT_LT(r.estimate->extrapolated, r.rigid_force);
  EXPECT_NE(r.verdict.find("beyond the linear wall's validity"), std::string::npos) << r.verdict;
}

// The same wire on the finite-strain (neo-Hookean) wall, two levels (0.1, 0.08 mm): each converges
// to a line of contact below both rigid-lumen forces, the levels agree within 0.5 %, and the
// verdict does not depend on a strain limit (the wall is valid at finite strain).
TEST(ContactReferenceSlow, StraightSceneFloppyWireOnTheNeoHookeanWall) {
  const Scene scene = shipped("guidewire_straight.toml");
  ContactReferenceOptions o;
  o.wall = ContactWall::neo_hookean;
  o.levels = 2;
  o.coarsest_size = 0.1e-3;
  o.ratio = 1.25;
  const ContactReference r = solve_contact_reference(scene, 4e-7, o);
  print_contact_reference(r, std::cout);
  ASSERT_EQ(r.levels.size(), 2u);
  for (const ContactLevel& l : r.levels) {
    ASSERT_TRUE(l.converged) << l.failure;
    EXPECT_LT(l.force, r.rigid_force);
    EXPECT_LT(l.force, *r.continuum_rigid_force);
    EXPECT_GT(l.pressed, 1);
    EXPECT_GT(l.strain, o.strain_limit);  // beyond the linear wall's range, within this one's
  }
  EXPECT_NEAR(r.levels[0].force, r.levels[1].force, 5e-3 * r.levels[1].force);
  EXPECT_EQ(r.verdict, "reference");
}

}  // namespace
}  // namespace vessel
