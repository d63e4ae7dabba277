// Topology builders, stiffness rules and mass rules against hand-counted and hand-computed values.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <numeric>

#include "meshes/foundation/errors.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "msm/topology/springs.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

/// Regular tetrahedron of edge l.
std::array<Vec3, 4> regular_tet(double l) {
  return {Vec3(0, 0, 0), Vec3(l, 0, 0), Vec3(l / 2, l * std::sqrt(3.0) / 2, 0),
          Vec3(l / 2, l * std::sqrt(3.0) / 6, l * std::sqrt(2.0 / 3.0))};
}

TetMesh single_tet_mesh(const std::array<Vec3, 4>& x) {
  TetMesh m;
  m.nodes.assign(x.begin(), x.end());
  m.tets = {{0, 1, 2, 3}};
  return m;
}

/// Two equilateral triangles of side l sharing the edge 0-1 (a rhombus).
TriangleSurface triangle_pair(double l) {
  TriangleSurface s;
  s.nodes = {Vec3(0, 0, 0), Vec3(l, 0, 0), Vec3(l / 2, l * std::sqrt(3.0) / 2, 0),
             Vec3(l / 2, -l * std::sqrt(3.0) / 2, 0)};
  s.triangles = {{0, 1, 2}, {1, 0, 3}};
  s.source_node = {0, 1, 2, 3};
  return s;
}

double k_of(const SpringNetwork& net, int a, int b) {
  for (const Spring& s : net.springs) {
    if ((s.a == a && s.b == b) || (s.a == b && s.b == a)) return s.law.k1;
  }
  ADD_FAILURE() << "no spring " << a << "-" << b;
  return 0.0;
}

const TetMesh& structured_tube() {
  static const TetMesh mesh = [] {
    VesselParams p;
    p.style = MeshStyle::structured;
    return generate_vessel_mesh(p);
  }();
  return mesh;
}

}  // namespace

TEST(Topology, VolumeNetworkHasEveryTetEdgeOnce) {
  TetMesh m = single_tet_mesh(regular_tet(1e-3));
  // A second tet on face (1, 2, 3) adds 3 edges.
  m.nodes.push_back(Vec3(1e-3, 1e-3, 1e-3));
  m.tets.push_back({1, 2, 3, 4});
  const SpringNetwork net = build_volume_network(m);
  EXPECT_EQ(net.springs.size(), 9u);
  EXPECT_EQ(net.count(SpringFamily::volume), 9u);
  EXPECT_NEAR(net.springs[0].rest_length, 1e-3, 1e-15);  // edge 0-1
}

TEST(Topology, TriangleNetworkEdgesPlusOneBendPerInteriorEdge) {
  const SpringNetwork net = build_triangle_network(triangle_pair(1e-3), 1e-3);
  EXPECT_EQ(net.count(SpringFamily::structural), 5u);
  EXPECT_EQ(net.count(SpringFamily::bend), 1u);  // nodes 2-3 across the shared edge 0-1
  EXPECT_NEAR(k_of(net, 2, 3), 0.0, 0.0);
  for (const Spring& s : net.springs) {
    if (s.family == SpringFamily::bend) EXPECT_NEAR(s.rest_length, std::sqrt(3.0) * 1e-3, 1e-15);
  }
  // Two-ring on the rhombus: every pair is already connected → none.
  EXPECT_EQ(build_triangle_network(triangle_pair(1e-3), 1e-3, true).count(SpringFamily::two_ring),
            0u);
}

TEST(Topology, TwoRingSpringsOnAStrip) {
  // Strip of 3 triangles: 0-1-2 / 1-3-2 / 2-3-4 ... path graph distance 2 pairs not yet joined.
  TriangleSurface s;
  s.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(0, 2, 0)};
  s.triangles = {{0, 1, 2}, {1, 3, 2}, {2, 3, 4}};
  const SpringNetwork net = build_triangle_network(s, 1.0, true);
  EXPECT_EQ(net.count(SpringFamily::structural), 7u);
  EXPECT_EQ(net.count(SpringFamily::bend), 2u);      // 0-3 across 1-2, 1-4 across 2-3
  EXPECT_EQ(net.count(SpringFamily::two_ring), 1u);  // 0-4 (via 2)
}

TEST(Topology, StructuredTubeGridHasSeed000FamiliesExactly) {
  VesselParams p;
  p.style = MeshStyle::structured;
  const StructuredCounts c = structured_counts(p);
  const TriangleSurface inner = wall_surface(structured_tube(), p, WallSurface::inner);
  ASSERT_EQ(inner.nodes.size(), static_cast<std::size_t>(c.circumferential * (c.axial + 1)));
  const SpringNetwork net = build_tube_grid_network(inner, p, p.wall_thickness);
  const std::size_t nc = c.circumferential, na = c.axial;
  // Periodic around, open along: structural nc(na+1) + nc·na, shear 2·nc·na,
  // bend nc(na+1) + nc(na−1).
  EXPECT_EQ(net.count(SpringFamily::structural), nc * (na + 1) + nc * na);
  EXPECT_EQ(net.count(SpringFamily::shear), 2 * nc * na);
  EXPECT_EQ(net.count(SpringFamily::bend), nc * (na + 1) + nc * (na - 1));
  // Rest lengths: circumferential structural = chord 2a·sin(π/nc), axial = L/na.
  const double chord = 2 * p.inner_radius * std::sin(std::numbers::pi / c.circumferential);
  const double axial = p.length / c.axial;
  for (const Spring& s : net.springs) {
    if (s.family != SpringFamily::structural) continue;
    const bool circumferential = std::abs(net.nodes[s.a].z() - net.nodes[s.b].z()) < 1e-9;
    EXPECT_NEAR(s.rest_length, circumferential ? chord : axial, 1e-9);
  }
  // An unstructured mesh is refused with a clear message.
  VesselParams u;
  const TetMesh um = generate_vessel_mesh(u);
  EXPECT_THROW((void)build_tube_grid_network(wall_surface(um, u, WallSurface::inner), u, 1e-3),
               InputError);
}

TEST(Topology, MidSurfaceLiesAtMidWallRadius) {
  VesselParams p;
  p.style = MeshStyle::structured;
  const TriangleSurface mid = wall_surface(structured_tube(), p, WallSurface::mid);
  for (const Vec3& x : mid.nodes) EXPECT_NEAR(std::hypot(x.x(), x.y()), 3.5e-3, 1e-12);
}

TEST(StiffnessRules, SingleTriangleMatchesHandValues) {
  // Equilateral pair of side l = 1 mm, t = 1 mm, E = 14.24 kPa. Triangle area A = √3/4 l².
  const double l = 1e-3, t = 1e-3, E = 14.24e3;
  const double A = std::sqrt(3.0) / 4 * l * l;
  StiffnessParams p;
  p.youngs_modulus = E;
  p.poisson_ratio = 1.0 / 3.0;
  auto net_for = [&](StiffnessRule rule) {
    SpringNetwork net = build_triangle_network(triangle_pair(l), t);
    assign_stiffness(net, rule, p);
    return net;
  };
  // Van Gelder: E t Σ A / l²: shared edge 2A, outer edges A.
  EXPECT_NEAR(k_of(net_for(StiffnessRule::van_gelder), 0, 1), E * t * 2 * A / (l * l), 1e-12);
  EXPECT_NEAR(k_of(net_for(StiffnessRule::van_gelder), 0, 2), E * t * A / (l * l), 1e-12);
  // seed 001: a third of that.
  EXPECT_NEAR(k_of(net_for(StiffnessRule::seed001), 0, 1), E * t * 2 * A / 3 / (l * l), 1e-12);
  // seed 000: k = E·A/h0 with A = t·h0 → E·t.
  EXPECT_NEAR(k_of(net_for(StiffnessRule::seed000), 0, 2), E * t, 1e-12);
  // Lloyd et al.: a triangular lattice of springs k per triangle edge is isotropic with ν = 1/3
  // and 2D modulus 2k_total/√3, so the exact per-triangle value is √3/4·E·t.
  EXPECT_NEAR(k_of(net_for(StiffnessRule::lloyd), 0, 2), std::sqrt(3.0) / 4 * E * t, 1e-9);
  EXPECT_NEAR(k_of(net_for(StiffnessRule::lloyd), 0, 1), std::sqrt(3.0) / 2 * E * t, 1e-9);
  // Uniform: the seed's k.
  EXPECT_NEAR(k_of(net_for(StiffnessRule::uniform), 0, 1), 41.106, 0.0);
  // Per-family factor on the bend spring.
  p.bend_factor = 0.5;
  EXPECT_NEAR(k_of(net_for(StiffnessRule::seed000), 2, 3), 0.5 * E * t, 1e-12);
}

TEST(StiffnessRules, LeastSquaresFitTriangleIsExactAtNuOneThird) {
  const double l = 1e-3, t = 1e-3, E = 1e4;
  std::array<Vec3, 3> x{Vec3(0, 0, 0), Vec3(l, 0, 0), Vec3(l / 2, l * std::sqrt(3.0) / 2, 0)};
  const auto k = least_squares_fit_triangle_stiffness(x, E, 1.0 / 3.0, t);
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(9, 9);
  const int e[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  for (int i = 0; i < 3; ++i) {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(9);
    const Vec3 d = (x[e[i][0]] - x[e[i][1]]).normalized();
    g.segment<3>(3 * e[i][0]) = d;
    g.segment<3>(3 * e[i][1]) = -d;
    K += k[i] * g * g.transpose();
  }
  const Eigen::MatrixXd Kfem = fem_triangle_stiffness(x, E, 1.0 / 3.0, t);
  EXPECT_LT((K - Kfem).norm() / Kfem.norm(), 1e-12);
}

TEST(StiffnessRules, SingleTetMatchesHandValues) {
  // Regular tet of edge l, volume V = l³/(6√2), E = 14.24 kPa, ν = 1/4.
  // Van Gelder: E·V/l² per edge; seed 001: a third of it; seed 000: E·h0 (A = h0²).
  // Lloyd et al. (2007) derive k = (2√2/25)·E·l for the regular tetrahedron, i.e. (24/25)·E·V/l²:
  // the six springs cannot represent the tet exactly (a uniform dilation would need E·V/l²). The
  // least-squares fit at ν = 1/4 gives the same value (hand derivation in
  // test_stiffness_rules_by_hand.cpp).
  const double l = 2e-3, E = 14.24e3;
  const auto x = regular_tet(l);
  const double V = l * l * l / (6 * std::sqrt(2.0));
  StiffnessParams p;
  p.youngs_modulus = E;
  p.poisson_ratio = 0.25;
  auto net_for = [&](StiffnessRule rule) {
    SpringNetwork net = build_volume_network(single_tet_mesh(x));
    assign_stiffness(net, rule, p);
    return net;
  };
  EXPECT_NEAR(k_of(net_for(StiffnessRule::van_gelder), 0, 1), E * V / (l * l), 1e-12);
  EXPECT_NEAR(k_of(net_for(StiffnessRule::seed001), 0, 1), E * V / 3 / (l * l), 1e-12);
  EXPECT_NEAR(k_of(net_for(StiffnessRule::seed000), 2, 3), E * l, 1e-12);  // A = h0²
  const auto kl = least_squares_fit_tet_stiffness(x, E, 0.25);
  for (double k : kl) EXPECT_NEAR(k, 2 * std::sqrt(2.0) / 25 * E * l, 1e-9 * E * l);
  EXPECT_NEAR(k_of(net_for(StiffnessRule::lloyd), 0, 1), 2 * std::sqrt(2.0) / 25 * E * l,
              1e-9 * E * l);
}

TEST(StiffnessRules, BadInputNamesTheParameter) {
  SpringNetwork net = build_volume_network(single_tet_mesh(regular_tet(1e-3)));
  StiffnessParams p;
  p.youngs_modulus = -1;
  try {
    assign_stiffness(net, StiffnessRule::seed001, p);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("youngs_modulus"), std::string::npos);
  }
  p = {};
  p.poisson_ratio = 0.6;
  EXPECT_THROW(assign_stiffness(net, StiffnessRule::lloyd, p), InputError);
  EXPECT_THROW((void)parse_stiffness_rule("magic"), InputError);
}

TEST(MassRules, SumToTheMaterialMassAndMatchHandValues) {
  const double rho = 1000.0, l = 1e-3;
  SpringNetwork tet = build_volume_network(single_tet_mesh(regular_tet(l)));
  const double V = l * l * l / (6 * std::sqrt(2.0));
  for (MassRule r : {MassRule::uniform, MassRule::seed001, MassRule::consistent}) {
    const auto m = nodal_masses(tet, r, rho);
    for (double mi : m) EXPECT_NEAR(mi, rho * V / 4, 1e-18);
  }
  // Seed 001 eq. (2) as printed on one tet: M·V/(V·1·3) = M/3 per node (sums to 4M/3).
  const auto raw = seed001_masses_as_printed(tet, 1.0);
  EXPECT_NEAR(raw[0], 1.0 / 3.0, 1e-15);
  // Surface: ρ·A·t/3 per triangle vertex. Rhombus: the shared-edge nodes get two triangles.
  SpringNetwork pair = build_triangle_network(triangle_pair(l), 2e-3);
  const double A = std::sqrt(3.0) / 4 * l * l;
  const auto mc = nodal_masses(pair, MassRule::consistent, rho);
  EXPECT_NEAR(mc[0], 2 * rho * A * 2e-3 / 3, 1e-18);
  EXPECT_NEAR(mc[2], rho * A * 2e-3 / 3, 1e-18);
  const auto mu = nodal_masses(pair, MassRule::uniform, rho);
  EXPECT_NEAR(mu[2], rho * 2 * A * 2e-3 / 4, 1e-18);
  EXPECT_THROW((void)nodal_masses(pair, MassRule::seed001, rho), InputError);
  EXPECT_THROW((void)nodal_masses(pair, MassRule::uniform, 0.0), InputError);
}

TEST(Topology, TriangleNetworkFromAnStlFileEqualsTheOneFromTheMesh) {
  // The surface model on an STL (seed 000 reads its vessel from STL): same springs, same lengths
  // to float32 precision.
  VesselParams p;
  p.style = MeshStyle::structured;
  const TriangleSurface inner = wall_surface(structured_tube(), p, WallSurface::inner);
  const auto path = std::filesystem::temp_directory_path() / "msm_topology_inner.stl";
  write_stl(path, inner, StlFormat::binary);
  const TriangleSurface read = read_stl(path);
  std::filesystem::remove(path);
  const SpringNetwork a = build_triangle_network(inner, 1e-3);
  const SpringNetwork b = build_triangle_network(read, 1e-3);
  EXPECT_EQ(a.count(SpringFamily::structural), b.count(SpringFamily::structural));
  EXPECT_EQ(a.count(SpringFamily::bend), b.count(SpringFamily::bend));
  double total_a = 0, total_b = 0;
  for (const auto& s : a.springs) total_a += s.rest_length;
  for (const auto& s : b.springs) total_b += s.rest_length;
  EXPECT_NEAR(total_b / total_a, 1.0, 1e-6);
  // Euler: a tube (open cylinder) has V − E + F = 0, so structural springs = nodes + triangles.
  EXPECT_EQ(a.count(SpringFamily::structural), inner.nodes.size() + inner.triangles.size());
}

TEST(Topology, StructuredArchGridAndMidSurface) {
  VesselParams p;
  p.kind = VesselKind::arch;
  p.style = MeshStyle::structured;
  const TetMesh mesh = generate_vessel_mesh(p);
  const StructuredCounts c = structured_counts(p);
  const TriangleSurface mid = wall_surface(mesh, p, WallSurface::mid);
  const SpringNetwork net = build_tube_grid_network(mid, p, p.wall_thickness);
  const std::size_t nc = c.circumferential, na = c.axial;
  EXPECT_EQ(net.count(SpringFamily::structural), nc * (na + 1) + nc * na);
  EXPECT_EQ(net.count(SpringFamily::shear), 2 * nc * na);
  EXPECT_EQ(net.count(SpringFamily::bend), nc * (na + 1) + nc * (na - 1));
  // Every mid-surface node at distance a + t/2 from the arch's centreline circle of radius R.
  for (const Vec3& x : mid.nodes) {
    const double rho = std::hypot(std::hypot(x.x(), x.y()) - p.bend_radius, x.z());
    EXPECT_NEAR(rho, p.inner_radius + 0.5 * p.wall_thickness, 1e-12);
  }
}

TEST(StiffnessRules, BothShearDiagonalsOfAGridCellGetTheSameStiffness) {
  VesselParams p;
  p.style = MeshStyle::structured;
  SpringNetwork net =
      build_tube_grid_network(wall_surface(structured_tube(), p, WallSurface::inner), p, 1e-3);
  for (StiffnessRule rule :
       {StiffnessRule::seed001, StiffnessRule::van_gelder, StiffnessRule::lloyd,
        StiffnessRule::least_squares_fit}) {
    assign_stiffness(net, rule, StiffnessParams{});
    double lo = 1e300, hi = 0;
    for (const Spring& s : net.springs) {
      if (s.family != SpringFamily::shear) continue;
      // All shear springs of the straight tube have the same length, so the same k.
      lo = std::min(lo, s.law.k1);
      hi = std::max(hi, s.law.k1);
    }
    EXPECT_NEAR(hi / lo, 1.0, 1e-9) << to_string(rule);
  }
}

TEST(StiffnessRules, CoincidentNodesAndTheFitAtNuOneHalfAreRefusedNotNan) {
  using namespace vessel::msm;
  SpringNetwork net;
  net.nodes = {Vec3(0, 0, 0), Vec3(1e-3, 0, 0), Vec3(0, 1e-3, 0), Vec3(0, 0, 1e-3)};
  net.tets = {{0, 1, 2, 3}};
  Spring s;
  s.a = 0;
  s.b = 1;
  s.rest_length = 1e-3;
  s.family = SpringFamily::volume;
  net.springs = {s};
  StiffnessParams p;
  p.poisson_ratio = 0.5;
  EXPECT_THROW(assign_stiffness(net, StiffnessRule::least_squares_fit, p), vessel::InputError);
  // lloyd's closed form does not read ν: accepted, and finite.
  assign_stiffness(net, StiffnessRule::lloyd, p);
  EXPECT_TRUE(std::isfinite(net.springs[0].law.k1));
  p.poisson_ratio = 0.3;
  net.springs[0].rest_length = 0.0;
  try {
    assign_stiffness(net, StiffnessRule::seed001, p);
    FAIL() << "a zero-length spring was accepted";
  } catch (const vessel::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("zero rest length"), std::string::npos) << e.what();
  }
}
