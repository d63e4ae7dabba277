// Vessels from files in scenes (issue 15 item 1): `[vessel] file = "x.msh"` and `lumen = "x.stl"`,
// paths relative to the scene, levels, refusals, and contact points projected onto the wall.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "../lumen_fixture.hpp"
#include "../test_helpers.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/mesh_cache.hpp"
#include "meshes/msh_io.hpp"
#include "verification/scene.hpp"
#include "verification/scene_problems.hpp"

using namespace vessel;
using vessel::test::TempDir;
using vessel::test::write_text;

namespace {

constexpr double kA = 3e-3, kT = 1e-3, kL = 20e-3;
constexpr int kSides = 16;

std::string scene_text(const std::string& vessel, const std::string& load) {
  return "name = \"file_vessel\"\n[vessel]\n" + vessel + "\n[load]\n" + load +
         "\n[[models]]\nkind = \"fem\"\ndegree = 1\n";
}

const std::string kContactOuter =
    "type = \"contact\"\nmagnitudes = [1e-4]\npoint = [8e-3, 0, 10e-3]\nsurface = \"outer_wall\"";

std::string error_of(const std::filesystem::path& file) {
  try {
    (void)read_scene(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// A temp dir holding tube.stl (a 16-gon tube, a vertex at θ = 0) and its wall as tube.msh.
struct Files {
  TempDir dir;
  Files() {
    std::filesystem::create_directories(dir / "vessels");
    write_stl(dir / "vessels" / "tube.stl", test::polygon_tube(kA, kL, kSides, 8), StlFormat::ascii);
    VesselParams p;
    p.kind = VesselKind::lumen;
    p.file = dir / "vessels" / "tube.stl";
    p.wall_thickness = kT;
    write_msh(dir / "vessels" / "tube.msh", load_or_generate_vessel(p, {}, {}));
  }
};

}  // namespace

TEST(FileVessel, LumenPathsResolveAgainstTheSceneFolderAndLevelsRefine) {
  Files f;
  write_text(f.dir / "s.toml", scene_text("lumen = \"vessels/tube.stl\"\nwall_thickness = 1e-3\n"
                                          "level = [0, 1]\nreference_level = 1",
                                          kContactOuter));
  const Scene s = read_scene(f.dir / "s.toml");
  EXPECT_EQ(s.vessel.kind, VesselKind::lumen);
  EXPECT_EQ(s.vessel.file, f.dir / "vessels" / "tube.stl");
  EXPECT_EQ(s.model_levels, (std::vector<int>{0, 1}));
  const TetMesh m0 = scene_mesh(s, 0, {});
  const TetMesh m1 = scene_mesh(s, 1, {});
  EXPECT_EQ(m1.tets.size(), 8 * m0.tets.size());  // 4× the triangles, 2× the layers
}

TEST(FileVessel, AContactPointIsProjectedOntoTheChosenWall) {
  Files f;
  write_text(f.dir / "s.toml", scene_text("lumen = \"vessels/tube.stl\"\nwall_thickness = 1e-3",
                                          kContactOuter));
  const Scene s = read_scene(f.dir / "s.toml");
  const TetMesh mesh = scene_mesh(s, 0, {});
  const Scene r = resolve_file_vessel(s, mesh);
  // From (8, 0, 10) mm, along the 16-gon's vertex line at θ = 0: the outer wall's nearest point
  // is that vertex line at radius a + t (the vertex normals of a regular prism are radial).
  EXPECT_NEAR((r.load.contact.point - Vec3(kA + kT, 0.0, 10e-3)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((qoi_point(r) - r.load.contact.point).norm(), 0.0, 0.0);
  // On the inner wall from the axis side, towards the middle of a face: that face's chord
  // midpoint, at radius a·cos(π/16).
  const double half = std::numbers::pi / kSides;
  const Vec3 towards(std::cos(half), std::sin(half), 0.0);
  Scene inner = s;
  inner.load.contact.surface_group = "inner_wall";
  inner.load.contact.point = 0.5e-3 * towards + Vec3(0.0, 0.0, 10e-3);
  const Vec3 p = resolve_file_vessel(inner, mesh).load.contact.point;
  EXPECT_NEAR((p - (kA * std::cos(half) * towards + Vec3(0.0, 0.0, 10e-3))).norm(), 0.0, 1e-12);
  // The patch is built around the projected point, on the outer wall.
  const TractionPatch patch = scene_contact_patch(r.load, mesh, 1e-4);
  EXPECT_NEAR((patch.centre - r.load.contact.point).norm(), 0.0, 1e-12);
  // A parametric vessel's scene is left alone.
  Scene straight;
  straight.load.contact.point = Vec3(1.0, 2.0, 3.0);
  EXPECT_EQ(resolve_file_vessel(straight, mesh).load.contact.point, Vec3(1.0, 2.0, 3.0));
}

TEST(FileVessel, APressureSceneReadsItsQoiOnTheInnerWall) {
  Files f;
  write_text(f.dir / "s.toml",
             scene_text("file = \"vessels/tube.msh\"", "type = \"pressure\"\nmagnitudes = [10]"));
  const Scene s = read_scene(f.dir / "s.toml");
  EXPECT_EQ(s.vessel.kind, VesselKind::mesh_file);
  const TetMesh mesh = scene_mesh(s, 0, {});
  const Vec3 q = qoi_point(resolve_file_vessel(s, mesh));
  // The nodes' centroid is on the axis at mid-length: the nearest inner-wall points are the chord
  // midpoints at radius a·cos(π/16).
  EXPECT_NEAR(std::hypot(q.x(), q.y()), kA * std::cos(std::numbers::pi / kSides), 1e-12);
  EXPECT_NEAR(q.z(), kL / 2, 1e-12);
}

TEST(FileVessel, AMeshFileWithoutThicknessGetsItsMeasuredThickness) {
  Files f;
  write_text(f.dir / "s.toml",
             scene_text("file = \"vessels/tube.msh\"", kContactOuter) +
                 "[[models]]\nname = \"shell\"\nkind = \"surface_msm\"\nsurface = \"inner\"\n");
  const Scene s = read_scene(f.dir / "s.toml");
  EXPECT_EQ(s.vessel.wall_thickness, 0.0);
  const TetMesh mesh = scene_mesh(s, 0, {});
  const msm::BuiltNetwork built = scene_network(s, s.models[1], mesh, s.vessel, 0.45);
  EXPECT_NEAR(built.network.thickness, kT, 1e-12);  // outer-wall vertices sit t from the lumen
}

TEST(FileVessel, RefusesLevelsOfAMeshFile) {
  Files f;
  write_text(f.dir / "s.toml", scene_text("file = \"vessels/tube.msh\"\nlevel = [0, 1]", kContactOuter));
  const std::string msg = error_of(f.dir / "s.toml");
  EXPECT_NE(msg.find("s.toml:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("key 'vessel.level': found a level other than 0 with a mesh file"),
            std::string::npos)
      << msg;
}

TEST(FileVessel, RefusesBadVesselTables) {
  Files f;
  const auto refusal = [&](const std::string& vessel) {
    write_text(f.dir / "s.toml", scene_text(vessel, kContactOuter));
    return error_of(f.dir / "s.toml");
  };
  EXPECT_NE(refusal("lumen = \"vessels/tube.stl\"").find("key 'vessel.wall_thickness': missing"),
            std::string::npos);
  EXPECT_NE(refusal("lumen = \"vessels/none.stl\"\nwall_thickness = 1e-3")
                .find("not found"),
            std::string::npos);
  EXPECT_NE(refusal("file = \"vessels/tube.msh\"\nlumen = \"vessels/tube.stl\"").find("expected one of them"),
            std::string::npos);
  EXPECT_NE(refusal("lumen = \"vessels/tube.stl\"\nwall_thickness = 1e-3\nunits = \"inch\"")
                .find("vessel.units"),
            std::string::npos);
  EXPECT_NE(refusal("lumen = \"vessels/tube.stl\"\nwall_thickness = 1e-3\ninner_radius = 3e-3")
                .find("unknown key"),
            std::string::npos);
}

TEST(FileVessel, AMillimetreLumenIsRefusedUnlessItsUnitsAreGiven) {
  Files f;
  write_stl(f.dir / "mm.stl", test::polygon_tube(3.0, 20.0, 12, 4));
  write_text(f.dir / "s.toml", scene_text("lumen = \"mm.stl\"\nwall_thickness = 1e-3", kContactOuter));
  const Scene s = read_scene(f.dir / "s.toml");
  try {
    (void)scene_mesh(s, 0, {});
    FAIL() << "millimetres accepted as metres";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mm.stl: the lumen's bounding box"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("looks like millimetres"), std::string::npos);
  }
  write_text(f.dir / "s.toml",
             scene_text("lumen = \"mm.stl\"\nwall_thickness = 1e-3\nunits = \"mm\"", kContactOuter));
  EXPECT_GT(scene_mesh(read_scene(f.dir / "s.toml"), 0, {}).tets.size(), 0u);
}

TEST(FileVessel, RollerEndsAndDefaultContactPointsAreRefused) {
  VesselParams v;
  v.kind = VesselKind::lumen;
  v.file = "x.stl";
  v.wall_thickness = 1e-3;
  EXPECT_THROW((void)default_contact_point(v, "inner_wall"), InputError);
  EXPECT_THROW((void)end_supports(v, {{"inlet", EndCondition::roller}}, "s.toml"), InputError);
  EXPECT_THROW((void)centreline_coordinates(v, Vec3::Zero()), InputError);
}
