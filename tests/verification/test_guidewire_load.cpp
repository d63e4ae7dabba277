// The guidewire load: the scene's wire solved against the rigid lumen gives the contact patch
// (checked against the continuum references of fem_reference/rod_theory), bad keys are refused
// naming the file and key, and the compliant coupling meets the series-spring law with the
// wire's and the wall's compliances from separate solves.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>

#include "../schema_check.hpp"
#include "../test_helpers.hpp"
#include "fem_reference/rod_theory/tube_contact.hpp"
#include "meshes/foundation/errors.hpp"
#include "verification/guidewire/guidewire_load.hpp"
#include "verification/harness/guidewire_coupling.hpp"
#include "verification/scene.hpp"
#include "verification/scene_problems.hpp"

using namespace vessel;

namespace {

constexpr double kA = 3e-3;          // lumen radius
constexpr double kD = 0.356e-3;      // wire diameter
constexpr double kEI = 4e-7;         // N·m²
const double kE = kEI / (std::numbers::pi * std::pow(kD, 4) / 64.0);

std::string straight_scene(const std::string& load_extra, double insertion = 20.25e-3,
                           const std::string& vessel = "kind = \"straight\"") {
  return "name = \"g\"\n[vessel]\n" + vessel + "\nmesh = \"structured\"\nlevel = 0\n" +
         "[load]\ntype = \"guidewire\"\nE = " + std::to_string(kE) +
         "\ndiameter = 0.356e-3\ninsertion = " + std::to_string(insertion) + "\n" + load_extra +
         "\n[[models]]\nkind = \"fem\"\ndegree = 1\n";
}

/// The scene parsed, then its wire solved (as the run path does).
Scene solved_scene(const std::string& text) {
  Scene s = parse_scene(text, "wire.toml");
  solve_guidewire_load(s);
  return s;
}

std::string error_of(const std::string& text) {
  try {
    (void)solved_scene(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(GuidewireLoad, StraightTubeForceMatchesShootingAtTheTip) {
  const Scene s = solved_scene(straight_scene("tilt = 0.3"));
  ASSERT_EQ(s.load.kind, LoadKind::contact);
  ASSERT_EQ(s.load.magnitudes.size(), 1u);
  const GuidewireSolution& w = s.load.wire.value();
  EXPECT_EQ(w.contact_nodes, 1);
  // The continuum wire whose tip touches at the discrete wire's axial position z.
  const double c = kA - kD / 2, z = w.contact_point.z();
  const rod_theory::StraightTubeContact ref = rod_theory::straight_tube_contact(0.3, c / z);
  // Bounds at about 1.5x what the scene's 32 segments reach: 4.3e-4 and 4.2e-6.
  EXPECT_NEAR(s.load.magnitudes[0] / (ref.force * kEI / (z * z)), 1.0, 6.5e-4);
  EXPECT_NEAR(20.25e-3 / (ref.length * z), 1.0, 6.5e-6);
  // The patch's point is on the wall, pushed radially outward in the tilt's plane (+x).
  EXPECT_NEAR(std::hypot(w.wall_point.x(), w.wall_point.y()), kA, 1e-12);
  EXPECT_NEAR(w.normal.x(), 1.0, 1e-6);
  EXPECT_NEAR(s.load.contact.point.z(), z, 1e-15);
  EXPECT_NEAR(s.load.contact.radius, 0.5e-3, 0.0);
}

// The band a wire tilted 0.3 rad from the straight tube's axis at the inlet's centre may bear on
// (bearing_band), by hand: the straight wire along its clamp comes within 1.5 mm of the 3 mm wall
// where its distance from the axis, z·tan 0.3, reaches 1.5 mm (z = 4.83 mm); the rigid-lumen
// wire ends on the wall at its contact. Every point lies on the wall on the tilt's side (x > 0),
// at least 0.25 mm from every other, from z = 4.83 mm to the rigid contact.
TEST(GuidewireLoad, TheBearingBandRunsAlongTheWallFromWhereTheStraightWireNearsIt) {
  const Scene s = parse_scene(straight_scene("tilt = 0.3"), "wire.toml");
  const GuidewireSpec& spec = *s.load.guidewire;
  GuidewireSolver solver(s.vessel, spec);
  const GuidewireSolution rigid = solver.solve_rigid();
  const msm::rods::RodLayout layout =
      msm::rods::make_layout(guidewire_rod_spec(spec, spec.insertion));
  const std::vector<Vec3> band =
      bearing_band(s.vessel, spec, layout, solver.rod_state(), 1.5e-3, 0.25e-3);
  ASSERT_GT(band.size(), 10u);
  double z_lo = 1.0, z_hi = -1.0;
  for (std::size_t i = 0; i < band.size(); ++i) {
    const Vec3& p = band[i];
    EXPECT_NEAR(std::hypot(p.x(), p.y()), kA, 1e-12);
    EXPECT_GT(p.x(), 0.0);
    for (std::size_t j = 0; j < i; ++j) EXPECT_GE((p - band[j]).norm(), 0.25e-3);
    z_lo = std::min(z_lo, p.z());
    z_hi = std::max(z_hi, p.z());
  }
  EXPECT_NEAR(z_lo, 1.5e-3 / std::tan(0.3), 0.25e-3);
  EXPECT_NEAR(z_hi, rigid.wall_point.z(), 0.25e-3);
}

TEST(GuidewireLoad, ArchApexForceMatchesQuarterWaveElastica) {
  const double R = 15e-3;
  const rod_theory::ArchApexContact ref = rod_theory::arch_apex_contact((R + kA - kD / 2) / R);
  const Scene s =
      solved_scene(straight_scene("", ref.length * R, "kind = \"arch\"\nbend_radius = 15e-3"));
  const GuidewireSolution& w = s.load.wire.value();
  EXPECT_EQ(w.contact_nodes, 1);  // no second contact
  // Bounds at about 1.5x what the scene's 32 segments reach: 1.4e-5 rad, 5.6e-4.
  EXPECT_NEAR(std::atan2(w.contact_point.y(), w.contact_point.x()), std::numbers::pi / 2, 2.2e-5);
  EXPECT_NEAR(s.load.magnitudes[0] / (ref.force * kEI / (R * R)), 1.0, 8.5e-4);
  EXPECT_NEAR(w.wall_point.norm(), R + kA, 1e-12);  // the outer wall at the apex
}

TEST(GuidewireLoad, ClampReactionBalancesTheWallForce) {
  // DER and XPBD (whose constraints are compliant energy terms): the energy's gradient at the
  // held nodes; CORDE: plus its inextensibility multipliers' force there (without them the
  // balance misses by the constraint force).
  for (const char* model : {"der", "corde", "xpbd"}) {
    SCOPED_TRACE(model);
    const Scene s =
        solved_scene(straight_scene(std::string("tilt = 0.3\nmodel = \"") + model + "\""));
    const GuidewireSolution& w = s.load.wire.value();
    // The clamp holds the wire against the wall's push −F n; the wire pushes the wall by F n,
    // the patch's total load. Σ of the wire's clamp reaction and the wall's load on the wire: 0.
    ASSERT_GT(w.force, 0.0);
    EXPECT_LT((w.clamp_force - w.force * w.normal).norm(), 1e-9);
  }
}

TEST(GuidewireLoad, BadKeysAreRefusedNamingFileAndKey) {
  EXPECT_NE(error_of(straight_scene("tilt = 0.3\nnu = 0.3\nG = 1e9")).find("load.nu"),
            std::string::npos);
  const std::string short_wire = error_of(straight_scene("tilt = 0.3", 5e-3));
  EXPECT_NE(short_wire.find("wire.toml"), std::string::npos) << short_wire;
  EXPECT_NE(short_wire.find("load.insertion"), std::string::npos) << short_wire;
  EXPECT_NE(short_wire.find("does not reach the wall"), std::string::npos) << short_wire;
  EXPECT_NE(error_of(straight_scene("clamp_point = [0, 0, 0]")).find("load.clamp_direction"),
            std::string::npos);
  EXPECT_NE(error_of(straight_scene("tilt = 0.3\ntilt_towards = [0, 0, 1]")).find("load.tilt_towards"),
            std::string::npos);
  EXPECT_NE(error_of(straight_scene("tilt = 0.3\nsegments = 2")).find("load.segments"),
            std::string::npos);
  EXPECT_NE(error_of(straight_scene("tilt = 0.3\ncoupling = \"soft\"")).find("load.coupling"),
            std::string::npos);
  EXPECT_NE(error_of(straight_scene("tilt = 0.3\nstiffness_sweep = [1e-6]")).find("load.stiffness_sweep"),
            std::string::npos);
  const std::string outside = error_of(straight_scene("clamp_point = [0, 2.9e-3, 0]\nclamp_direction = [0, 0, 1]"));
  EXPECT_NE(outside.find("load.clamp_point"), std::string::npos) << outside;
  // A wire lying along the wall touches it at several nodes: refused, not averaged.
  const std::string lying = error_of(straight_scene("tilt = 0.3", 38e-3));
  EXPECT_NE(lying.find("load.insertion"), std::string::npos) << lying;
}

TEST(GuidewireCoupling, SeriesSpringsWithCompliancesFromSeparateSolves) {
  const Scene s = parse_scene(straight_scene("tilt = 0.3"), "wire.toml");
  GuidewireSolver solver(s.vessel, *s.load.guidewire);
  const double F_rigid = solver.solve_rigid().force;
  // The wire's compliance from its own solves against a wall moved by ±δ.
  const double d = 1e-6;
  const double Cr = -2.0 * d / (solver.solve_with_give(d).force - solver.solve_with_give(-d).force);
  (void)solver.solve_rigid();
  for (const double ratio : {0.01, 0.03, 0.07}) {
    const double Cv = ratio * Cr;  // δ = Cv·F stays ≪ the wire's deflection: the linear regime
    const double F = solver.coupled_force(Cv);
    std::printf("GUIDEWIRE series Cv/Cr %.2f: coupled %.9e N, F_rigid Cr/(Cr + Cv) %.9e N\n",
                ratio, F, F_rigid * Cr / (Cr + Cv));
    EXPECT_NEAR(F / (F_rigid * Cr / (Cr + Cv)), 1.0, 1e-3) << "Cv/Cr = " << ratio;
    // And the coupled state is an equilibrium of both springs: the wall gave Cv·F.
    EXPECT_NEAR(solver.solve_with_give(Cv * F).force / F, 1.0, 1e-9);
  }
}

/// The continuum wire's tip force at fixed length L against a tube of centreline offset c:
/// the tip's axial position z solves L = (L/z)(c/z)·z (shooting's length, secant on z).
double continuum_force(double theta, double c, double L) {
  double z0 = 0.98 * L, z1 = 0.99 * L;
  const auto miss = [&](double z) { return rod_theory::straight_tube_contact(theta, c / z).length * z - L; };
  double m0 = miss(z0), m1 = miss(z1);
  for (int it = 0; it < 50 && std::abs(m1) > 1e-15; ++it) {
    const double z2 = z1 - m1 * (z1 - z0) / (m1 - m0);
    z0 = z1;
    m0 = m1;
    z1 = z2;
    m1 = miss(z1);
  }
  return rod_theory::straight_tube_contact(theta, c / z1).force * kEI / (z1 * z1);
}

TEST(GuidewireCoupling, WireComplianceMatchesTheContinuumWire) {
  const Scene s = parse_scene(straight_scene("tilt = 0.3"), "wire.toml");
  GuidewireSolver solver(s.vessel, *s.load.guidewire);
  (void)solver.solve_rigid();
  const double Cr = solver.compliance();
  const double c = kA - kD / 2, d = 1e-3 * c, L = 20.25e-3;
  const double Cr_continuum =
      -2.0 * d / (continuum_force(0.3, c + d, L) - continuum_force(0.3, c - d, L));
  std::printf("GUIDEWIRE straight tube wire compliance %.6f m/N, continuum %.6f m/N\n", Cr,
              Cr_continuum);
  EXPECT_NEAR(Cr / Cr_continuum, 1.0, 1e-2);
}

TEST(GuidewireCoupling, RowsPerModelAndStiffnessFromTheOutcomesIndentation) {
  Scene s = solved_scene(straight_scene("tilt = 0.3\ncoupling = \"compliant\"\n"
                                       "stiffness_sweep = [4e-7, 4e-6, 4e-5]"));
  const double F = s.load.magnitudes[0];
  // Two walls seen through their indentation under the rigid wire's force: the model twice as
  // compliant as the reference. C = 0.5 m/N is the straight tube's order of magnitude.
  ModelOutcome o;
  o.model = "m";
  o.ok = true;
  o.magnitude = F;
  o.quantities.indentation_mm = 1.0 * F * 1e3;
  o.quantities.indentation_reference_mm = 0.5 * F * 1e3;
  // Its whole field twice the reference's at the same load: |u − u_ref| = |u_ref|, |u| = 2|u_ref|.
  o.error.relative_l2 = 1.0;
  o.error.model_l2_over_reference = 2.0;
  const GuidewireOutcome g = couple_guidewire(s, {o});
  ASSERT_EQ(g.rigid.size(), 3u);
  ASSERT_EQ(g.rows.size(), 3u);
  for (std::size_t k = 0; k < g.rows.size(); ++k) {
    const GuidewireCouplingRow& r = g.rows[k];
    ASSERT_TRUE(r.ok) << r.failure;
    EXPECT_NEAR(r.wall_compliance, 1.0, 1e-12);
    EXPECT_NEAR(r.reference_compliance, 0.5, 1e-12);
    // The softer wall takes less force; both below the rigid wire's.
    EXPECT_LT(r.force_mN, r.reference_force_mN);
    EXPECT_LT(r.reference_force_mN, g.rigid[k].solution.force * 1e3);
    EXPECT_NEAR(r.displacement_mm, r.wall_compliance * r.force_mN, 1e-12);
    // Each wall under its own force: 2 u_ref F/F_rigid against u_ref F_ref/F_rigid, a relative
    // error |2 F/F_ref − 1|, below the rigid force's 1 since the softer wall takes less force.
    EXPECT_EQ(r.field_relative_l2_rigid, 1.0);
    EXPECT_NEAR(r.field_relative_l2, std::abs(2.0 * r.force_mN / r.reference_force_mN - 1.0), 1e-9);
    EXPECT_LT(r.field_relative_l2, 1.0);
  }
  // A stiffer wire is closer to displacement control: its force falls further below the rigid one.
  EXPECT_LT(g.rows[2].force_mN / (g.rigid[2].solution.force * 1e3),
            g.rows[1].force_mN / (g.rigid[1].solution.force * 1e3));
  // The reference's dent C_ref·F_ref against the wall's 1 mm. The springs keep
  // F_ref = F_rigid·C_r/(C_r + C_ref), C_r the wire's compliance (6.95 m/N at EI 4e-7, a tenth
  // per decade of EI) and F_rigid 0.471 mN × EI/4e-7: by hand 0.439 / 2.74 / 5.75 mN, dents 0.22 /
  // 1.37 / 2.87 mm. The stiff wires' rows dent the wall deeper than it is thick and are marked.
  ASSERT_DOUBLE_EQ(s.vessel.wall_thickness, 1e-3);
  const nlohmann::json rows = guidewire_json(g)["coupling_rows"];
  const std::vector<bool> within{true, false, false};
  std::ostringstream md;
  write_guidewire_markdown(md, g);
  for (std::size_t k = 0; k < g.rows.size(); ++k) {
    EXPECT_EQ(rows[k]["reference_within_wall"].get<bool>(), within[k])
        << "EI " << g.rows[k].bending_stiffness;
  }
  const std::string text = md.str();
  std::size_t marked = 0;
  for (auto at = text.find(" ✗ |"); at != std::string::npos; at = text.find(" ✗ |", at + 1))
    ++marked;
  EXPECT_EQ(marked, 2u) << text;
}

TEST(GuidewireResults, CentrelineRunsFromTheScenesClampToTheContactPointOnTheWall) {
  const Scene s = solved_scene(straight_scene("tilt = 0.3\ncoupling = \"compliant\""));
  ModelOutcome o;  // a wall twice as compliant as the reference's (as above)
  o.model = "m";
  o.ok = true;
  o.magnitude = s.load.magnitudes[0];
  o.quantities.indentation_mm = 1.0 * o.magnitude * 1e3;
  o.quantities.indentation_reference_mm = 0.5 * o.magnitude * 1e3;
  const nlohmann::json g = guidewire_json(couple_guidewire(s, {o}));
  const auto schema = nlohmann::json::parse(test::read_text(VESSEL_RESULTS_SCHEMA));
  const auto problems = test::schema_problems(
      g, schema["properties"]["scenes"]["items"]["properties"]["guidewire"]);
  EXPECT_TRUE(problems.empty()) << test::joined(problems);
  const nlohmann::json& rigid = g["rigid"][0];
  const nlohmann::json& line = rigid["centreline_mm"];
  ASSERT_EQ(line.size(), 33u);  // the scene's 32 segments: clamp node to tip
  // The scene's clamp (tilt form on a straight tube: the inlet's centre, the origin).
  EXPECT_EQ(line.front(), nlohmann::json({0.0, 0.0, 0.0}));
  // Its tip is the contact point, on the lumen less the wire's radius: 3 − 0.178 mm off the axis,
  // in the tilt's plane (+x).
  EXPECT_EQ(line.back(), rigid["contact_point_mm"]);
  const auto radial = [](const nlohmann::json& p) {
    return std::hypot(p[0].get<double>(), p[1].get<double>());
  };
  EXPECT_NEAR(radial(line.back()), 3.0 - 0.178, 1e-9);
  EXPECT_NEAR(line.back()[1].get<double>(), 0.0, 1e-9);
  EXPECT_GT(line.back()[0].get<double>(), 0.0);
  // Every node inside the lumen.
  for (const auto& p : line) EXPECT_LE(radial(p), 3.0 - 0.178 + 1e-9);
  // The wire coupled with the reference's wall (C_ref = 0.5 m/N) touches the lumen grown by
  // its give C_ref·F_ref.
  const nlohmann::json& ref = rigid["reference_coupled"];
  ASSERT_TRUE(ref.is_object());
  EXPECT_EQ(ref["row"], "m, ν 0, level 0");
  const double F = ref["contact_force_N"].get<double>();
  EXPECT_LT(F, rigid["contact_force_N"].get<double>());
  EXPECT_EQ(ref["centreline_mm"].front(), nlohmann::json({0.0, 0.0, 0.0}));
  EXPECT_NEAR(radial(ref["centreline_mm"].back()), 3.0 - 0.178 + 0.5 * F * 1e3, 1e-9);
  // Rigid coupling: no reference-coupled wire.
  const Scene r = solved_scene(straight_scene("tilt = 0.3"));
  EXPECT_TRUE(guidewire_json(couple_guidewire(r, {o}))["rigid"][0]["reference_coupled"].is_null());
}

}  // namespace
