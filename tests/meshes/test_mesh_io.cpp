// .msh, STL and VTU input/output: round trips, files written by gmsh itself, and bad input.
#include <gmsh.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "../test_helpers.hpp"
#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/mesh_cache.hpp"
#include "meshes/msh_io.hpp"
#include "meshes/stl_io.hpp"
#include "meshes/vtu_io.hpp"

using namespace vessel;
using vessel::test::TempDir;
using vessel::test::read_text;
using vessel::test::write_text;

namespace {

/// The message of the InputError that `f` throws ("" if none).
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const TetMesh& level0_tube() {
  static const TetMesh mesh = generate_vessel_mesh(VesselParams{});
  return mesh;
}

void expect_same_mesh(const TetMesh& a, const TetMesh& b) {
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (std::size_t i = 0; i < a.nodes.size(); ++i) ASSERT_EQ(a.nodes[i], b.nodes[i]) << i;
  ASSERT_EQ(a.tets, b.tets);
  ASSERT_EQ(a.groups.size(), b.groups.size());
  for (const auto& g : a.groups) {
    const auto* h = b.find_group(g.name, g.dim);
    ASSERT_NE(h, nullptr) << g.name;
    EXPECT_EQ(g.tag, h->tag);
    if (g.dim == 2) EXPECT_EQ(a.group_triangles(g), b.group_triangles(*h)) << g.name;
    EXPECT_EQ(g.elements.size(), h->elements.size()) << g.name;
  }
}

/// A single tet with two named groups, in msh 2.2.
const char* kOneTet22 = R"($MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
2
2 1 "inlet"
3 10 "wall"
$EndPhysicalNames
$Nodes
4
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1
$EndNodes
$Elements
2
1 2 2 1 1 1 3 2
2 4 2 10 10 1 2 3 4
$EndElements
)";

/// Five nodes and two tets in msh 2.2: element 7 is 1 2 3 4 (V = +1/6, hand-derived: the unit
/// corner tet) and element 8 is `second` (node 5 at `node5`). With node 5 at (1, 1, 1),
/// "2 3 4 5" has V = +1/3 ((b−a)·((c−a)×(d−a))/6 = 2/6) and "2 3 5 4" V = −1/3.
std::string two_tets22(const std::string& second, const std::string& node5 = "1 1 1") {
  return "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n"
         "4 0 0 1\n5 " + node5 + "\n$EndNodes\n$Elements\n2\n7 4 2 10 10 1 2 3 4\n"
         "8 4 2 10 10 " + second + "\n$EndElements\n";
}

/// The 1-based line of `text` that starts with `start`.
int line_of(const std::string& text, const std::string& start) {
  const auto at = text.find("\n" + start);
  return 2 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

}  // namespace

TEST(MshIo, TwoPositiveTetsAreReadWithTheirHandDerivedVolume) {
  TempDir dir;
  write_text(dir / "ok.msh", two_tets22("2 3 4 5"));
  EXPECT_DOUBLE_EQ(mesh_volume(read_msh(dir / "ok.msh")), 1.0 / 6.0 + 1.0 / 3.0);
}

TEST(MshIo, InvertedTetIsRefusedNamingFileLineElementAndSignedVolume) {
  TempDir dir;
  const std::string text = two_tets22("2 3 5 4");
  write_text(dir / "inverted.msh", text);
  const auto msg = input_error([&] { (void)read_msh(dir / "inverted.msh"); });
  const std::string where =
      (dir / "inverted.msh").string() + ":" + std::to_string(line_of(text, "8 4 ")) + ": element 8";
  EXPECT_NE(msg.find(where), std::string::npos) << msg;
  EXPECT_NE(msg.find("inverted"), std::string::npos) << msg;
  EXPECT_NE(msg.find("signed volume -0.3333 m³"), std::string::npos) << msg;
  // mean |V| = (1/6 + 1/3)/2 = 1/4, so the ratio is −4/3.
  EXPECT_NE(msg.find("-1.33 × the mean tet volume"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected a positive volume"), std::string::npos) << msg;
  EXPECT_NE(msg.find("1 of 2 tets"), std::string::npos) << msg;
}

TEST(MshIo, FlatTetIsRefusedAsZeroVolume) {
  TempDir dir;
  // Node 5 at (1, 1, 0) lies in the plane z = 0 of nodes 1, 2, 3: "1 2 3 5" is flat, V = 0.
  const std::string text = two_tets22("1 2 3 5", "1 1 0");
  write_text(dir / "flat.msh", text);
  const auto msg = input_error([&] { (void)read_msh(dir / "flat.msh"); });
  EXPECT_NE(msg.find("flat.msh:" + std::to_string(line_of(text, "8 4 ")) + ": element 8"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("zero volume"), std::string::npos) << msg;
  EXPECT_NE(msg.find("signed volume 0 m³"), std::string::npos) << msg;
  EXPECT_NE(msg.find("coplanar"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected a positive volume"), std::string::npos) << msg;
}

TEST(MshIo, NearlyFlatTetBelowTheRelativeToleranceIsRefusedAndASliverAboveItRead) {
  TempDir dir;
  // Node 5 lifted h above the plane z = 0: "1 2 3 5" has V = h/6 exactly and longest edge √2, so
  // it is zero below h = 6·1e-12·2√2 ≈ 1.7e-11 and a (terrible but valid) sliver above.
  write_text(dir / "flat.msh", two_tets22("1 2 3 5", "1 1 1e-12"));
  EXPECT_NE(input_error([&] { (void)read_msh(dir / "flat.msh"); }).find("zero volume"),
            std::string::npos);
  write_text(dir / "sliver.msh", two_tets22("1 2 3 5", "1 1 1e-9"));
  EXPECT_NEAR(mesh_volume(read_msh(dir / "sliver.msh")), 1.0 / 6.0 + 1e-9 / 6.0, 1e-15);
}

TEST(MshIo, CoincidentNodesAreRefusedNamingTheNodes) {
  TempDir dir;
  // Node 5 at node 4's position (0, 0, 1): "2 3 4 5" has zero volume.
  const std::string text = two_tets22("2 3 4 5", "0 0 1");
  write_text(dir / "coincident.msh", text);
  const auto msg = input_error([&] { (void)read_msh(dir / "coincident.msh"); });
  EXPECT_NE(msg.find(":" + std::to_string(line_of(text, "8 4 ")) + ": element 8"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("zero volume"), std::string::npos) << msg;
  EXPECT_NE(msg.find("node 4 and node 5 coincide at (0, 0, 1) m"), std::string::npos) << msg;
}

TEST(MshIo, InvertedTetInMsh41IsRefusedWithItsLine) {
  TempDir dir;
  const std::string text =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 5 1 5\n3 1 0 5\n1\n2\n3\n4\n5\n"
      "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n$EndNodes\n$Elements\n1 2 1 2\n3 1 4 2\n"
      "11 1 2 3 4\n12 2 3 5 4\n$EndElements\n";
  write_text(dir / "inv41.msh", text);
  const auto msg = input_error([&] { (void)read_msh(dir / "inv41.msh"); });
  EXPECT_NE(msg.find("inv41.msh:" + std::to_string(line_of(text, "12 2 3 5 4")) + ": element 12"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("signed volume -0.3333 m³"), std::string::npos) << msg;
}

TEST(MshIo, AFileWhoseTetsAreAllNegativeIsAConventionAndIsFlipped) {
  TempDir dir;
  // Both tets listed with negative volume: a consistent convention, not inverted elements.
  std::string neg = two_tets22("2 3 5 4");
  neg.replace(neg.find("1 2 3 4"), 7, "1 2 4 3");
  write_text(dir / "neg.msh", neg);
  const TetMesh mesh = read_msh(dir / "neg.msh");
  EXPECT_DOUBLE_EQ(mesh_volume(mesh), 0.5);
  // With the majority negative, the one positive tet is the inverted one; quoted in the file's sign.
  write_text(dir / "mixed.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n6\n1 0 0 0\n"
                                "2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n6 0 0 -1\n$EndNodes\n"
                                "$Elements\n3\n7 4 2 10 10 1 2 4 3\n8 4 2 10 10 2 3 5 4\n"
                                "9 4 2 10 10 1 3 2 6\n$EndElements\n");
  const auto msg = input_error([&] { (void)read_msh(dir / "mixed.msh"); });
  EXPECT_NE(msg.find("element 9"), std::string::npos) << msg;
  EXPECT_NE(msg.find("signed volume 0.1667 m³"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected a negative volume"), std::string::npos) << msg;
}

TEST(TetVolumes, InMemoryMeshNamesTheTetIndexWithoutAFile) {
  TetMesh mesh;
  mesh.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 1)};
  mesh.tets = {{0, 1, 2, 3}, {1, 2, 3, 4}};  // +1/6 and +1/3 (hand-derived)
  EXPECT_NO_THROW(require_positive_volumes(mesh, "in-memory"));
  mesh.tets[1] = {1, 2, 4, 3};  // −1/3
  const auto msg = input_error([&] { require_positive_volumes(mesh, "in-memory"); });
  EXPECT_NE(msg.find("in-memory: tetrahedron 1 (0-based, of 2) is inverted: signed volume "
                     "-0.3333 m³"),
            std::string::npos)
      << msg;
}

TEST(MshIo, RoundTripV41IsExact) {
  TempDir dir;
  write_msh(dir / "tube.msh", level0_tube(), MshVersion::v41);
  expect_same_mesh(level0_tube(), read_msh(dir / "tube.msh"));
}

TEST(MshIo, RoundTripV22IsExact) {
  TempDir dir;
  write_msh(dir / "tube.msh", level0_tube(), MshVersion::v22);
  expect_same_mesh(level0_tube(), read_msh(dir / "tube.msh"));
}

// The generated mesh a run uses must be the mesh a later run reads from the cache, element for
// element: the FEM solution cache keys on the triangles' order, and a second run of
// pressure_lame's level-1 structured tube missed it when the generated order was used.
TEST(MeshCache, AGeneratedMeshIsTheMeshTheCacheGivesBackElementForElement) {
  TempDir dir;
  VesselParams p;
  p.style = MeshStyle::structured;
  p.length = 10e-3;
  p.level = 1;
  MeshSource first, second;
  const TetMesh generated = load_or_generate_vessel(p, dir.path(), {}, &first);
  const TetMesh cached = load_or_generate_vessel(p, dir.path(), {}, &second);
  ASSERT_FALSE(first.cache_hit);
  ASSERT_TRUE(second.cache_hit);
  expect_same_mesh(generated, cached);
  EXPECT_EQ(generated.triangles, cached.triangles);
  for (std::size_t g = 0; g < generated.groups.size(); ++g) {
    EXPECT_EQ(generated.groups[g].elements, cached.groups[g].elements) << generated.groups[g].name;
  }
  // Without a cache the run uses the same mesh as with one.
  expect_same_mesh(load_or_generate_vessel(p, {}, {}), cached);
  EXPECT_EQ(load_or_generate_vessel(p, {}, {}).triangles, cached.triangles);
}

TEST(MeshCache, ACorruptEntryIsReportedAndTheMeshGeneratedAgain) {
  // The mesh cache is an entry of the checksummed content store: a flipped byte in the stored
  // mesh fails the checksum, so the mesh is generated again (and the entry replaced), never read
  // wrong.
  TempDir dir;
  VesselParams p;
  p.style = MeshStyle::structured;
  p.length = 10e-3;
  MeshSource first, second, third;
  const TetMesh generated = load_or_generate_vessel(p, dir.path(), {}, &first);
  ASSERT_FALSE(first.cache_hit);
  ASSERT_TRUE(std::filesystem::exists(first.path)) << first.path;
  EXPECT_EQ(first.path.parent_path(), dir.path() / "meshes");
  std::string bytes = vessel::test::read_text(first.path);
  bytes[bytes.size() / 2] ^= 0x20;
  std::ofstream(first.path, std::ios::binary) << bytes;
  testing::internal::CaptureStderr();
  const TetMesh again = load_or_generate_vessel(p, dir.path(), {}, &second);
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_FALSE(second.cache_hit);
  EXPECT_NE(log.find("mesh cache: entry"), std::string::npos) << log;
  EXPECT_NE(log.find("checksum mismatch"), std::string::npos) << log;
  expect_same_mesh(generated, again);
  (void)load_or_generate_vessel(p, dir.path(), {}, &third);
  EXPECT_TRUE(third.cache_hit);
}

TEST(MshIo, ReadsFilesWrittenByGmshInBothFormats) {
  // gmsh writes the files; our reader must recover gmsh's own element counts and the box volume.
  TempDir dir;
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::model::add("box");
  const int box = gmsh::model::occ::addBox(0, 0, 0, 1, 2, 3);
  gmsh::model::occ::synchronize();
  gmsh::vectorpair faces;
  gmsh::model::getBoundary({{3, box}}, faces, false, false);
  std::vector<int> face_tags;
  for (const auto& f : faces) face_tags.push_back(f.second);
  gmsh::model::addPhysicalGroup(2, face_tags, 7);
  gmsh::model::setPhysicalName(2, 7, "skin");
  gmsh::model::addPhysicalGroup(3, {box}, 3);
  gmsh::model::setPhysicalName(3, 3, "wall");
  gmsh::option::setNumber("Mesh.MeshSizeMax", 0.5);
  gmsh::model::mesh::generate(3);
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> tags, nodes;
  gmsh::model::mesh::getElements(types, tags, nodes, 3);
  const std::size_t gmsh_tets = tags.at(0).size();
  gmsh::model::mesh::getElements(types, tags, nodes, 2);
  std::size_t gmsh_triangles = 0;
  for (const auto& t : tags) gmsh_triangles += t.size();
  gmsh::option::setNumber("Mesh.MshFileVersion", 2.2);
  gmsh::write((dir / "box22.msh").string());
  gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
  gmsh::write((dir / "box41.msh").string());
  gmsh::finalize();

  for (const char* file : {"box22.msh", "box41.msh"}) {
    SCOPED_TRACE(file);
    const TetMesh mesh = read_msh(dir / file);
    EXPECT_EQ(mesh.tets.size(), gmsh_tets);
    EXPECT_EQ(mesh.triangles.size(), gmsh_triangles);
    EXPECT_NEAR(mesh_volume(mesh), 6.0, 1e-12);
    const auto* skin = mesh.find_group("skin", 2);
    ASSERT_NE(skin, nullptr);
    EXPECT_EQ(skin->tag, 7);
    EXPECT_NEAR(group_area(mesh, *skin), 2.0 * (1 * 2 + 2 * 3 + 1 * 3), 1e-12);
    EXPECT_TRUE(surface_topology(mesh.group_triangles(*skin)).closed_and_oriented());
    EXPECT_NEAR(enclosed_volume(mesh.nodes, mesh.group_triangles(*skin)), 6.0, 1e-12);
  }
}

TEST(MshIo, HandWrittenTetHasVolumeOneSixthAndOutwardFace) {
  TempDir dir;
  write_text(dir / "tet.msh", kOneTet22);
  const TetMesh mesh = read_msh(dir / "tet.msh");
  ASSERT_EQ(mesh.tets.size(), 1u);
  EXPECT_DOUBLE_EQ(mesh_volume(mesh), 1.0 / 6.0);
  // The inlet triangle lies in z = 0; outward from the tet is −z.
  const auto& t = mesh.triangles.at(0);
  const Vec3 n = (mesh.nodes[t[1]] - mesh.nodes[t[0]]).cross(mesh.nodes[t[2]] - mesh.nodes[t[0]]);
  EXPECT_LT(n.z(), 0.0);
}

TEST(MshIo, MissingFileIsAClearError) {
  const auto msg = input_error([] { (void)read_msh("/nonexistent/vessel.msh"); });
  EXPECT_NE(msg.find("/nonexistent/vessel.msh"), std::string::npos) << msg;
  EXPECT_NE(msg.find("not found"), std::string::npos) << msg;
}

TEST(MshIo, EmptyAndNonMshFilesAreRefused) {
  TempDir dir;
  write_text(dir / "empty.msh", "");
  EXPECT_NE(input_error([&] { (void)read_msh(dir / "empty.msh"); }).find("empty"),
            std::string::npos);
  write_text(dir / "text.msh", "hello\n");
  EXPECT_NE(input_error([&] { (void)read_msh(dir / "text.msh"); }).find("$MeshFormat"),
            std::string::npos);
}

TEST(MshIo, TruncatedFilesAreRefusedInEveryFormat) {
  TempDir dir;
  for (auto version : {MshVersion::v22, MshVersion::v41}) {
    write_msh(dir / "full.msh", level0_tube(), version);
    const std::string text = read_text(dir / "full.msh");
    for (double fraction : {0.05, 0.3, 0.6, 0.99}) {
      write_text(dir / "cut.msh", text.substr(0, static_cast<std::size_t>(fraction * text.size())));
      const auto msg = input_error([&] { (void)read_msh(dir / "cut.msh"); });
      EXPECT_FALSE(msg.empty()) << "fraction " << fraction;
      EXPECT_NE(msg.find("cut.msh"), std::string::npos) << msg;
    }
  }
}

TEST(MshIo, MalformedValuesNameTheLine) {
  TempDir dir;
  std::string text = kOneTet22;
  text.replace(text.find("2 1 0 0"), 7, "2 1 zero 0");
  write_text(dir / "bad.msh", text);
  const auto msg = input_error([&] { (void)read_msh(dir / "bad.msh"); });
  EXPECT_NE(msg.find("bad.msh:12:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("zero"), std::string::npos) << msg;
}

TEST(MshIo, NonFiniteCoordinatesAreRefused) {
  TempDir dir;
  std::string text = kOneTet22;
  text.replace(text.find("4 0 0 1"), 7, "4 0 nan 1");
  write_text(dir / "nan.msh", text);
  EXPECT_NE(input_error([&] { (void)read_msh(dir / "nan.msh"); }).find("non-finite"),
            std::string::npos);
}

TEST(MshIo, UnknownNodeTagsAndBinaryFilesAreRefused) {
  TempDir dir;
  std::string text = kOneTet22;
  text.replace(text.find("10 10 1 2 3 4"), 13, "10 10 1 2 3 9");
  write_text(dir / "tag.msh", text);
  EXPECT_NE(input_error([&] { (void)read_msh(dir / "tag.msh"); }).find("node tag 9"),
            std::string::npos);
  text = kOneTet22;
  text.replace(text.find("2.2 0 8"), 7, "2.2 1 8");
  write_text(dir / "bin.msh", text);
  EXPECT_NE(input_error([&] { (void)read_msh(dir / "bin.msh"); }).find("binary"),
            std::string::npos);
}

TEST(MshIo, MeshWithoutVesselGroupsIsRefusedNamingTheGroup) {
  TempDir dir;
  write_text(dir / "tet.msh", kOneTet22);
  const TetMesh mesh = read_msh(dir / "tet.msh");
  const auto msg = input_error([&] { require_vessel_groups(mesh, (dir / "tet.msh").string()); });
  EXPECT_NE(msg.find("tet.msh"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'outlet'"), std::string::npos) << msg;
}

TEST(StlIo, AsciiRoundTripIsExactAndBinaryWithinFloatPrecision) {
  TempDir dir;
  const TriangleSurface inner =
      extract_surface(level0_tube(), {std::string(group_names::inner_wall)}, "test");
  write_stl(dir / "inner.stl", inner, StlFormat::ascii);
  const TriangleSurface ascii = read_stl(dir / "inner.stl");
  EXPECT_EQ(ascii.nodes, inner.nodes);
  EXPECT_EQ(ascii.triangles, inner.triangles);
  write_stl(dir / "inner_bin.stl", inner, StlFormat::binary);
  const TriangleSurface binary = read_stl(dir / "inner_bin.stl");
  EXPECT_EQ(binary.nodes.size(), inner.nodes.size());
  EXPECT_EQ(binary.triangles.size(), inner.triangles.size());
  EXPECT_NEAR(surface_area(binary) / surface_area(inner), 1.0, 1e-6);
  // The inner wall is an open tube: its only open edges are the two rims.
  const SurfaceTopology topo = surface_topology(binary.triangles);
  EXPECT_EQ(topo.inconsistent_edges, 0u);
  EXPECT_EQ(topo.non_manifold_edges, 0u);
  EXPECT_GT(topo.boundary_edges, 0u);
}

TEST(StlIo, BadFilesAreClearErrors) {
  TempDir dir;
  EXPECT_NE(input_error([&] { (void)read_stl(dir / "missing.stl"); }).find("not found"),
            std::string::npos);
  write_text(dir / "empty.stl", "");
  EXPECT_NE(input_error([&] { (void)read_stl(dir / "empty.stl"); }).find("empty"),
            std::string::npos);
  write_text(dir / "cut.stl",
             "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n");
  const auto cut = input_error([&] { (void)read_stl(dir / "cut.stl"); });
  EXPECT_NE(cut.find("cut.stl:5: file is truncated"), std::string::npos) << cut;
  write_text(dir / "flat.stl",
             "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 0 0 0\n"
             "   vertex 1 0 0\n  endloop\n endfacet\nendsolid x\n");
  EXPECT_NE(input_error([&] { (void)read_stl(dir / "flat.stl"); }).find("degenerate"),
            std::string::npos);
}

TEST(VtuIo, WritesPointsCellsAndFieldsAndRefusesWrongSizes) {
  TempDir dir;
  const TetMesh& mesh = level0_tube();
  VtuField u{"u", 3, std::vector<double>(3 * mesh.nodes.size(), 0.5)};
  write_vtu(dir / "tube.vtu", mesh, {u});
  const std::string text = read_text(dir / "tube.vtu");
  EXPECT_NE(text.find("NumberOfPoints=\"" + std::to_string(mesh.nodes.size()) + "\""),
            std::string::npos);
  EXPECT_NE(text.find("NumberOfCells=\"" + std::to_string(mesh.tets.size()) + "\""),
            std::string::npos);
  EXPECT_NE(text.find("Name=\"u\" NumberOfComponents=\"3\""), std::string::npos);
  VtuField wrong{"w", 1, {1.0}};
  EXPECT_THROW(write_vtu(dir / "bad.vtu", mesh, {wrong}), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.vtu"));
}

TEST(AtomicFile, AFailedWriteLeavesTheEarlierFileAndNoTemporary) {
  TempDir dir;
  write_file_atomically(dir / "out.txt", [](std::ostream& out) { out << "good"; });
  EXPECT_THROW(write_file_atomically(dir / "out.txt",
                                     [](std::ostream& out) {
                                       out << "half";
                                       throw std::runtime_error("boom");
                                     }),
               std::runtime_error);
  EXPECT_EQ(read_text(dir / "out.txt"), "good");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator()),
            1);
}

TEST(AtomicFile, UnwritableDirectoryIsAnInputError) {
  const auto msg = input_error([] {
    write_file_atomically("/proc/vesselverify/out.txt", [](std::ostream& out) { out << "x"; });
  });
  EXPECT_NE(msg.find("/proc/vesselverify"), std::string::npos) << msg;
}
