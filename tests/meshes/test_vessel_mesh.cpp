// Generated vessel meshes against closed-form geometry: volumes, areas, groups, surface closure and
// orientation, node positions on the walls, and structured growth per level.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "meshes/foundation/errors.hpp"
#include "meshes/foundation/solver_threads.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/mesh_quality.hpp"

using namespace vessel;

namespace {

struct Case {
  VesselKind kind;
  MeshStyle style;
};

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  return to_string(info.param.kind) + "_" + to_string(info.param.style);
}

VesselParams params_for(const Case& c, int level) {
  VesselParams p;
  p.kind = c.kind;
  p.style = c.style;
  p.level = level;
  return p;
}

double rel(double value, double exact) { return std::abs(value - exact) / exact; }

std::vector<Triangle> all_boundary_triangles(const TetMesh& mesh) {
  std::vector<Triangle> out;
  for (const auto& spec : kVesselGroups) {
    if (spec.dim != 2) continue;
    const auto t = mesh.group_triangles(*mesh.find_group(spec.name, 2));
    out.insert(out.end(), t.begin(), t.end());
  }
  return out;
}

std::set<std::array<int, 3>> sorted_set(const std::vector<Triangle>& tris) {
  std::set<std::array<int, 3>> s;
  for (auto t : tris) {
    std::sort(t.begin(), t.end());
    s.insert(t);
  }
  return s;
}

/// Relative errors of volume and of each wall area against the closed forms.
struct GeometryErrors {
  double volume, inner, outer, end;
};

GeometryErrors geometry_errors(const TetMesh& mesh, const VesselParams& p) {
  return {rel(mesh_volume(mesh), analytic_wall_volume(p)),
          rel(group_area(mesh, *mesh.find_group(group_names::inner_wall, 2)),
              analytic_lateral_area(p, p.inner_radius)),
          rel(group_area(mesh, *mesh.find_group(group_names::outer_wall, 2)),
              analytic_lateral_area(p, p.outer_radius())),
          rel(group_area(mesh, *mesh.find_group(group_names::inlet, 2)), analytic_end_area(p))};
}

class VesselMesh : public ::testing::TestWithParam<Case> {};

}  // namespace

TEST_P(VesselMesh, Level0HasEveryGroupAClosedOrientedBoundaryAndValidTets) {
  const VesselParams p = params_for(GetParam(), 0);
  const TetMesh mesh = generate_vessel_mesh(p);
  EXPECT_NO_THROW(require_vessel_groups(mesh, "test"));
  for (const auto& spec : kVesselGroups) {
    const auto* g = mesh.find_group(spec.name, spec.dim);
    ASSERT_NE(g, nullptr) << spec.name;
    EXPECT_EQ(g->tag, spec.tag);
    EXPECT_FALSE(g->elements.empty()) << spec.name;
  }
  EXPECT_GE(mesh.nodes.size(), 1000u);
  EXPECT_LE(mesh.nodes.size(), 3500u);

  // The union of the four surface groups is exactly the boundary of the tet mesh (shared
  // vertices), closed and consistently oriented, and encloses the tets' volume.
  const auto surface = all_boundary_triangles(mesh);
  EXPECT_EQ(sorted_set(surface), sorted_set(boundary_faces(mesh)));
  const SurfaceTopology topo = surface_topology(surface);
  EXPECT_TRUE(topo.closed_and_oriented())
      << "open " << topo.boundary_edges << " non-manifold " << topo.non_manifold_edges
      << " inconsistent " << topo.inconsistent_edges;
  EXPECT_NEAR(enclosed_volume(mesh.nodes, surface) / mesh_volume(mesh), 1.0, 1e-10);

  const MeshQuality q = compute_quality(mesh);
  EXPECT_EQ(q.inverted, 0u);
  EXPECT_EQ(q.degenerate, 0u);
  // The check every .msh read goes through accepts the generated meshes.
  EXPECT_NO_THROW(require_positive_volumes(mesh, "generated"));
  EXPECT_GT(q.dihedral_deg.min, 5.0);
  EXPECT_GT(q.radius_ratio.min, 0.05);
}

// A tube's wall (straight or bent, open at both ends) has Euler characteristic 0: V − E + F − T
// = 0, every interior face shared by two tets, so F = (4T + F_boundary)/2.
TEST_P(VesselMesh, TetEdgesAreListedOnceEachAndSatisfyEulersFormulaForATube) {
  const TetMesh mesh = generate_vessel_mesh(params_for(GetParam(), 0));
  const std::vector<std::array<int, 2>> edges = unique_edges(mesh);
  EXPECT_TRUE(std::is_sorted(edges.begin(), edges.end()));
  EXPECT_EQ(std::adjacent_find(edges.begin(), edges.end()), edges.end());
  for (const auto& [a, b] : edges) ASSERT_LT(a, b);
  const auto V = static_cast<long>(mesh.nodes.size()), T = static_cast<long>(mesh.tets.size());
  const long F = (4 * T + static_cast<long>(boundary_faces(mesh).size())) / 2;
  EXPECT_EQ(V - static_cast<long>(edges.size()) + F - T, 0);
}

TEST(UniqueEdges, TwoTetsSharingAFaceHaveNineEdges) {
  TetMesh mesh;
  mesh.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 1)};
  mesh.tets = {{0, 1, 2, 3}, {3, 2, 1, 4}};
  const std::vector<std::array<int, 2>> expected = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3},
                                                    {1, 4}, {2, 3}, {2, 4}, {3, 4}};
  EXPECT_EQ(unique_edges(mesh), expected);
}

TEST_P(VesselMesh, WallNodesLieOnTheirSurfaces) {
  const VesselParams p = params_for(GetParam(), 0);
  const TetMesh mesh = generate_vessel_mesh(p);
  const double tol = 1e-9;  // m: node placement is exact up to rounding
  for (int n : mesh.group_nodes(*mesh.find_group(group_names::inner_wall, 2))) {
    ASSERT_NEAR(distance_from_centreline(p, mesh.nodes[n]), p.inner_radius, tol);
  }
  for (int n : mesh.group_nodes(*mesh.find_group(group_names::outer_wall, 2))) {
    ASSERT_NEAR(distance_from_centreline(p, mesh.nodes[n]), p.outer_radius(), tol);
  }
  for (int n : mesh.group_nodes(*mesh.find_group(group_names::inlet, 2))) {
    const Vec3& x = mesh.nodes[n];
    if (p.kind == VesselKind::straight) {
      ASSERT_NEAR(x.z(), 0.0, tol);
    } else {
      ASSERT_NEAR(x.y(), 0.0, tol);
      ASSERT_GT(x.x(), 0.0);
    }
  }
  for (int n : mesh.group_nodes(*mesh.find_group(group_names::outlet, 2))) {
    const Vec3& x = mesh.nodes[n];
    if (p.kind == VesselKind::straight) {
      ASSERT_NEAR(x.z(), p.length, tol);
    } else {
      ASSERT_NEAR(x.y(), 0.0, tol);
      ASSERT_LT(x.x(), 0.0);
    }
  }
  // Every node is inside the wall: a − tol ≤ ρ ≤ b + tol.
  for (const auto& x : mesh.nodes) {
    const double rho = distance_from_centreline(p, x);
    ASSERT_GE(rho, p.inner_radius - tol);
    ASSERT_LE(rho, p.outer_radius() + tol);
  }
}

TEST_P(VesselMesh, VolumeAndAreasConvergeToClosedFormsWithLevel) {
  // Straight-sided elements inscribe the circular walls: the chord error is O(h²), so each level
  // should cut the error by about 4 (asserted: by more than 2).
  const VesselParams p0 = params_for(GetParam(), 0);
  const VesselParams p1 = params_for(GetParam(), 1);
  const GeometryErrors e0 = geometry_errors(generate_vessel_mesh(p0), p0);
  const GeometryErrors e1 = geometry_errors(generate_vessel_mesh(p1), p1);
  EXPECT_LT(e0.volume, 0.03);
  EXPECT_LT(e0.inner, 0.03);
  EXPECT_LT(e0.outer, 0.03);
  EXPECT_LT(e0.end, 0.03);
  EXPECT_LT(e1.volume, e0.volume / 2.0);
  EXPECT_LT(e1.inner, e0.inner / 2.0);
  EXPECT_LT(e1.outer, e0.outer / 2.0);
  EXPECT_LT(e1.end, e0.end / 2.0);
  RecordProperty("volume_error_L0", std::to_string(e0.volume));
  RecordProperty("volume_error_L1", std::to_string(e1.volume));
}

INSTANTIATE_TEST_SUITE_P(AllVessels, VesselMesh,
                         ::testing::Values(Case{VesselKind::straight, MeshStyle::unstructured},
                                           Case{VesselKind::straight, MeshStyle::structured},
                                           Case{VesselKind::arch, MeshStyle::unstructured},
                                           Case{VesselKind::arch, MeshStyle::structured}),
                         case_name);

TEST(UnstructuredVessel, SameParamsGiveTheSameMeshWhateverWasMeshedBeforeAndOnAnyThreads) {
  // The mesh cache and the baselines key on the params alone, so the mesh must be theirs alone:
  // not the heap's history (another vessel meshed in between) nor the OpenMP threads.
  const auto mesh_on = [](int threads, const VesselParams& p) {
    const int saved = solver_threads();
    set_solver_threads(threads);
    apply_solver_threads();
    TetMesh m = generate_vessel_mesh(p);
    set_solver_threads(saved);
    apply_solver_threads();
    return m;
  };
  const VesselParams tube;
  VesselParams arch;
  arch.kind = VesselKind::arch;
  const TetMesh first = mesh_on(1, tube);
  mesh_on(1, arch);
  const TetMesh again = mesh_on(4, tube);
  ASSERT_EQ(first.nodes.size(), again.nodes.size());
  ASSERT_EQ(first.tets.size(), again.tets.size());
  for (std::size_t i = 0; i < first.nodes.size(); ++i) ASSERT_EQ(first.nodes[i], again.nodes[i]) << i;
  for (std::size_t i = 0; i < first.tets.size(); ++i) ASSERT_EQ(first.tets[i], again.tets[i]) << i;
}

TEST(StructuredVessel, NodeCountsMatchTheGridAndGrowAbout8xPerLevel) {
  VesselParams p;
  p.style = MeshStyle::structured;
  std::vector<long> nodes;
  for (int level = 0; level <= 1; ++level) {
    p.level = level;
    const TetMesh mesh = generate_vessel_mesh(p);
    EXPECT_EQ(static_cast<long>(mesh.nodes.size()), structured_counts(p).expected_nodes());
    nodes.push_back(static_cast<long>(mesh.nodes.size()));
  }
  // n_c (n_a + 1)(n_r + 1): the "+1" layers make the first ratio ~6.5, tending to 8.
  const double ratio = static_cast<double>(nodes[1]) / static_cast<double>(nodes[0]);
  EXPECT_GT(ratio, 6.0);
  EXPECT_LT(ratio, 8.0);
}

TEST(StructuredVessel, TetCountIsSixPerGridCell) {
  // Every hexahedral-like grid cell (two prisms of a quad split in two triangles) becomes 6 tets.
  VesselParams p;
  p.style = MeshStyle::structured;
  const TetMesh mesh = generate_vessel_mesh(p);
  const auto c = structured_counts(p);
  EXPECT_EQ(static_cast<long>(mesh.tets.size()),
            6L * c.circumferential * c.axial * c.radial);
}

// The graded contact-patch mesh against the tube's closed-form volume and its size field.
TEST(RefinedPatchMesh, IsFineAtThePointCoarseElsewhereAndHasTheTubesVolume) {
  VesselParams params;
  const Vec3 point(params.inner_radius, 0.0, 0.5 * params.length);
  const double fine = 0.15e-3;
  const TetMesh mesh = refined_patch_mesh(params, point, fine, 0.5e-3);
  EXPECT_NO_THROW(require_vessel_groups(mesh, "refined"));
  const MeshQuality q = compute_quality(mesh);
  EXPECT_EQ(q.inverted, 0u);
  // Closed form π(b² − a²)L; the straight-sided tets miss the circular segments (O(h²)).
  const double exact = analytic_wall_volume(params);
  EXPECT_NEAR(q.total_volume, exact, 0.02 * exact);
  // Edges touching the point's neighbourhood are near `fine`; far away near the nominal 1 mm.
  double near_max = 0.0, far_min = 1.0;
  for (const Tet& t : mesh.tets) {
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const Vec3 a = mesh.nodes[t[i]], b = mesh.nodes[t[j]];
        const double len = (a - b).norm();
        if ((0.5 * (a + b) - point).norm() < 0.3e-3) near_max = std::max(near_max, len);
        if ((0.5 * (a + b) - point).norm() > 8e-3) far_min = std::min(far_min, len);
      }
  }
  EXPECT_LT(near_max, 2.5 * fine);
  EXPECT_GT(far_min, 0.3e-3);
  EXPECT_THROW(
      (void)refined_patch_mesh(VesselParams{.kind = VesselKind::mesh_file}, point, fine, 1e-3),
      InputError);
  EXPECT_THROW((void)refined_patch_mesh(params, point, 0.0, 1e-3), InputError);
}

// Two refined balls, on opposite sides of the tube: fine edges at both, coarse between and far.
TEST(RefinedPatchMesh, EveryBallIsRefined) {
  VesselParams params;
  const Vec3 a(params.inner_radius, 0.0, 0.3 * params.length);
  const Vec3 b(-params.inner_radius, 0.0, 0.7 * params.length);
  const double fine = 0.15e-3;
  const TetMesh mesh = refined_balls_mesh(params, {{a, 0.5e-3}, {b, 0.5e-3}}, fine);
  EXPECT_EQ(compute_quality(mesh).inverted, 0u);
  double near_a = 0.0, near_b = 0.0, far_min = 1.0;
  for (const Tet& t : mesh.tets) {
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const Vec3 p = mesh.nodes[t[i]], q = mesh.nodes[t[j]];
        const Vec3 mid = 0.5 * (p + q);
        const double len = (p - q).norm();
        if ((mid - a).norm() < 0.3e-3) near_a = std::max(near_a, len);
        if ((mid - b).norm() < 0.3e-3) near_b = std::max(near_b, len);
        if ((mid - a).norm() > 8e-3 && (mid - b).norm() > 8e-3) far_min = std::min(far_min, len);
      }
  }
  EXPECT_GT(near_a, 0.0);
  EXPECT_GT(near_b, 0.0);
  EXPECT_LT(near_a, 2.5 * fine);
  EXPECT_LT(near_b, 2.5 * fine);
  EXPECT_GT(far_min, 0.3e-3);
  EXPECT_THROW((void)refined_balls_mesh(params, {}, fine), InputError);
  EXPECT_THROW((void)refined_balls_mesh(params, {{a, -1e-3}}, fine), InputError);
}

// The arch's graded mesh: its closed-form volume (Pappus) and fine edges at the apex only.
TEST(RefinedPatchMesh, ArchIsFineAtTheApexAndHasTheArchsVolume) {
  const VesselParams params{.kind = VesselKind::arch};
  // Slightly off the apex on the negative side of x and z: the size field takes negative
  // coordinates.
  const Vec3 apex(-1e-5, params.bend_radius + params.inner_radius, -1e-5);
  const double fine = 0.2e-3;
  const TetMesh mesh = refined_patch_mesh(params, apex, fine, 0.5e-3);
  EXPECT_NO_THROW(require_vessel_groups(mesh, "refined arch"));
  const MeshQuality q = compute_quality(mesh);
  EXPECT_EQ(q.inverted, 0u);
  const double exact = analytic_wall_volume(params);
  EXPECT_NEAR(q.total_volume, exact, 0.02 * exact);
  double near_max = 0.0, far_min = 1.0;
  for (const Tet& t : mesh.tets) {
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const Vec3 a = mesh.nodes[t[i]], b = mesh.nodes[t[j]];
        const double len = (a - b).norm();
        if ((0.5 * (a + b) - apex).norm() < 0.3e-3) near_max = std::max(near_max, len);
        if ((0.5 * (a + b) - apex).norm() > 8e-3) far_min = std::min(far_min, len);
      }
  }
  EXPECT_LT(near_max, 2.5 * fine);
  EXPECT_GT(far_min, 0.3e-3);
}
