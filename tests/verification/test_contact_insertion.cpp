// The wire pushed into the vessel in steps (verification/harness/contact_insertion.hpp): bad input
// refused with the file named; on the straight scene the push computed from the clamp's force and
// moment (R·t − M²/2EI, the Eshelby-like force of a rod leaving a sleeve) equals the derivative of
// the stored energy along the insertion (virtual work), and four steps end where one step does.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "meshes/foundation/errors.hpp"
#include "test_paths.hpp"
#include "verification/harness/contact_insertion.hpp"

namespace vessel {
namespace {

Scene shipped(const std::string& name) { return read_scene(VESSEL_SCENES_DIR + "/" + name); }

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

TEST(ContactInsertion, RefusesASceneWithoutAGuidewireAndAnEmptyRange) {
  const Scene patch = shipped("contact_straight.toml");
  expect_input_error([&] { (void)solve_contact_insertion(patch, 4e-7); },
                     {"contact_straight.toml", "guidewire"});
  const Scene wire = shipped("guidewire_straight.toml");
  ContactInsertionOptions backwards;
  backwards.first = 21e-3;
  backwards.last = 20e-3;
  expect_input_error([&] { (void)solve_contact_insertion(wire, 4e-7, backwards); },
                     {"guidewire_straight.toml", "first length", "shorter than the last"});
  ContactInsertionOptions no_steps;
  no_steps.steps = 0;
  expect_input_error([&] { (void)solve_contact_insertion(wire, 4e-7, no_steps); },
                     {"guidewire_straight.toml", "steps ≥ 1"});
  expect_input_error([&] { (void)solve_contact_insertion(wire, 0.0); },
                     {"guidewire_straight.toml", "EI"});
}

// guidewire_straight's floppy wire (EI 4e-7 N·m²) on its neo-Hookean wall, pushed from 19.25 to
// 20.25 mm in four steps of 0.25 mm.
TEST(ContactInsertionSlow, PushIsTheEnergysDerivativeAndFourStepsEndWhereOneDoes) {
  const Scene scene = shipped("guidewire_straight.toml");
  const double EI = 4e-7;
  ContactInsertionOptions o;
  o.first = 19.25e-3;
  o.last = 20.25e-3;
  o.steps = 4;
  o.log = &std::cerr;
  const ContactInsertion r = solve_contact_insertion(scene, EI, o);
  print_contact_insertion(r, std::cout);
  ASSERT_EQ(r.steps.size(), 5u);
  for (const InsertionStep& s : r.steps) {
    ASSERT_TRUE(s.converged) << s.insertion << ": " << s.failure;
    EXPECT_GT(s.force, 0.0);
    EXPECT_GE(s.zones.size(), 1u);
  }
  // The push by the clamp's force and moment against dΠ/dL by central differences at the three
  // inner steps. The clamp's axial force carries the faceted wall's scatter in the contact
  // normal's direction (a tilt of 0.01 rad moves 1 % of the contact force into the axis), so
  // per step they agree to 2.5 % of the contact force; over the range, the trapezoid of the
  // push against the energy's change to 8 %.
  for (std::size_t k = 1; k + 1 < r.steps.size(); ++k) {
    const InsertionStep& s = r.steps[k];
    EXPECT_NEAR(s.push, s.push_by_energy, 0.025 * s.force)
        << "at " << s.insertion * 1e3 << " mm: R·t " << s.clamp_axial << " N, M " << s.clamp_moment
        << " N·m";
  }
  double work = 0.0;
  for (std::size_t k = 1; k < r.steps.size(); ++k) {
    work += 0.5 * (r.steps[k].push + r.steps[k - 1].push) *
            (r.steps[k].insertion - r.steps[k - 1].insertion);
  }
  const double stored = r.steps.back().energy - r.steps.front().energy;
  EXPECT_NEAR(work, stored, 0.08 * std::abs(stored)) << "push's work " << work << " J";
  // Without the sleeve's M²/2EI the clamp's axial force alone is several times the push.
  EXPECT_GT(r.steps[2].clamp_axial, 2.0 * r.steps[2].push_by_energy);
  // The same range in one step (the same mesh: it follows the range, not the steps).
  ContactInsertionOptions one = o;
  one.steps = 1;
  const ContactInsertion direct = solve_contact_insertion(scene, EI, one);
  ASSERT_EQ(direct.mesh_nodes, r.mesh_nodes);
  ASSERT_TRUE(direct.steps.back().converged) << direct.steps.back().failure;
  EXPECT_NEAR(direct.steps.back().force, r.steps.back().force, 1e-3 * r.steps.back().force);
  EXPECT_LT((direct.steps.back().tip - r.steps.back().tip).norm(), 1e-3 * 0.178e-3);
}

}  // namespace
}  // namespace vessel
