// A guidewire scene with coupling = "contact" (verification/harness/guidewire_contact.hpp, on
// verification/contact_models/contact_models.hpp): on a wall 10^4–10^6 times stiffer than the
// shipped scenes' the contact solve's force is the rigid lumen's, so the continuum wire's closed
// forms judge it (the straight tube's Kirchhoff shooting, F·z²/EI = 0.470968; the arch's
// quarter-wave elastica at the apex, F·R²/EI = 1.0648702), within the rod's own discretisation
// error and the faceted wall's; the solve kept in the outcome cache is read back unchanged; the
// results.json object conforms to its schema.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <thread>
#include <tuple>

#include "meshes/foundation/errors.hpp"
#include "meshes/foundation/solver_threads.hpp"
#include "meshes/vessel_geometry.hpp"
#include "schema_check.hpp"
#include "test_helpers.hpp"
#include "test_paths.hpp"
#include "verification/guidewire/guidewire_load.hpp"
#include "verification/harness/guidewire_contact.hpp"
#include "verification/harness/guidewire_coupling.hpp"
#include "verification/harness/outcome_cache.hpp"

namespace vessel {
namespace {

/// A shipped guidewire scene with only `models` kept and its wall `stiffer` times stiffer.
Scene shipped_scene(const std::string& name, const std::vector<std::string>& models,
                    double stiffer = 1.0) {
  Scene s = read_scene(VESSEL_SCENES_DIR + "/" + name);
  s.youngs_modulus *= stiffer;
  std::vector<ModelSpec> kept;
  for (const ModelSpec& m : s.models) {
    if (std::find(models.begin(), models.end(), m.name) != models.end()) kept.push_back(m);
  }
  s.models = kept;
  return s;
}

/// A run's options with an outcome cache of its own (a temporary folder) and a 0.12 mm contact
/// mesh.
struct CachedContactOptions {
  CachedContactOptions() {
    options.outcome_cache = &cache;
    options.contact_fine_size = 0.12e-3;
    options.log = &std::cerr;
  }
  test::TempDir dir;
  std::ostringstream cache_log;
  OutcomeCache cache{dir.path(), false, &cache_log};
  HarnessOptions options;
};

/// The continuum wire's force (N) for the scene's wire at EI against the rigid lumen.
double continuum_force(const Scene& s, double EI) {
  std::string why;
  const auto w = continuum_wire(s.vessel, with_stiffness(*s.load.guidewire, EI), why);
  if (!w) throw std::runtime_error("no continuum wire: " + why);
  return w->force;
}

// The arch's floppy wire against its wall made 10^4 times stiffer (its dent ~0.1 µm), the reference
// P1 on a mesh refined to 0.1 mm at the apex, solved as one potential (the condensed active set
// does not converge on the buckled wire): the contact solve's force is the discrete wire's on the
// rigid lumen within 0.5 % (the wall's faceting and the capsule's sink between its nodes), the
// continuum quarter-wave elastica's within the rod's own error (N = 32) plus that, and the zone is
// at the rigid wire's contact, on the outer wall at the apex. (At 10^6 the potential's Newton
// stalls at a residual of 3e-8 N, 4e-5 of the force scale.) The reference is factorised on two
// threads; the solver threads are one again after the call.
TEST(GuidewireContact, TheArchOnAWallTenThousandTimesStifferIsTheQuarterWaveElastica) {
  const Scene scene = shipped_scene("guidewire_arch.toml", {}, 1e4);
  contact::ContactModelsOptions o;
  o.bending_stiffness = {4e-7};
  o.reference_degree = 1;
  o.fine_size = 0.1e-3;
  o.fine_radius = 0.6e-3;
  o.reference_threads = 2;
  o.log = &std::cerr;
  set_solver_threads(1);
  const contact::ContactModels c = contact::solve_contact_models(scene, {}, o);
  EXPECT_EQ(solver_threads(), 1);
  ASSERT_EQ(c.runs.size(), 1u);
  const contact::ContactModelsRun& run = c.runs.front();
  ASSERT_EQ(run.reference.failure, "") << run.reference.failure;
  const double F = run.reference.force, F_rigid = run.rigid_force;
  const double F_continuum = continuum_force(scene, 4e-7);
  const double rod_error = std::abs(F_rigid / F_continuum - 1.0);
  const double R = scene.vessel.bend_radius;
  std::printf(
      "GUIDEWIRE-CONTACT arch, wall x1e4: F R^2/EI = %.6f (contact), %.6f (rigid lumen, "
      "discrete wire), %.7f (continuum); %d pressed, centroid %.3f mm from the rigid "
      "wall point\n",
      F * R * R / 4e-7, F_rigid * R * R / 4e-7, F_continuum * R * R / 4e-7, run.reference.pressed,
      (run.reference.centroid - run.rigid_wall_point).norm() * 1e3);
  EXPECT_NEAR(F_continuum * R * R / 4e-7, 1.0648702, 1e-6);
  EXPECT_LT(std::abs(F / F_rigid - 1.0), 5e-3);
  EXPECT_LT(std::abs(F / F_continuum - 1.0), rod_error + 5e-3);
  EXPECT_LT((run.reference.centroid - run.rigid_wall_point).norm(), 0.3e-3);
  const CentrelineCoordinates at = centreline_coordinates(scene.vessel, run.reference.centroid);
  EXPECT_NEAR(at.s, 0.5 * std::numbers::pi * R, 1e-3);  // the apex
  EXPECT_LT(std::abs(at.theta), 0.2);                   // on the outer bend
}

// The straight scene with coupling = "contact" on its wall made 10^6 times stiffer, its fem_p1
// model and the P2 reference at EI 4e-7 and 4e-6 on a mesh refined to 0.12 mm: against a rigid
// wall the wire's shape does not depend on EI, so F/EI is the same at both (1e-3) and equals the
// continuum wire's 0.470968/z² within the rod's error plus the faceted wall's 1 %; fem_p1's force
// is the reference's within 1 % (both walls rigid); the shortcut "rigid lumen" is the rigid
// force. The solve kept in the outcome cache is read back (the same forces, marked cached), and
// results.json's object conforms to the schema.
TEST(GuidewireContactSlow, TheStraightSceneOnAStiffWallScalesWithEiAndIsReadBackFromTheCache) {
  Scene scene = shipped_scene("guidewire_straight.toml", {"fem_p1"}, 1e6);
  scene.load.guidewire->coupling = GuidewireCoupling::contact;
  scene.load.guidewire->stiffness_sweep = {4e-7, 4e-6};
  CachedContactOptions cached;
  const HarnessOptions& o = cached.options;
  const GuidewireContact first = solve_guidewire_contact(scene, GuidewireOutcome{}, o);
  ASSERT_EQ(first.solve.runs.size(), 2u);
  EXPECT_FALSE(first.provenance.cached);
  const double z = 20e-3;  // the scene's contact distance from the clamp
  double per_EI[2] = {0.0, 0.0};
  for (std::size_t k = 0; k < 2; ++k) {
    const contact::ContactModelsRun& run = first.solve.runs[k];
    const double EI = run.bending_stiffness;
    ASSERT_EQ(run.reference.failure, "") << run.reference.failure;
    ASSERT_EQ(run.models.size(), 1u);
    ASSERT_EQ(run.models[0].failure, "") << run.models[0].failure;
    const double F = run.reference.force, F_continuum = continuum_force(scene, EI);
    per_EI[k] = F / EI;
    std::printf(
        "GUIDEWIRE-CONTACT straight, wall x1e6, EI %g: F z^2/EI = %.6f (P2), %.6f "
        "(fem_p1), %.6f (rigid lumen), %.6f (continuum)\n",
        EI, F * z * z / EI, run.models[0].force * z * z / EI, run.rigid_force * z * z / EI,
        F_continuum * z * z / EI);
    EXPECT_NEAR(F_continuum * z * z / EI, 0.470968, 2e-6);
    const double rod_error = std::abs(run.rigid_force / F_continuum - 1.0);
    EXPECT_LT(std::abs(F / F_continuum - 1.0), rod_error + 1e-2);
    EXPECT_LT(std::abs(run.models[0].force / F - 1.0), 1e-2);
    ASSERT_FALSE(first.shortcuts[k].empty());
    EXPECT_EQ(first.shortcuts[k].front().name, "rigid lumen");
    EXPECT_EQ(first.shortcuts[k].front().force, run.rigid_force);
    EXPECT_TRUE(first.within_linear_validity(run));
  }
  EXPECT_NEAR(per_EI[1] / per_EI[0], 1.0, 1e-3);

  const GuidewireContact again = solve_guidewire_contact(scene, GuidewireOutcome{}, o);
  EXPECT_TRUE(again.provenance.cached);
  ASSERT_EQ(again.solve.runs.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(again.solve.runs[k].reference.force, first.solve.runs[k].reference.force);
    EXPECT_EQ(again.solve.runs[k].models[0].force, first.solve.runs[k].models[0].force);
    EXPECT_EQ(again.solve.runs[k].models[0].tip, first.solve.runs[k].models[0].tip);
  }

  const nlohmann::json results = nlohmann::json::parse(test::read_text(VESSEL_RESULTS_SCHEMA));
  const nlohmann::json contact_schema =
      results["properties"]["scenes"]["items"]["properties"]["guidewire"]["properties"]["contact"];
  ASSERT_TRUE(contact_schema.is_object());
  const nlohmann::json doc = guidewire_contact_json(again);
  EXPECT_EQ(test::schema_problems(doc, contact_schema), std::vector<std::string>{});
  EXPECT_EQ(doc["runs"].size(), 2u);
  EXPECT_TRUE(doc.contains("cached_from"));
  std::ostringstream md;
  write_guidewire_contact_markdown(md, again);
  EXPECT_NE(md.str().find("| fem_p1 |"), std::string::npos) << md.str();
  EXPECT_NE(md.str().find("| rigid lumen |"), std::string::npos) << md.str();
}

// The two formulations of the linearised contact on the straight scene's own wall (P1 on a mesh
// refined to h = 0.08 mm, EI 4e-7): the wire and the wall as one potential (an augmented
// Lagrangian, the tip also against the wall's faces) and the active set (exact on its final
// active set, the nodes alone) solve the same Signorini problem on the same candidates. They
// differ where the tip meets a face between nodes, a difference of the mesh's scale: measured at
// h = 0.12 / 0.1 / 0.08 / 0.06 mm, forces −0.43 / +0.09 / −0.23 / −0.03 % apart, centroids 0.060 /
// 0.032 / 0.015 / 0.011 mm, tips 0.013 / 0.015 / 0.006 / 0.005 mm. So at 0.08 mm: forces within
// 0.5 %, centroids within h / 2, tips within h / 4.
TEST(GuidewireContactSlow, ThePotentialAndTheActiveSetAgreeOnTheScenesWall) {
  const Scene scene = shipped_scene("guidewire_straight.toml", {});
  contact::ContactModelsOptions o;
  o.bending_stiffness = {4e-7};
  o.reference_degree = 1;
  o.fine_size = 0.08e-3;
  o.bearing_band_size = 0.0;
  const contact::ContactModelsRun potential = contact::solve_contact_models(scene, {}, o).runs[0];
  o.active_set = true;
  const contact::ContactModelsRun active = contact::solve_contact_models(scene, {}, o).runs[0];
  const contact::ModelContact &p = potential.reference, &a = active.reference;
  ASSERT_EQ(p.failure, "") << p.failure;
  ASSERT_EQ(a.failure, "") << a.failure;
  std::printf(
      "GUIDEWIRE-CONTACT straight, P1 wall, EI 4e-7: potential %.6f mN (%d pressed), active set "
      "%.6f mN (%d pressed): %+.2e; centroids %.4f mm, tips %.4f mm apart\n",
      p.force * 1e3, p.pressed, a.force * 1e3, a.pressed, p.force / a.force - 1.0,
      (p.centroid - a.centroid).norm() * 1e3, (p.tip - a.tip).norm() * 1e3);
  EXPECT_LT(std::abs(p.force / a.force - 1.0), 5e-3);
  EXPECT_LT((p.centroid - a.centroid).norm(), 0.5 * o.fine_size);
  EXPECT_LT((p.tip - a.tip).norm(), 0.25 * o.fine_size);
}

// A scene whose vessel is read from a file has no parametric lumen to refine around: refused,
// naming the file and what is expected.
TEST(GuidewireContact, AVesselThatIsNeitherTheTubeNorTheArchIsRefused) {
  Scene scene = read_scene(VESSEL_SCENES_DIR + "/guidewire_straight.toml");
  scene.vessel.kind = VesselKind::mesh_file;
  try {
    (void)contact::solve_contact_models(scene, {}, {});
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("guidewire_straight.toml"), std::string::npos) << what;
    EXPECT_NE(what.find("\"arch\""), std::string::npos) << what;
  }
}

// The reference's thread count is refused below one, naming the option and what is expected.
TEST(GuidewireContact, FewerThanOneReferenceThreadIsRefused) {
  const Scene scene = read_scene(VESSEL_SCENES_DIR + "/guidewire_straight.toml");
  contact::ContactModelsOptions o;
  o.reference_threads = 0;
  try {
    (void)contact::solve_contact_models(scene, {}, o);
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("reference_threads"), std::string::npos) << what;
    EXPECT_NE(what.find("at least 1"), std::string::npos) << what;
  }
}

// A linear wall dented deeper than it is thick cannot hold the wire: where the series springs
// put the reference's wall in by more (C_ref·F_ref from the run's coupling, here written by hand
// on either side of the 1 mm wall) the contact is not solved, and the run says why at that EI,
// in the scene's order, with the rigid lumen's force kept for the shortcuts. Nothing is solved
// when no EI can be (the test returns at once).
TEST(GuidewireContact, AnEiWhoseSeriesSpringsDentTheWallDeeperThanItIsThickIsNotSolved) {
  Scene scene = read_scene(VESSEL_SCENES_DIR + "/guidewire_straight.toml");
  ASSERT_EQ(scene.vessel.wall_thickness, 1e-3);
  scene.load.guidewire->stiffness_sweep = {4e-6};
  const double own = guidewire_stiffnesses(*scene.load.guidewire).front();
  GuidewireOutcome coupled;
  for (const auto& [EI, compliance, force] :
       std::vector<std::tuple<double, double, double>>{{own, 0.5, 2.1e-3}, {4e-6, 0.5, 2.8e-3}}) {
    GuidewireRigid r;
    r.bending_stiffness = EI;
    r.reference_compliance = compliance;  // m/N
    r.reference_force = force;            // N: 1.05 mm and 1.4 mm in
    r.solution.force = 1.1 * force;
    coupled.rigid.push_back(r);
  }
  const GuidewireContact c = solve_guidewire_contact(scene, coupled, HarnessOptions{});
  ASSERT_EQ(c.solve.runs.size(), 2u);
  EXPECT_NEAR(c.solve.runs[0].bending_stiffness, own, 1e-12 * own);
  EXPECT_DOUBLE_EQ(c.solve.runs[1].bending_stiffness, 4e-6);
  for (std::size_t k = 0; k < 2; ++k) {
    const std::string& why = c.solve.runs[k].reference.failure;
    EXPECT_NE(why.find("not solved"), std::string::npos) << why;
    EXPECT_NE(why.find(k == 0 ? "1.05 mm in under 2.100 mN" : "1.40 mm in under 2.800 mN"),
              std::string::npos)
        << why;
    EXPECT_NE(why.find("--own-equilibrium"), std::string::npos) << why;
    EXPECT_NE(why.find("contact_wall = \"neo-hookean\""), std::string::npos) << why;
    EXPECT_DOUBLE_EQ(c.solve.runs[k].rigid_force, coupled.rigid[k].solution.force);
    EXPECT_TRUE(c.solve.runs[k].models.empty());
  }
  EXPECT_EQ(c.shortcuts.size(), 2u);
  // The run's solve gives the reference wall's factorisations every core of the machine.
  EXPECT_EQ(c.options.reference_threads,
            static_cast<int>(std::max(1U, std::thread::hardware_concurrency())));
  EXPECT_FALSE(c.options.p2_from_p1);
}

// The scene's contact_p1_start reaches the run's contact-solve options (the P2 reference from
// P1's equilibrium); the options alone are built, nothing is solved.
TEST(GuidewireContact, AScenesP1StartReachesTheFiniteStrainReferencesOptions) {
  Scene scene = read_scene(VESSEL_SCENES_DIR + "/guidewire_straight.toml");
  scene.load.guidewire->contact_wall = ContactWall::neo_hookean;
  scene.load.guidewire->contact_p1_start = true;
  scene.load.guidewire->stiffness_sweep.clear();
  scene.load.guidewire->contact_at_own_stiffness_only = true;
  const contact::ContactModelsOptions o =
      guidewire_contact_options(scene, GuidewireOutcome{}, HarnessOptions{});
  EXPECT_TRUE(o.own_equilibrium);
  EXPECT_TRUE(o.p2_from_p1);
  scene.load.guidewire->contact_p1_start = false;
  EXPECT_FALSE(guidewire_contact_options(scene, GuidewireOutcome{}, HarnessOptions{}).p2_from_p1);
}

// contact_wall = "neo-hookean": the EI the linear wall refuses (series springs 1.4 mm into the
// 1 mm wall, hand-written) is solved, with the P2 reference the neo-Hookean wall and the surface
// model at their own equilibria, and read back from the outcome cache. On the wall made 10^4
// times stiffer (its dent ~0.1 µm, its strains far below any nonlinearity) the reference's force
// is the continuum wire's F·z²/EI = 0.470968 within the rod's own error plus the faceted wall's
// 1 %, and the run is judged (valid at any strain), its results.json object naming the wall and
// meeting the schema.
TEST(GuidewireContactSlow, ANeoHookeanContactWallSolvesTheEiALinearWallCannotHold) {
  Scene scene = shipped_scene("guidewire_straight.toml", {"surface_seed000"}, 1e4);
  scene.load.guidewire->coupling = GuidewireCoupling::contact;
  scene.load.guidewire->contact_wall = ContactWall::neo_hookean;
  *scene.load.guidewire = with_stiffness(*scene.load.guidewire, 4e-6);  // its one EI
  scene.load.guidewire->stiffness_sweep.clear();
  GuidewireRigid r;
  r.bending_stiffness = 4e-6;
  r.reference_compliance = 0.5;  // m/N
  r.reference_force = 2.8e-3;    // N: 1.4 mm in
  GuidewireOutcome coupled;
  coupled.rigid.push_back(r);
  CachedContactOptions cached;
  const HarnessOptions& o = cached.options;
  (void)solve_guidewire_contact(scene, coupled, o);
  // Read back from the cache: the surface model's wall has no tets, its strain NaN.
  const GuidewireContact c = solve_guidewire_contact(scene, coupled, o);
  EXPECT_TRUE(c.provenance.cached);
  ASSERT_EQ(c.solve.runs.size(), 1u);
  const contact::ContactModelsRun& run = c.solve.runs.front();
  ASSERT_EQ(run.models.size(), 1u);
  ASSERT_EQ(run.models[0].failure, "") << run.models[0].failure;
  EXPECT_EQ(run.models[0].linearisation, "own equilibrium");
  EXPECT_TRUE(std::isnan(run.models[0].strain));
  ASSERT_EQ(run.reference.failure, "") << run.reference.failure;
  EXPECT_EQ(run.reference.linearisation, "own equilibrium");
  EXPECT_NE(run.reference.detail.find("neo-Hookean"), std::string::npos) << run.reference.detail;
  EXPECT_NEAR(run.bending_stiffness, 4e-6, 1e-12);
  const double z = 20e-3, EI = 4e-6;
  const double F = run.reference.force, F_continuum = continuum_force(scene, EI);
  std::printf(
      "GUIDEWIRE-CONTACT straight, neo-Hookean wall x1e4, EI %g: F z^2/EI = %.6f (P2), "
      "%.6f (rigid lumen), %.6f (continuum), largest strain %.2e\n",
      EI, F * z * z / EI, run.rigid_force * z * z / EI, F_continuum * z * z / EI,
      run.reference.strain);
  const double rod_error = std::abs(run.rigid_force / F_continuum - 1.0);
  EXPECT_LT(std::abs(F / F_continuum - 1.0), rod_error + 1e-2);
  EXPECT_FALSE(c.beyond_its_reference(run));
  const nlohmann::json j = guidewire_contact_json(c);
  EXPECT_EQ(j.at("wall"), "neo-Hookean");
  const auto schema = nlohmann::json::parse(test::read_text(VESSEL_RESULTS_SCHEMA));
  const auto problems = test::schema_problems(j, schema.at("properties")
                                                     .at("scenes")
                                                     .at("items")
                                                     .at("properties")
                                                     .at("guidewire")
                                                     .at("properties")
                                                     .at("contact"));
  EXPECT_TRUE(problems.empty()) << test::joined(problems);
}

// At own equilibrium each EI after the first starts from the wall's equilibrium under the softer
// wire before it (the same mesh), through the rungs between (4e-6 from 4e-7 through 1.26e-6):
// the straight scene's P1 reference and volume_hybrid at EI 4e-7 and 4e-6 (the scene's wall,
// 0.16 mm mesh) reach the equilibria the solves from the wall at rest reach: on the same side of
// the wire's plane of symmetry, the same force (1e-6) and pressed nodes. The wire in the straight
// tube may settle on either side of that plane, on a mesh that is not symmetric: volume_hybrid at
// 4e-6 did (zone centroids 0.09 mm and 0.11 mm off it), its forces 0.2 % apart; across the plane
// the forces agree within 0.5 %.
TEST(GuidewireContactSlow, AStifferWireFromTheSofterWiresEquilibriumReachesItsOwnFromRest) {
  const Scene scene = shipped_scene("guidewire_straight.toml", {"volume_hybrid"});
  contact::ContactModelsOptions o;
  o.bending_stiffness = {4e-7, 4e-6};
  o.reference_degree = 1;
  o.fine_size = 0.16e-3;
  o.own_equilibrium = true;
  std::ostringstream log;
  o.log = &log;
  const contact::ContactModels chained = contact::solve_contact_models(scene, scene.models, o);
  const std::string chained_log = log.str();
  std::cerr << chained_log;
  // Each wall through the one rung between, none falling back to the wall at rest.
  const std::string rung = "EI 1.26491e-06 N·m² on the way";
  const auto first = chained_log.find(rung);
  ASSERT_NE(first, std::string::npos);
  EXPECT_NE(chained_log.find(rung, first + 1), std::string::npos);
  EXPECT_EQ(chained_log.find("solved again from the wall at rest"), std::string::npos);
  o.from_softer_wire = false;
  o.log = &std::cerr;
  const contact::ContactModels rest = contact::solve_contact_models(scene, scene.models, o);
  ASSERT_EQ(chained.runs.size(), 2u);
  for (std::size_t e = 0; e < 2; ++e) {
    const contact::ContactModelsRun &a = chained.runs[e], &b = rest.runs[e];
    ASSERT_EQ(a.models.size(), 1u);
    const std::vector<std::pair<const contact::ModelContact*, const contact::ModelContact*>> walls{
        {&a.reference, &b.reference}, {&a.models[0], &b.models[0]}};
    for (const auto& [x, y] : walls) {
      ASSERT_EQ(x->failure, "") << x->name;
      ASSERT_EQ(y->failure, "") << y->name;
      std::printf(
          "GUIDEWIRE-CONTACT %s at EI %g: %d steps from the softer wire, %d from rest; F %.6f / "
          "%.6f mN, centroid y %.4f / %.4f mm, %d / %d pressed\n",
          x->name.c_str(), a.bending_stiffness, x->steps, y->steps, x->force * 1e3, y->force * 1e3,
          x->centroid.y() * 1e3, y->centroid.y() * 1e3, x->pressed, y->pressed);
      EXPECT_EQ(x->from_softer_wire, e > 0) << x->name;
      EXPECT_FALSE(y->from_softer_wire);
      if (x->centroid.y() * y->centroid.y() > 0.0) {
        EXPECT_NEAR(x->force, y->force, 1e-6 * y->force)
            << x->name << " EI " << a.bending_stiffness;
        EXPECT_EQ(x->pressed, y->pressed) << x->name;
      } else {
        EXPECT_NEAR(x->force, y->force, 5e-3 * y->force)
            << x->name << " EI " << a.bending_stiffness;
      }
    }
  }
}

// The P2 reference's own equilibrium started from P1's on the same mesh (ContactModelsOptions::
// p2_from_p1) is the one P2 reaches alone from the rigid-lumen state: the straight scene's wire
// at EI 4e-7 on its wall (0.16 mm mesh), the same force (1e-6) and pressed nodes, the P1 start
// logged and not fallen back from.
TEST(GuidewireContactSlow, TheP2ReferenceFromP1sEquilibriumReachesTheOneP2ReachesAlone) {
  const Scene scene = shipped_scene("guidewire_straight.toml", {});
  contact::ContactModelsOptions o;
  o.bending_stiffness = {4e-7};
  o.fine_size = 0.16e-3;
  o.own_equilibrium = true;
  o.p2_from_p1 = true;
  ASSERT_EQ(o.reference_degree, 2);
  std::ostringstream log;
  o.log = &log;
  const contact::ContactModels from_p1 = contact::solve_contact_models(scene, {}, o);
  std::cerr << log.str();
  EXPECT_NE(log.str().find("P1's equilibrium: F"), std::string::npos);
  EXPECT_EQ(log.str().find("P2 from P1's equilibrium failed"), std::string::npos);
  o.p2_from_p1 = false;
  o.log = &std::cerr;
  const contact::ContactModels alone = contact::solve_contact_models(scene, {}, o);
  const contact::ModelContact& a = from_p1.runs.at(0).reference;
  const contact::ModelContact& b = alone.runs.at(0).reference;
  ASSERT_EQ(a.failure, "");
  ASSERT_EQ(b.failure, "");
  std::printf(
      "GUIDEWIRE-CONTACT P2 reference at EI 4e-7 from P1's equilibrium: F %.6f mN, %d pressed, %d "
      "steps (P1's included), %.1f s; alone: F %.6f mN, %d pressed, %d steps, %.1f s\n",
      a.force * 1e3, a.pressed, a.steps, a.solve_seconds, b.force * 1e3, b.pressed, b.steps,
      b.solve_seconds);
  EXPECT_NEAR(a.force, b.force, 1e-6 * b.force);
  EXPECT_EQ(a.pressed, b.pressed);
  EXPECT_NE(a.detail.find("from P1's equilibrium"), std::string::npos) << a.detail;
}

}  // namespace
}  // namespace vessel
