// Spring-network files (msm/formats/network_file.hpp): a hand-written file read back to the values
// written by hand, JSON and VTU round trips bit for bit, and every refusal named (file, item,
// what was expected).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "../test_helpers.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/vtu_io.hpp"
#include "msm/formats/network_file.hpp"
#include "msm/kernels/spring_kernels.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

/// Two springs on three nodes, one bilinear and damped; node 0 fixed, the inlet followed.
const char* kSmall = R"({
  "format": "vesselverify.network",
  "version": 1,
  "description": "hand-written",
  "nodes": [[0, 0, 0], [0.001, 0, 0], [0.001, 0.002, 0.0005]],
  "masses": [1e-6, 2e-6, 3.5e-6],
  "springs": [
    {"nodes": [0, 1], "stiffness": 12.5, "rest_length": 0.001},
    {"nodes": [2, 1], "stiffness": 3, "rest_length": 0.0021, "k2": 6, "threshold": 1e-4,
     "damping": 0.01, "family": "bend"}
  ],
  "fixed": {"nodes": [0]},
  "follow_groups": ["inlet"]
})";

/// The text of kSmall with `from` replaced by `to` (once; the test fails if `from` is absent).
std::string small_with(const std::string& from, const std::string& to) {
  std::string s = kSmall;
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

/// The InputError message of parsing `text`, or "" if it parsed.
std::string json_error(const std::string& text) {
  try {
    (void)parse_network_json(text, "net.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_error(const std::string& text, const std::vector<std::string>& parts) {
  const std::string message = json_error(text);
  ASSERT_FALSE(message.empty()) << "accepted:\n" << text;
  EXPECT_NE(message.find("net.json"), std::string::npos) << message;
  for (const auto& p : parts) EXPECT_NE(message.find(p), std::string::npos) << message << "\n  lacks: " << p;
}

/// A network whose coordinates and parameters have no short decimal form (a round trip that
/// rounds anywhere changes them).
NetworkFile awkward_network() {
  NetworkFile f;
  f.description = "awkward \"quoted\" values";
  f.network.nodes = {Vec3(1.0 / 3.0, -2.0 / 7.0, 1e-3 * M_PI), Vec3(0.1, 0.2, 0.30000000000000004),
                     Vec3(-1e-9 / 3.0, 5.0 / 9.0, 0.0), Vec3(std::sqrt(2.0) * 1e-3, 0.0, 1.0 / 11.0)};
  f.masses = {1e-6 / 3.0, 2.0 / 3.0 * 1e-5, 1e-7 * M_E, 4.2e-6};
  Spring a;
  a.a = 0, a.b = 1, a.rest_length = 1.0 / 7.0, a.law.k1 = 41.106 / 3.0, a.family = SpringFamily::volume;
  Spring b;
  b.a = 2, b.b = 1, b.rest_length = 0.01 / 3.0, b.law.k1 = M_PI, b.law.k2 = 2.0 * M_PI / 3.0;
  b.law.threshold = 1e-4 / 3.0;
  b.damping = 1.0 / 9.0;
  b.family = SpringFamily::shear;
  Spring c;
  c.a = 3, c.b = 0, c.rest_length = 0.5, c.law.k1 = 1e-3 / 7.0;
  f.network.springs = {a, b, c};
  f.supports.fixed_nodes = {1, 3};
  f.supports.follow_groups = {"inlet", "outlet"};
  return f;
}

void expect_same(const NetworkFile& a, const NetworkFile& b, bool description = true) {
  if (description) EXPECT_EQ(a.description, b.description);
  ASSERT_EQ(a.network.nodes.size(), b.network.nodes.size());
  for (std::size_t i = 0; i < a.network.nodes.size(); ++i) {
    EXPECT_EQ(a.network.nodes[i], b.network.nodes[i]) << "node " << i;  // bit for bit
    EXPECT_EQ(a.masses[i], b.masses[i]) << "mass " << i;
  }
  ASSERT_EQ(a.network.springs.size(), b.network.springs.size());
  for (std::size_t k = 0; k < a.network.springs.size(); ++k) {
    const Spring& s = a.network.springs[k];
    const Spring& t = b.network.springs[k];
    EXPECT_EQ(s.a, t.a);
    EXPECT_EQ(s.b, t.b);
    EXPECT_EQ(s.rest_length, t.rest_length) << k;
    EXPECT_EQ(s.law.k1, t.law.k1) << k;
    EXPECT_EQ(s.law.threshold, t.law.threshold) << k;
    if (std::isfinite(s.law.threshold)) EXPECT_EQ(s.law.k2, t.law.k2) << k;
    EXPECT_EQ(s.damping, t.damping) << k;
    EXPECT_EQ(s.family, t.family) << k;
  }
  EXPECT_EQ(a.supports.fixed_nodes, b.supports.fixed_nodes);
  EXPECT_EQ(a.supports.follow_groups, b.supports.follow_groups);
}

}  // namespace

TEST(NetworkFile, AHandWrittenFileReadsToTheValuesWrittenInIt) {
  const NetworkFile f = parse_network_json(kSmall, "net.json");
  EXPECT_EQ(f.description, "hand-written");
  ASSERT_EQ(f.network.nodes.size(), 3u);
  EXPECT_EQ(f.network.nodes[2], Vec3(0.001, 0.002, 0.0005));
  EXPECT_EQ(f.masses, (std::vector<double>{1e-6, 2e-6, 3.5e-6}));
  ASSERT_EQ(f.network.springs.size(), 2u);
  const Spring& hooke = f.network.springs[0];
  EXPECT_EQ(hooke.law.k1, 12.5);
  EXPECT_EQ(hooke.rest_length, 0.001);
  EXPECT_TRUE(std::isinf(hooke.law.threshold));  // no k2/threshold: Hooke
  EXPECT_EQ(hooke.damping, 0.0);
  EXPECT_EQ(hooke.family, SpringFamily::structural);
  const Spring& bilinear = f.network.springs[1];
  EXPECT_EQ(bilinear.a, 2);
  EXPECT_EQ(bilinear.b, 1);
  EXPECT_EQ(bilinear.law.k2, 6.0);
  EXPECT_EQ(bilinear.law.threshold, 1e-4);
  EXPECT_EQ(bilinear.damping, 0.01);
  EXPECT_EQ(bilinear.family, SpringFamily::bend);
  EXPECT_EQ(f.supports.fixed_nodes, std::vector<int>{0});
  EXPECT_EQ(f.supports.follow_groups, std::vector<std::string>{"inlet"});
  // The bilinear law as seed 001 eq. (1) uses it: k1 up to the threshold elongation, k2 beyond.
  const double beyond = bilinear.rest_length + 3e-4;
  const LengthProfile p = spring_profile(beyond, bilinear.rest_length, bilinear.law);
  EXPECT_DOUBLE_EQ(p.dpsi, 3.0 * 1e-4 + 6.0 * 2e-4);
}

TEST(NetworkFile, JsonAndVtuRoundTripBitForBit) {
  test::TempDir dir;
  const NetworkFile f = awkward_network();
  for (const char* name : {"net.json", "net.vtu", "NET.VTU"}) {
    write_network_file(dir / name, f);
    const NetworkFile back = read_network_file(dir / name);
    SCOPED_TRACE(name);
    // VTU has no description field.
    expect_same(f, back, std::string(name) == "net.json");
  }
}

TEST(NetworkFile, TheVtuHoldsLineCellsWithTheSpringsAsCellData) {
  test::TempDir dir;
  write_network_file(dir / "net.vtu", awkward_network());
  const VtuData d = read_vtu(dir / "net.vtu");
  EXPECT_EQ(d.types, std::vector<int>(3, 3));  // VTK_LINE
  EXPECT_EQ(d.offsets, (std::vector<std::size_t>{2, 4, 6}));
  EXPECT_EQ(d.connectivity, (std::vector<std::size_t>{0, 1, 2, 1, 3, 0}));
  const VtuField* k = VtuData::find(d.cell_fields, "stiffness");
  ASSERT_NE(k, nullptr);
  EXPECT_EQ(k->values[1], M_PI);
  const VtuField* threshold = VtuData::find(d.cell_fields, "threshold");
  ASSERT_NE(threshold, nullptr);
  EXPECT_EQ(threshold->values[0], 0.0);  // Hooke spring: threshold 0
  const VtuField* fixed = VtuData::find(d.point_fields, "fixed");
  ASSERT_NE(fixed, nullptr);
  EXPECT_EQ(fixed->values, (std::vector<double>{0, 1, 0, 1}));
  ASSERT_EQ(d.field_data.size(), 3u);  // version, follow_group_inlet, follow_group_outlet
}

TEST(NetworkFile, MalformedJsonNamesTheFileAndWhere) {
  expect_error("{\"format\": \"vesselverify.network\", ", {"not valid JSON", "byte"});
  expect_error("[1, 2]", {"expected a JSON object"});
}

TEST(NetworkFile, EachRefusalNamesTheItemAndWhatWasExpected) {
  struct Case {
    std::string from, to;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases{
      {"\"nodes\": [0, 1]", "\"nodes\": [0, 3]", {"springs[0]", "node index 3", "expected 0 to 2"}},
      {"\"nodes\": [0, 1]", "\"nodes\": [0, -1]", {"springs[0].nodes[1]", "expected a node index"}},
      {"\"nodes\": [0, 1]", "\"nodes\": [1, 1]", {"springs[0]", "joins node 1 to itself"}},
      {"\"nodes\": [0, 1]", "\"nodes\": [0, 1, 2]", {"springs[0].nodes", "two node indices"}},
      {"\"stiffness\": 12.5", "\"stiffness\": 0", {"springs[0]", "stiffness 0", "> 0 N/m"}},
      {"\"stiffness\": 12.5", "\"stiffness\": -2", {"springs[0]", "stiffness -2", "> 0 N/m"}},
      {"\"stiffness\": 12.5", "\"stiffness\": \"stiff\"", {"springs[0].stiffness", "a stiffness > 0"}},
      {"\"rest_length\": 0.001", "\"rest_length\": 0", {"springs[0]", "rest_length 0", "> 0 m"}},
      {"\"rest_length\": 0.001}", "\"rest_length\": 0.001, \"damping\": -1}",
       {"springs[0]", "damping -1", "≥ 0"}},
      {"\"k2\": 6, ", "", {"springs[1]", "\"threshold\" without \"k2\"", "both"}},
      {"\"k2\": 6", "\"k2\": 0", {"springs[1]", "k2 0", "> 0 N/m"}},
      {"\"threshold\": 1e-4", "\"threshold\": -1e-4", {"springs[1]", "threshold -0.0001", "> 0 m"}},
      {"\"family\": \"bend\"", "\"family\": \"curly\"", {"springs[1].family", "structural, shear"}},
      {"\"nodes\": [2, 1]", "\"nodes\": [1, 0]", {"springs[1]", "joins nodes 0 and 1 like springs[0]", "each pair of nodes once"}},
      {"\"masses\": [1e-6, 2e-6, 3.5e-6]", "\"masses\": [1e-6, 0, 3.5e-6]", {"masses[1]", "found 0", "mass > 0 kg"}},
      {"\"masses\": [1e-6, 2e-6, 3.5e-6]", "\"masses\": [1e-6, -2e-6, 3.5e-6]", {"masses[1]", "mass > 0 kg"}},
      {"\"masses\": [1e-6, 2e-6, 3.5e-6]", "\"masses\": [1e-6, 2e-6]", {"masses", "2 masses for 3 nodes", "one per node"}},
      {"[0.001, 0.002, 0.0005]", "[0.001, 0.002]", {"nodes[2]", "expected [x, y, z]"}},
      {"\"fixed\": {\"nodes\": [0]}", "\"fixed\": {\"nodes\": [7]}", {"fixed.nodes[0]", "node index 7"}},
      {"\"fixed\": {\"nodes\": [0]}", "\"fixed\": {\"nodes\": [0, 0]}", {"fixed.nodes[1]", "twice"}},
      {"\"fixed\": {\"nodes\": [0]}", "\"fixed\": {\"node\": [0]}", {"fixed: key \"node\"", "unknown key", "nodes"}},
      {"\"follow_groups\": [\"inlet\"]", "\"follow_groups\": [\"inlet\", \"inlet\"]", {"follow_groups[1]", "twice"}},
      {"\"follow_groups\": [\"inlet\"]", "\"follow_groups\": [3]", {"follow_groups[0]", "group name"}},
      {"\"description\"", "\"descripton\"", {"key \"descripton\"", "unknown key", "description"}},
      {"\"damping\": 0.01", "\"dampng\": 0.01", {"springs[1]: key \"dampng\"", "unknown key"}},
      {"\"version\": 1", "\"version\": 2", {"version", "found 2", "expected 1"}},
      {"\"format\": \"vesselverify.network\"", "\"format\": \"other\"", {"format", "\"other\""}},
      {"\"format\": \"vesselverify.network\",", "", {"missing \"format\""}},
      {"\"masses\": [1e-6, 2e-6, 3.5e-6],", "", {"missing \"masses\""}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.to);
    expect_error(small_with(c.from, c.to), c.parts);
  }
  // A fourth node with its mass but no spring.
  std::string loose = small_with("[0.001, 0.002, 0.0005]", "[0.001, 0.002, 0.0005], [1, 1, 1]");
  loose.replace(loose.find("3.5e-6]"), 7, "3.5e-6, 1e-6]");
  expect_error(loose, {"nodes[3]", "in no spring"});
}

TEST(NetworkFile, AFileOfAnotherExtensionOrMissingIsRefused) {
  test::TempDir dir;
  try {
    (void)read_network_file(dir / "net.txt");
    FAIL() << "read a .txt";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("expected .json or .vtu"), std::string::npos) << e.what();
  }
  try {
    (void)read_network_file(dir / "missing.json");
    FAIL() << "read a missing file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.json: network file not found"), std::string::npos);
  }
}

namespace {

/// The VTU of awkward_network with `from` replaced by `to`, read back: the error message.
std::string vtu_error(const std::string& from, const std::string& to) {
  test::TempDir dir;
  write_network_file(dir / "net.vtu", awkward_network());
  std::string text = test::read_text(dir / "net.vtu");
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  test::write_text(dir / "bad.vtu", text);
  try {
    (void)read_network_file(dir / "bad.vtu");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_vtu_error(const std::string& from, const std::string& to,
                      const std::vector<std::string>& parts) {
  const std::string m = vtu_error(from, to);
  SCOPED_TRACE(to);
  ASSERT_FALSE(m.empty()) << "accepted";
  EXPECT_NE(m.find("bad.vtu"), std::string::npos) << m;
  for (const auto& p : parts) EXPECT_NE(m.find(p), std::string::npos) << m << "\n  lacks: " << p;
}

}  // namespace

TEST(NetworkFile, MalformedVtuIsRefusedNamingTheFileAndTheItem) {
  expect_vtu_error("</Piece>", "", {"closing tag </UnstructuredGrid> does not match", "<Piece>"});
  expect_vtu_error("format=\"ascii\"", "format=\"binary\"", {"format \"binary\"", "expected format=\"ascii\""});
  expect_vtu_error("Name=\"mass\"", "Name=\"masses\"", {"point data \"masses\"", "unknown array", "mass, fixed"});
  expect_vtu_error("Name=\"stiffness\"", "Name=\"k\"", {"cell data \"k\"", "unknown array"});
  expect_vtu_error("<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n3",
                   "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n5",
                   {"cells[0]", "VTK cell type 5", "a line (type 3)"});
  expect_vtu_error("Name=\"connectivity\" format=\"ascii\">\n0 1", "Name=\"connectivity\" format=\"ascii\">\n0 9",
                   {"connectivity entry 1 names point 9", "expected < 4"});
  expect_vtu_error("Name=\"connectivity\" format=\"ascii\">\n0 1", "Name=\"connectivity\" format=\"ascii\">\n0 x1",
                   {"DataArray \"connectivity\"", "\"x1\"", "expected a number"});
  expect_vtu_error("Name=\"connectivity\" format=\"ascii\">\n0 1", "Name=\"connectivity\" format=\"ascii\">\n0 0",
                   {"springs[0]", "joins node 0 to itself"});
  expect_vtu_error("NumberOfPoints=\"4\"", "NumberOfPoints=\"5\"", {"NumberOfPoints=5", "4 points"});
  expect_vtu_error("UnstructuredGrid\" version", "PolyData\" version", {"VTKFile type \"PolyData\"", "UnstructuredGrid"});
  expect_vtu_error("Name=\"follow_group_inlet\"", "Name=\"colour\"", {"field data \"colour\"", "unknown array"});
}

TEST(NetworkFile, AVtuWithoutMassesOrStiffnessIsRefused) {
  test::TempDir dir;
  write_vtu(dir / "bare.vtu", {Vec3(0, 0, 0), Vec3(1, 0, 0)}, VtuCells{3, 2, {0, 1}},
            {}, {VtuField{"stiffness", 1, {1.0}}, VtuField{"rest_length", 1, {1.0}}});
  try {
    (void)read_network_file(dir / "bare.vtu");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bare.vtu: point data \"mass\": missing"), std::string::npos)
        << e.what();
  }
  write_vtu(dir / "nok.vtu", {Vec3(0, 0, 0), Vec3(1, 0, 0)}, VtuCells{3, 2, {0, 1}},
            {VtuField{"mass", 1, {1.0, 1.0}}}, {VtuField{"rest_length", 1, {1.0}}});
  try {
    (void)read_network_file(dir / "nok.vtu");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nok.vtu: cell data \"stiffness\": missing"), std::string::npos)
        << e.what();
  }
}

TEST(NetworkFile, AModelWithAVolumeOrBendingTermIsNotExported) {
  BuiltNetwork built;
  built.network.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0)};
  built.terms.volume_kappa = 1.0;
  EXPECT_THROW((void)network_file_of(built, {}, ""), InputError);
  built.terms.volume_kappa.reset();
  built.terms.bending_rigidity = 1.0;
  EXPECT_THROW((void)network_file_of(built, {}, ""), InputError);
}

TEST(NetworkFile, NodesOnTheMeshAreMatchedAndNodesOutsideAreNamed) {
  // One tet with a boundary made of its four faces.
  TetMesh mesh;
  mesh.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  mesh.tets = {{0, 1, 2, 3}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  mesh.groups = {{"inlet", 2, 1, {0}}};
  NetworkFile f;
  f.network.nodes = {Vec3(1, 0, 0), Vec3(0.1, 0.1, 0.1), Vec3(0, 0, 1 + 1e-9)};
  f.masses = {1, 1, 1};
  f.network.springs.resize(2);
  f.network.springs[0].a = 0, f.network.springs[0].b = 1;
  f.network.springs[1].a = 1, f.network.springs[1].b = 2;
  for (auto& s : f.network.springs) s.law.k1 = s.rest_length = 1.0;
  f.supports.follow_groups = {"inlet"};
  const BuiltNetwork b = network_on_mesh(f, mesh, "net.json");
  EXPECT_EQ(b.network.source_node, (std::vector<int>{1, -1, 3}));  // 1e-9 is within 1e-6·√3
  f.supports.follow_groups = {"outlet"};
  try {
    (void)network_on_mesh(f, mesh, "net.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("net.json: follow_groups[0]: found \"outlet\""),
              std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(require_nodes_inside(f.network.nodes, mesh, 1e-6, "net.json"));
  // Node 2 moved 2 mm above the tet's apex (distance 2e-3 from the boundary), node 0 0.5 mm out.
  f.network.nodes[2] = Vec3(0, 0, 1.002);
  f.network.nodes[0] = Vec3(1.0005, 0, 0);
  try {
    require_nodes_inside(f.network.nodes, mesh, 1e-6, "net.json");
    FAIL();
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("net.json: 2 of 3 nodes lie outside"), std::string::npos) << m;
    EXPECT_NE(m.find("(nodes 0, 2)"), std::string::npos) << m;
    EXPECT_NE(m.find("up to 2 mm"), std::string::npos) << m;
  }
}

TEST(NetworkFile, AnAsciiVtuWrittenByVtkItselfReadsToTheValuesItWasGiven) {
  // tests/fixtures/network_by_vtk.vtu: written by VTK 9.1's vtkXMLUnstructuredGridWriter in ASCII
  // mode (tests/fixtures/make_network_by_vtk.py), as ParaView saves: Int32 and Int64 arrays, a
  // compressor attribute, and an InformationKey inside the points.
  const NetworkFile f = read_network_file(std::string(VESSEL_TEST_FIXTURES) + "/network_by_vtk.vtu");
  ASSERT_EQ(f.network.nodes.size(), 4u);
  EXPECT_EQ(f.network.nodes[2], Vec3(0.0035, 0.0, 0.001));
  EXPECT_EQ(f.masses, (std::vector<double>{1e-6, 2e-6, 3e-6, 4e-6}));
  ASSERT_EQ(f.network.springs.size(), 4u);
  EXPECT_EQ(f.network.springs[3].a, 3);
  EXPECT_EQ(f.network.springs[3].b, 0);
  EXPECT_EQ(f.network.springs[3].law.k1, 40.5);
  EXPECT_EQ(f.network.springs[3].rest_length, 0.0005);
  EXPECT_TRUE(std::isinf(f.network.springs[0].law.threshold));
  EXPECT_EQ(f.network.springs[1].law.k2, 60.0);
  EXPECT_EQ(f.network.springs[1].law.threshold, 1e-4);
  EXPECT_EQ(f.supports.fixed_nodes, std::vector<int>{0});
  EXPECT_EQ(f.supports.follow_groups, std::vector<std::string>{"inlet"});
}
