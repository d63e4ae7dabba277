/// Contact-patch loads given as quadrature points (vessel::SurfacePoint) against closed forms.
/// For any load vector f, the discrete solution satisfies Clapeyron's theorem 2W = uᵀK u = fᵀu
/// (W the strain energy the solver integrates from ε(u)); so 2W = Σ_i f_i·u_i checks f node by
/// node against the hand-derived loads: a point at barycentric λ gives f_k = w t λ_k to the P1
/// nodes; a uniform traction over a whole triangle gives ∫ N_k t dA = t A/3 to each P1 node, and
/// to the P2 element's edge midpoints (0 to its vertices).
#include <gtest/gtest.h>

#include <cmath>

#include "fem_reference/elasticity.hpp"
#include "fem_test_meshes.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/surface_loads.hpp"

using namespace vessel;
using namespace vessel::fem;

namespace {

const TetMesh& mesh() { return test::short_tube_mesh(0); }

/// A triangle of the inner wall: its nodes are all free (the body is held at its outer wall).
int loaded_triangle() { return mesh().require_group("inner_wall", 2, "test").elements.front(); }

double triangle_area(int t) {
  const auto& tri = mesh().triangles[static_cast<std::size_t>(t)];
  const Vec3 a = mesh().nodes[tri[0]], b = mesh().nodes[tri[1]], c = mesh().nodes[tri[2]];
  return 0.5 * (b - a).cross(c - a).norm();
}

const Vec3 kTraction(40.0, -100.0, 25.0);  // Pa, an arbitrary direction

ElasticityResult solve_with_points(const std::vector<SurfacePoint>& points, int degree,
                                   std::vector<Vec3> probes, std::vector<Vec3>* at_probes) {
  ElasticityProblem p;
  p.options.degree = degree;
  p.options.solver = LinearSolver::direct;
  p.dirichlet = {DirichletCondition::clamped("outer_wall")};
  TractionPatch patch;
  patch.triangles = {loaded_triangle()};
  patch.points = points;
  patch.traction = kTraction;
  p.patches = {patch};
  ElasticitySolver solver(mesh(), p);
  const auto r = solver.solve();
  if (at_probes) *at_probes = solver.displacement_at(probes);
  return r;
}

}  // namespace

TEST(PatchPoints, OnePointAtANodePutsTheWholeLoadOnThatNodeForP1) {
  const int t = loaded_triangle();
  const double w = 2e-8;  // m²
  for (int k = 0; k < 3; ++k) {
    Vec3 bary = Vec3::Zero();
    bary[k] = 1.0;
    const auto r = solve_with_points({{t, bary, w}}, 1, {}, nullptr);
    const Vec3 f = w * kTraction;
    EXPECT_LT((r.applied_load - f).norm(), 1e-14 * f.norm());
    const Vec3& u = r.nodal_displacement[static_cast<std::size_t>(mesh().triangles[t][k])];
    EXPECT_NEAR(2.0 * r.strain_energy, f.dot(u), 1e-8 * std::abs(f.dot(u))) << "node " << k;
  }
}

TEST(PatchPoints, AnInteriorPointSplitsItsLoadByBarycentricsForP1) {
  const int t = loaded_triangle();
  const double w = 3e-8;
  const Vec3 bary(0.2, 0.3, 0.5);
  const auto r = solve_with_points({{t, bary, w}}, 1, {}, nullptr);
  double work = 0.0;
  for (int k = 0; k < 3; ++k) {
    work += w * bary[k] * kTraction.dot(r.nodal_displacement[mesh().triangles[t][k]]);
  }
  EXPECT_NEAR(2.0 * r.strain_energy, work, 1e-8 * std::abs(work));
}

TEST(PatchPoints, WholeTriangleGivesAThirdOfTheAreaToEachP1Node) {
  const int t = loaded_triangle();
  const double area = triangle_area(t);
  const auto r = solve_with_points(whole_triangle_points(t, area), 1, {}, nullptr);
  EXPECT_LT((r.applied_load - area * kTraction).norm(), 1e-13 * area * kTraction.norm());
  double work = 0.0;  // Σ_k (A/3) t·u_k
  for (int k = 0; k < 3; ++k)
    work += area / 3.0 * kTraction.dot(r.nodal_displacement[mesh().triangles[t][k]]);
  EXPECT_NEAR(2.0 * r.strain_energy, work, 1e-8 * std::abs(work));
}

TEST(PatchPoints, WholeTriangleGivesAThirdOfTheAreaToEachP2EdgeMidpointAndNoneToVertices) {
  const int t = loaded_triangle();
  const auto& tri = mesh().triangles[static_cast<std::size_t>(t)];
  const double area = triangle_area(t);
  // ∫ N dA over a triangle for the quadratic Lagrange basis: 0 at the vertices, A/3 at the edge
  // midpoints (e.g. Zienkiewicz & Taylor, The FEM vol. 1, §6.5 / the 6-node triangle).
  std::vector<Vec3> midpoints;
  for (int k = 0; k < 3; ++k)
    midpoints.push_back(0.5 * (mesh().nodes[tri[k]] + mesh().nodes[tri[(k + 1) % 3]]));
  std::vector<Vec3> u_mid;
  const auto r = solve_with_points(whole_triangle_points(t, area), 2, midpoints, &u_mid);
  double work = 0.0;
  for (const Vec3& u : u_mid) work += area / 3.0 * kTraction.dot(u);
  EXPECT_NEAR(2.0 * r.strain_energy, work, 1e-8 * std::abs(work));
  // The vertices' share is zero: their displacement does not enter 2W.
  double with_vertices = work;
  for (int k = 0; k < 3; ++k)
    with_vertices += area / 3.0 * kTraction.dot(r.nodal_displacement[tri[k]]);
  EXPECT_GT(std::abs(with_vertices - work), 1e-3 * std::abs(work));
}

TEST(PatchPoints, PointOffTheMeshOrNonFiniteBarycentricsIsAnInputError) {
  const int t = loaded_triangle();
  for (const SurfacePoint& bad :
       {SurfacePoint{-1, Vec3(1, 0, 0), 1e-8},
        SurfacePoint{static_cast<int>(mesh().triangles.size()), Vec3(1, 0, 0), 1e-8},
        SurfacePoint{t, Vec3(NAN, 0, 1), 1e-8}}) {
    std::string msg;
    try {
      (void)solve_with_points({bad}, 1, {}, nullptr);
    } catch (const InputError& e) {
      msg = e.what();
    }
    EXPECT_NE(msg.find("traction patch point 0"), std::string::npos) << msg;
  }
}
