// The wire and the wall as one potential (contact::solve_wire_wall_potential): the gap's exact
// derivatives against finite differences, the finite-strain wall's energy against its linear
// limit and finite differences, the rigid limit against the shooting reference, two contact
// formulations (Alart–Curnier, penalty extrapolated to infinite stiffness) against each
// other, action and reaction through the wall's own support reactions, the wall condensed on a
// band against the whole wall and a direct solve. Rows "WIRE-WALL-POTENTIAL".
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <utility>

#include "../../fem/cube_mesh.hpp"
#include "fem_reference/hyperelastic.hpp"
#include "fem_reference/rod_theory/tube_contact.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/fem/linear_tet.hpp"
#include "verification/contact/condensed_wall_potential.hpp"
#include "verification/contact/point_segment_distance.hpp"
#include "verification/contact/point_triangle_distance.hpp"
#include "verification/contact/wall_crossing.hpp"
#include "verification/contact/wire_wall_potential.hpp"
#include "wire_in_tube.hpp"

using namespace vessel;
using namespace vessel::wire_in_tube;
using Eigen::VectorXd;

namespace {

using Vec9 = Eigen::Matrix<double, 9, 1>;

Vec9 stack(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  Vec9 q;
  q << p, a, b;
  return q;
}

contact::PointSegmentDistance at(const Vec9& q, bool hessian) {
  return contact::point_segment_distance(q.head<3>(), q.segment<3>(3), q.tail<3>(), hessian);
}

/// The largest differences of a distance's gradient and Hessian from central differences of its
/// value and gradient (step 1e-6) at coordinates q: {gradient's, Hessian's}.
template <class Q, class Distance>
std::pair<double, double> central_difference_errors(const Q& q, Distance at) {
  constexpr double h = 1e-6;
  const auto d = at(q, true);
  double g_err = 0.0, h_err = 0.0;
  for (int k = 0; k < q.size(); ++k) {
    Q qp = q, qm = q;
    qp[k] += h;
    qm[k] -= h;
    const auto dp = at(qp, true), dm = at(qm, true);
    g_err = std::max(g_err, std::abs((dp.distance - dm.distance) / (2 * h) - d.gradient[k]));
    h_err = std::max(
        h_err, ((dp.gradient - dm.gradient) / (2 * h) - d.hessian.col(k)).cwiseAbs().maxCoeff());
  }
  return {g_err, h_err};
}

}  // namespace

// d and its derivatives against central differences, inside the segment and beyond either end.
TEST(PointSegmentDistance, DerivativesMatchFiniteDifferences) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d a(0.1, -0.2, 0.05), b(1.1, 0.3, -0.2);
  // Points whose nearest point is inside, before a and beyond b.
  for (const double along : {0.4, -0.5, 1.6}) {
    for (int trial = 0; trial < 4; ++trial) {
      const Eigen::Vector3d off(u(rng), u(rng), u(rng));
      const Eigen::Vector3d p = a + along * (b - a) + 0.5 * off;
      const Vec9 q = stack(p, a + 0.01 * off, b - 0.02 * off);
      const auto d = at(q, true);
      const auto [g_err, h_err] = central_difference_errors(q, at);
      EXPECT_LT(g_err, 1e-8) << "along " << along;
      EXPECT_LT(h_err, 1e-6 * std::max(1.0, d.hessian.cwiseAbs().maxCoeff())) << "along " << along;
      EXPECT_LT((d.hessian - d.hessian.transpose()).cwiseAbs().maxCoeff(), 1e-12);
      // Translating everything leaves d unchanged: the gradient's three blocks sum to zero (the
      // contact forces on the wall and the wire are equal and opposite).
      EXPECT_LT((d.gradient.head<3>() + d.gradient.segment<3>(3) + d.gradient.tail<3>()).norm(),
                1e-14);
    }
  }
  EXPECT_THROW((void)contact::point_segment_distance(a, a, a, false), std::invalid_argument);
}

// d to a triangle and its derivatives against central differences, with the nearest point inside,
// on each edge and at each corner; d itself against the mesh library's closest point.
TEST(PointTriangleDistance, DerivativesMatchFiniteDifferences) {
  using Vec12 = Eigen::Matrix<double, 12, 1>;
  const auto at = [](const Vec12& q, bool hessian) {
    return contact::point_triangle_distance(q.head<3>(), q.segment<3>(3), q.segment<3>(6),
                                            q.tail<3>(), hessian);
  };
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d a(0.1, -0.2, 0.05), b(1.1, 0.3, -0.2), c(0.2, 0.9, 0.3);
  const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
  // Barycentric targets: inside, beyond each edge, beyond each corner.
  const std::vector<Eigen::Vector3d> targets{{0.3, 0.3, 0.4},  {0.5, 0.8, -0.3},  {-0.3, 0.5, 0.8},
                                             {0.6, -0.4, 0.8}, {1.5, -0.2, -0.3}, {-0.3, 1.5, -0.2},
                                             {-0.2, -0.3, 1.5}};
  for (const Eigen::Vector3d& w : targets) {
    for (int trial = 0; trial < 3; ++trial) {
      const Eigen::Vector3d off(u(rng), u(rng), u(rng));
      const Eigen::Vector3d p =
          w[0] * a + w[1] * b + w[2] * c + (0.4 + 0.2 * trial) * n + 0.05 * off;
      Vec12 q;
      q << p, a + 0.01 * off, b - 0.02 * off, c + 0.015 * off;
      const auto d = at(q, true);
      const Eigen::Vector3d nearest =
          closest_point_on_triangle(q.segment<3>(3), q.segment<3>(6), q.tail<3>(), p);
      EXPECT_NEAR(d.distance, (p - nearest).norm(), 1e-14);
      EXPECT_NEAR(d.weights.sum(), 1.0, 1e-14);
      EXPECT_LT((d.weights[0] * q.segment<3>(3) + d.weights[1] * q.segment<3>(6) +
                 d.weights[2] * q.tail<3>() - nearest)
                    .norm(),
                1e-13);
      const auto [g_err, h_err] = central_difference_errors(q, at);
      EXPECT_LT(g_err, 1e-8) << "barycentric target " << w.transpose();
      EXPECT_LT(h_err, 1e-6 * std::max(1.0, d.hessian.cwiseAbs().maxCoeff()))
          << "barycentric target " << w.transpose();
      EXPECT_LT((d.hessian - d.hessian.transpose()).cwiseAbs().maxCoeff(), 1e-12);
      // Equal and opposite: the four blocks of the gradient sum to zero.
      EXPECT_LT((d.gradient.head<3>() + d.gradient.segment<3>(3) + d.gradient.segment<3>(6) +
                 d.gradient.tail<3>())
                    .norm(),
                1e-14);
    }
  }
  EXPECT_THROW((void)contact::point_triangle_distance(a, a, b, b, false), std::invalid_argument);
  EXPECT_THROW((void)contact::point_triangle_distance((a + b + c) / 3.0, a, b, c, false),
               std::invalid_argument);
}

// Möller–Trumbore by hand: the triangle (0,0,0), (1,0,0), (0,1,0) in z = 0.
TEST(WallCrossing, SegmentTriangleByHand) {
  const Vec3 p(0, 0, 0), q(1, 0, 0), r(0, 1, 0);
  const auto through = contact::segment_triangle_crossing(Vec3(0.2, 0.3, -1), Vec3(0.2, 0.3, 3), p, q, r);
  ASSERT_TRUE(through);
  EXPECT_NEAR(*through, 0.25, 1e-15);
  // Beyond the hypotenuse (u + v > 1), beside an edge (v < 0), short of the plane, in the plane.
  EXPECT_FALSE(contact::segment_triangle_crossing(Vec3(0.6, 0.6, -1), Vec3(0.6, 0.6, 1), p, q, r));
  EXPECT_FALSE(contact::segment_triangle_crossing(Vec3(0.5, -0.1, -1), Vec3(0.5, -0.1, 1), p, q, r));
  EXPECT_FALSE(contact::segment_triangle_crossing(Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, -0.1), p, q, r));
  EXPECT_FALSE(contact::segment_triangle_crossing(Vec3(-1, 0.2, 0), Vec3(2, 0.2, 0), p, q, r));
}

// On the tube (inner radius kA): a centreline inside the lumen crosses nothing; one carried
// radially out to 1.2 kA crosses the inner wall where it leaves (at radius kA, between nodes);
// the same wall displaced outward by 0.3 kA holds it again.
TEST(WallCrossing, CentrelineThroughTheTubeWall) {
  const TetMesh& mesh = tube_mesh();
  const std::vector<Triangle> inner = mesh.group_triangles(mesh.require_group("inner_wall", 2, "tube"));
  const std::vector<Vec3> rest(mesh.nodes.size(), Vec3::Zero());
  const double zm = 0.5 * kTubeLength;
  std::vector<Vec3> wire;
  for (int i = 0; i <= 10; ++i) wire.emplace_back(0.09 * kA * i, 0.013 * kA * i, zm);
  EXPECT_FALSE(contact::first_wall_crossing(mesh, inner, rest, wire));
  for (Vec3& x : wire) x *= 1.2 / 0.9;
  const auto c = contact::first_wall_crossing(mesh, inner, rest, wire);
  ASSERT_TRUE(c);
  EXPECT_NEAR(std::hypot(c->point.x(), c->point.y()), kA, 0.02 * kA);  // chords of the circle
  // The crossed triangle's longest edge (at rest here), which the failure's message reports.
  const Triangle& t = inner[static_cast<std::size_t>(c->triangle)];
  const auto node = [&](int k) { return mesh.nodes[static_cast<std::size_t>(t[k])]; };
  EXPECT_DOUBLE_EQ(c->longest_edge,
                   std::max({(node(0) - node(1)).norm(), (node(1) - node(2)).norm(),
                             (node(2) - node(0)).norm()}));
  EXPECT_NE(contact::describe(*c).find("longest edge is"), std::string::npos);
  std::vector<Vec3> out(mesh.nodes.size());
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    out[n] = 0.3 * Vec3(mesh.nodes[n].x(), mesh.nodes[n].y(), 0.0);
  }
  EXPECT_FALSE(contact::first_wall_crossing(mesh, inner, out, wire));
}

// A wire whose centreline goes through the wall: on the structured tube (nodes ~1 mm apart, far
// more than the wire's diameter) every node's gap is open on the far side, so a solve from there
// would "converge" outside the lumen. Started through the wall (the rigid solution carried out
// about the clamp to 1.4 times its reach, the tip 1 mm beyond the inner wall), it refuses with
// the crossing named; started from the inside with no candidate near the wire (only the
// outlet's nodes), the wire springs back towards straight, through the wall, and the first step
// that carries its centreline through ends the solve with the crossing named. A wall start that
// turns cells inside out (a level's start interpolated from a coarser level's deep dent can) is
// refused before any Newton step: every trial step near it is inverted too.
TEST(WireWallPotential, ACentrelineThroughTheWallIsRefusedNotSolved) {
  const TetMesh& mesh = tube_mesh();
  const std::vector<int> nodes = inner_nodes(mesh);
  const double d = 0.356e-3;
  const double length = rod_theory::straight_tube_contact(kTheta, (kA - d / 2) / kZc).length * kZc;
  const Vec3 origin(0, 0, 5e-3);
  Wire w(d, length, 32, origin);
  const RigidRun rigid = rigid_run(w);
  VectorXd outside = rigid.x;
  for (int i = 0; i < w.rod.num_nodes(); ++i) {
    outside.segment<3>(3 * i) = origin + 1.4 * (rigid.x.segment<3>(3 * i) - origin);
  }
  contact::PotentialContactOptions o;
  o.force_scale = w.EI / (kZc * kZc);
  const contact::NeoHookeanWall wall(mesh, wall_problem(kWallE));
  std::optional<contact::WireThroughWall> last;
  const auto message = [&](const VectorXd& start, const std::vector<int>& candidates) {
    try {
      (void)contact::solve_wire_wall_potential(w.rod, w.radius, wall, mesh, candidates, start, o);
    } catch (const contact::WireThroughWall& e) {
      EXPECT_EQ(static_cast<int>(e.centreline.size()), w.layout.tip_node - w.layout.first_node + 1);
      last = e;
      return std::string(e.what());
    } catch (const std::runtime_error& e) {
      return std::string("another error: ") + e.what();
    }
    return std::string("solved");
  };
  const std::string from_outside = message(outside, nodes);
  EXPECT_NE(from_outside.find("cannot start outside the lumen"), std::string::npos) << from_outside;
  EXPECT_NE(from_outside.find("crosses the wall"), std::string::npos) << from_outside;
  // The start, not the solve, put it there: no claim that it slipped between the wall's nodes.
  EXPECT_EQ(from_outside.find("passed between"), std::string::npos) << from_outside;
  std::vector<int> outlet;
  for (const int n : nodes) {
    if (mesh.nodes[static_cast<std::size_t>(n)].z() > kTubeLength - 1e-3) outlet.push_back(n);
  }
  ASSERT_FALSE(outlet.empty());
  const std::string through = message(rigid.x, outlet);
  EXPECT_NE(through.find("stopped after Newton step"), std::string::npos) << through;
  EXPECT_NE(through.find("crosses the wall"), std::string::npos) << through;
  EXPECT_NE(through.find("passed between the wall's nodes"), std::string::npos) << through;
  // A wall start mirrored through the tube's middle turns the cells inside out (det F = −1 away
  // from the clamped ends, whose held rows stay at rest).
  const Vec3 middle(0, 0, 0.5 * kTubeLength);
  const VectorXd inverted =
      fem::interpolate_rows(wall.dofs(), [&](const Vec3& x) -> Vec3 { return 2.0 * (middle - x); });
  // The crossing holds the wall's rows where it crossed: a whole wall adds nothing to its message;
  // the same crossing on the wall turned inside out names its inverted tets, every tet but those
  // at the clamped ends.
  ASSERT_TRUE(last.has_value());
  ASSERT_EQ(last->wall_rows.size(), wall.num_dofs());
  EXPECT_EQ(std::string(contact::with_inverted_tets(*last, wall, mesh).what()), through);
  contact::WireThroughWall folded = *last;
  folded.wall_rows = inverted;
  const std::string named = contact::with_inverted_tets(folded, wall, mesh).what();
  const std::size_t at = named.rfind(" (");
  ASSERT_NE(at, std::string::npos) << named;
  EXPECT_EQ(named.substr(0, at), through);
  const double count = std::stod(named.substr(at + 2));
  EXPECT_GT(count, 0.8 * static_cast<double>(mesh.tets.size())) << named;
  EXPECT_LE(count, static_cast<double>(mesh.tets.size())) << named;
  EXPECT_NE(named.find("of the wall's tets inverted: it had folded)"), std::string::npos) << named;
  try {
    (void)contact::solve_wire_wall_potential(w.rod, w.radius, wall, mesh, nodes, rigid.x, o,
                                             inverted);
    ADD_FAILURE() << "an inverted wall start was solved";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("inverts an element"), std::string::npos) << e.what();
  }
}

// The finite-strain wall's energy, gradient and tangent (fem::HyperelasticSolver::free_state): at
// rest its tangent is the linear wall's stiffness (the same mesh and supports, deal.II's linear
// assembly) to round-off; away from rest its gradient and tangent are the central differences of
// its energy and gradient.
TEST(NeoHookeanWall, StateMatchesLinearLimitAndFiniteDifferences) {
  const TetMesh& mesh = tube_mesh();
  const fem::ElasticityProblem problem = wall_problem(kWallE);
  const contact::NeoHookeanWall wall(mesh, problem);
  const fem::ElasticitySolver linear(mesh, problem);
  const fem::FreeDisplacementSystem sys = linear.free_displacement_system();
  ASSERT_EQ(wall.num_dofs(), sys.K.rows());
  VectorXd g;
  Eigen::SparseMatrix<double> H;
  const double e0 = wall.evaluate(VectorXd::Zero(wall.num_dofs()), &g, &H);
  EXPECT_NEAR(e0, 0.0, 1e-30);
  EXPECT_LT(g.norm(), 1e-12);
  const Eigen::SparseMatrix<double> diff = H - sys.K;
  const double kmax = Eigen::MatrixXd(sys.K.diagonal()).cwiseAbs().maxCoeff();
  double worst = 0.0;
  for (int c = 0; c < diff.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(diff, c); it; ++it)
      worst = std::max(worst, std::abs(it.value()));
  std::printf("WIRE-WALL-POTENTIAL neo-Hookean tangent at rest - linear K: %.2e of max K_ii\n",
              worst / kmax);
  EXPECT_LT(worst, 1e-10 * kmax);
  // A displacement of strain ~0.05: a smooth field over the tube.
  VectorXd u(wall.num_dofs());
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    const Vec3& x = mesh.nodes[n];
    const Vec3 v(0.05 * std::sin(200 * x.z()) * 1e-3, 0.03e-3 * std::cos(300 * x.x()),
                 0.02 * x.y());
    for (int c = 0; c < 3; ++c) {
      if (wall.node_rows()[n][c] >= 0) u[wall.node_rows()[n][c]] = v[c];
    }
  }
  VectorXd gu;
  Eigen::SparseMatrix<double> Hu;
  (void)wall.evaluate(u, &gu, &Hu);
  const VectorXd dir = VectorXd::Random(wall.num_dofs()) * 1e-6;
  constexpr double h = 1e-3;
  VectorXd gp, gm;
  const double ep = wall.evaluate(u + h * dir, &gp, nullptr);
  const double em = wall.evaluate(u - h * dir, &gm, nullptr);
  const double slope = (ep - em) / (2 * h);
  std::printf("WIRE-WALL-POTENTIAL neo-Hookean gradient: directional %.9e vs FD %.9e\n",
              gu.dot(dir), slope);
  EXPECT_NEAR(gu.dot(dir), slope, 1e-6 * std::abs(slope));
  const VectorXd hd = Hu * dir, fd = (gp - gm) / (2 * h);
  EXPECT_LT((hd - fd).norm(), 1e-6 * hd.norm());
}

namespace {

// The inner wall's edges (mesh node pairs, each once): derived here from its triangles, apart
// from the solve's own list.
std::vector<std::array<int, 2>> inner_wall_edges(const TetMesh& mesh) {
  std::vector<std::array<int, 2>> edges;
  for (const Triangle& t : mesh.group_triangles(mesh.require_group("inner_wall", 2, "tube"))) {
    for (int e = 0; e < 3; ++e) {
      const int a = t[e], b = t[(e + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b)});
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

}  // namespace

// A P2 wall's mid-edge nodes (NeoHookeanWall::edge_nodes): one per inner-wall edge whose middle
// is not held (the clamped ends hold the edges lying in them), at the chord's midpoint on
// straight-sided tets and on the cylinder r = a, off the chord, with the tube's curved mapping;
// their rows are their own (no vertex's, no other edge's). A P1 wall has none.
TEST(NeoHookeanWall, P2MidEdgeNodesSitAtTheInnerWallsEdgeMiddles) {
  const TetMesh& mesh = tube_mesh();
  const std::vector<std::array<int, 2>> edges = inner_wall_edges(mesh);
  fem::ElasticityProblem problem = wall_problem(kWallE);
  EXPECT_TRUE(contact::NeoHookeanWall(mesh, problem).edge_nodes(mesh, edges).empty());
  problem.options.degree = 2;
  for (const bool curved : {false, true}) {
    if (curved) problem.curved_surfaces = fem::tube_curved_walls(kA, kA + 1e-3);
    const contact::NeoHookeanWall wall(mesh, problem);
    const std::vector<contact::EdgeNode> middles = wall.edge_nodes(mesh, edges);
    std::size_t held_edges = 0;
    for (const auto& [a, b] : edges) {
      held_edges += wall.node_rows()[a][0] < 0 && wall.node_rows()[b][0] < 0;
    }
    EXPECT_EQ(middles.size(), edges.size() - held_edges) << (curved ? "curved" : "flat");
    std::set<int> rows;
    for (const auto& node_rows : wall.node_rows()) {
      for (const int r : node_rows) {
        if (r >= 0) rows.insert(r);
      }
    }
    const std::size_t vertex_rows = rows.size();
    double off_chord = 0.0, off_cylinder = 0.0;
    for (const contact::EdgeNode& m : middles) {
      for (const int r : m.rows) {
        EXPECT_GE(r, 0);
        rows.insert(r);
      }
      off_chord = std::max(off_chord, (m.rest - 0.5 * (mesh.nodes[m.a] + mesh.nodes[m.b])).norm());
      off_cylinder = std::max(off_cylinder, std::abs(std::hypot(m.rest.x(), m.rest.y()) - kA));
    }
    std::printf(
        "WIRE-WALL-POTENTIAL P2 mid-edge nodes (%s): %zu of %zu inner-wall edges (%zu held), "
        "largest distance from the chord's midpoint %.2e m, from the cylinder r = a %.2e m\n",
        curved ? "curved" : "flat", middles.size(), edges.size(), held_edges, off_chord,
        off_cylinder);
    EXPECT_EQ(rows.size(), vertex_rows + 3 * middles.size());
    if (curved) {
      EXPECT_LT(off_cylinder, 1e-12);
      EXPECT_GT(off_chord, 1e-5);  // a 0.78 mm chord's sagitta on r = 3 mm: 2.6e-5 m
    } else {
      EXPECT_LT(off_chord, 1e-12);
    }
  }
}

// A field linear in space, given at the mesh's nodes, onto a wall's rows (linear_field_rows): on
// P1 and on straight-sided P2 every row takes the field's value at its own support point (the
// rows' points deal.II reports), vertices and edge middles alike, to round-off.
TEST(NeoHookeanWall, ALinearFieldAtTheNodesIsItselfOnP1AndP2Rows) {
  const TetMesh& mesh = tube_mesh();
  Eigen::Matrix3d A;
  A << 0.01, -0.02, 0.03, 0.005, 0.015, -0.01, -0.02, 0.01, 0.025;
  const Vec3 b(1e-4, -2e-4, 3e-4);
  const auto field = [&](const Vec3& x) -> Vec3 { return A * x + b; };
  std::vector<Vec3> nodal;
  for (const Vec3& x : mesh.nodes) nodal.push_back(field(x));
  fem::ElasticityProblem problem = wall_problem(kWallE);
  for (const int degree : {1, 2}) {
    problem.options.degree = degree;
    const contact::NeoHookeanWall wall(mesh, problem);
    const VectorXd u = contact::linear_field_rows(wall, mesh, nodal);
    const fem::FreeDisplacementSystem& rows = wall.dofs();
    ASSERT_EQ(u.size(), static_cast<Eigen::Index>(rows.row_points.size()));
    double worst = 0.0;
    for (std::size_t r = 0; r < rows.row_points.size(); ++r) {
      const double exact = field(rows.row_points[r])[rows.row_components[r]];
      worst = std::max(worst, std::abs(u[static_cast<Eigen::Index>(r)] - exact));
    }
    std::printf("WIRE-WALL-POTENTIAL linear field on P%d rows: %zu rows, largest error %.2e m\n",
                degree, rows.row_points.size(), worst);
    EXPECT_LT(worst, 1e-15);
  }
}

// The linear wall's mid-edge nodes (LinearWall::edge_nodes) from deal.II's linear system: at P2
// the same points as the neo-Hookean wall's (its own rows), with the system's row points filled;
// without them a P2 system's candidates cannot be found and it says so; at P1 none.
TEST(LinearWall, P2MidEdgeNodesAreTheNeoHookeanWallsPoints) {
  const TetMesh& mesh = tube_mesh();
  const std::vector<std::array<int, 2>> edges = inner_wall_edges(mesh);
  fem::ElasticityProblem problem = wall_problem(kWallE);
  EXPECT_TRUE(contact::LinearWall(fem::ElasticitySolver(mesh, problem).free_displacement_system())
                  .edge_nodes(mesh, edges)
                  .empty());
  problem.options.degree = 2;
  problem.curved_surfaces = fem::tube_curved_walls(kA, kA + 1e-3);
  const fem::ElasticitySolver solver(mesh, problem);
  fem::FreeDisplacementSystem system = solver.free_displacement_system();
  EXPECT_THROW((void)contact::LinearWall(system).edge_nodes(mesh, edges), std::logic_error);
  solver.set_row_points(system);
  const std::vector<contact::EdgeNode> linear =
      contact::LinearWall(std::move(system)).edge_nodes(mesh, edges);
  const std::vector<contact::EdgeNode> neo_hookean =
      contact::NeoHookeanWall(mesh, problem).edge_nodes(mesh, edges);
  ASSERT_EQ(linear.size(), neo_hookean.size());
  ASSERT_GT(linear.size(), 1000u);
  double apart = 0.0;
  for (std::size_t i = 0; i < linear.size(); ++i) {
    EXPECT_EQ(std::tie(linear[i].a, linear[i].b), std::tie(neo_hookean[i].a, neo_hookean[i].b));
    apart = std::max(apart, (linear[i].rest - neo_hookean[i].rest).norm());
  }
  EXPECT_LT(apart, 1e-15);
}

// A field carried from another mesh may fold a few cells (the solve's start is then refused):
// fem::HyperelasticSolver::inverted_cells finds them (for P1, the tets whose deformed signed
// volume, computed here by hand, is not positive), and NeoHookeanWall::untangled smooths their
// rows until none is inverted, keeping the field away from the fold; a field mirrored through
// the tube's middle (every cell inside out) is not unfolded by smoothing, and says so.
TEST(NeoHookeanWall, UntangledUnfoldsAFewInvertedCellsAndKeepsTheFieldElsewhere) {
  const TetMesh& mesh = tube_mesh();
  const contact::NeoHookeanWall wall(mesh, wall_problem(kWallE));
  const auto smooth = [](const Vec3& x) {  // a dent-like field, strain ~0.1
    return Vec3(-0.1 * x.x() * std::exp(-std::pow((x.z() - 25e-3) / 3e-3, 2)), 0.0, 0.0);
  };
  VectorXd u = fem::interpolate_rows(wall.dofs(), smooth);
  ASSERT_TRUE(std::isfinite(wall.evaluate(u, nullptr, nullptr)));
  // The free node nearest the tube's middle section.
  std::size_t pushed = mesh.nodes.size();
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    const auto& rows = wall.node_rows()[n];
    if (rows[0] < 0 || rows[1] < 0 || rows[2] < 0) continue;
    if (pushed == mesh.nodes.size() ||
        std::abs(mesh.nodes[n].z() - 25e-3) < std::abs(mesh.nodes[pushed].z() - 25e-3))
      pushed = n;
  }
  ASSERT_LT(pushed, mesh.nodes.size());
  double star = 0.0;  // the farthest node sharing a tet with it
  for (const Tet& t : mesh.tets) {
    if (std::find(t.begin(), t.end(), static_cast<int>(pushed)) == t.end()) continue;
    for (const int n : t)
      star = std::max(star, (mesh.nodes[static_cast<std::size_t>(n)] - mesh.nodes[pushed]).norm());
  }
  VectorXd folded = u;  // pushed twice its star's size along x, through its neighbours
  folded[wall.node_rows()[pushed][0]] += 2.0 * star;
  // The inverted tets by hand: deformed signed volume ≤ 0.
  const std::vector<Vec3> d = wall.nodal(folded);
  std::set<int> by_hand;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    std::array<Vec3, 4> q;
    for (int i = 0; i < 4; ++i) {
      const auto n = static_cast<std::size_t>(mesh.tets[t][static_cast<std::size_t>(i)]);
      q[static_cast<std::size_t>(i)] = mesh.nodes[n] + d[n];
    }
    if ((q[1] - q[0]).cross(q[2] - q[0]).dot(q[3] - q[0]) <= 0.0)
      by_hand.insert(static_cast<int>(t));
  }
  const std::vector<int> inverted = wall.inverted_cells(folded);
  std::printf("WIRE-WALL-POTENTIAL a node pushed %.2f mm: %zu cells inverted (by hand %zu)\n",
              2e3 * star, inverted.size(), by_hand.size());
  ASSERT_FALSE(by_hand.empty());
  EXPECT_EQ(std::set<int>(inverted.begin(), inverted.end()), by_hand);
  EXPECT_FALSE(std::isfinite(wall.evaluate(folded, nullptr, nullptr)));

  const std::optional<VectorXd> fixed = wall.untangled(folded);
  ASSERT_TRUE(fixed.has_value());
  EXPECT_TRUE(wall.inverted_cells(*fixed).empty());
  EXPECT_TRUE(std::isfinite(wall.evaluate(*fixed, nullptr, nullptr)));
  // The pushed node back near the smooth field (its neighbours' mean), and every node beyond
  // the smoothing's reach (its star and six rings more) untouched.
  const Vec3 back = wall.nodal(*fixed)[pushed], expected = smooth(mesh.nodes[pushed]);
  std::printf(
      "WIRE-WALL-POTENTIAL after smoothing: the pushed node %.3e m from the smooth field "
      "(pushed %.3e m)\n",
      (back - expected).norm(), 2.0 * star);
  EXPECT_LT((back - expected).norm(), 0.1 * star);
  int far_changed = 0;
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    if ((mesh.nodes[n] - mesh.nodes[pushed]).norm() < 7.0 * star) continue;
    for (const int r : wall.node_rows()[n]) far_changed += r >= 0 && (*fixed)[r] != folded[r];
  }
  EXPECT_EQ(far_changed, 0);
  EXPECT_EQ(wall.untangled(u), u);  // nothing folded: unchanged

  const Vec3 middle(0, 0, 0.5 * kTubeLength);
  const VectorXd mirrored =
      fem::interpolate_rows(wall.dofs(), [&](const Vec3& x) -> Vec3 { return 2.0 * (middle - x); });
  EXPECT_FALSE(wall.untangled(mirrored).has_value());
}

namespace {

/// The number of negative pivots of H's LDLᵀ (its negative eigenvalues, by Sylvester's law of
/// inertia), or −1 if the factorisation fails.
int negative_eigenvalues(const Eigen::SparseMatrix<double>& H) {
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(H);
  if (ldlt.info() != Eigen::Success) return -1;
  return static_cast<int>((ldlt.vectorD().array() < 0.0).count());
}

// Whether A + shift·I is positive definite (a sparse Cholesky factorisation succeeds).
bool positive_definite_after_shift(const Eigen::SparseMatrix<double>& A, double shift) {
  Eigen::SparseMatrix<double> I(A.rows(), A.cols());
  I.setIdentity();
  const Eigen::SparseMatrix<double> shifted = A + shift * I;
  return Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>(shifted).info() == Eigen::Success;
}

}  // namespace

// The wall's tangent projected onto the PSD cone per cell (the projected Newton's Hessian): at
// rest, where every cell's tangent is already PSD, it is the exact tangent; under an axial
// compression of 40 %, where the exact tangent is indefinite (negative pivots in its LDLᵀ),
// the projected one has none, and exceeds the exact one by a positive semidefinite matrix (each
// cell's negative eigenvalues raised to zero, nothing lowered).
TEST(NeoHookeanWall, ProjectedTangentIsPositiveSemidefiniteAndExactWhereTheCellsAre) {
  const TetMesh& mesh = tube_mesh();
  const contact::NeoHookeanWall wall(mesh, wall_problem(kWallE));
  VectorXd g;
  Eigen::SparseMatrix<double> exact, projected;
  const VectorXd rest = VectorXd::Zero(wall.num_dofs());
  (void)wall.evaluate(rest, &g, &exact, false);
  (void)wall.evaluate(rest, &g, &projected, true);
  const double scale = Eigen::MatrixXd(exact.diagonal()).cwiseAbs().maxCoeff();
  EXPECT_LT(Eigen::MatrixXd(exact - projected).cwiseAbs().maxCoeff(), 1e-12 * scale);
  VectorXd u = rest;
  double z0 = mesh.nodes.front().z(), z1 = z0;
  for (const Vec3& x : mesh.nodes) {
    z0 = std::min(z0, x.z());
    z1 = std::max(z1, x.z());
  }
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    const double s = (mesh.nodes[n].z() - z0) / (z1 - z0);
    // 40 % shorter in the middle, the clamped ends held: u_z = −0.4 (z − z_mid) inside a ramp.
    const double uz = -0.4 * (z1 - z0) * std::sin(M_PI * s) * (s - 0.5);
    if (wall.node_rows()[n][2] >= 0) u[wall.node_rows()[n][2]] = uz;
  }
  ASSERT_TRUE(std::isfinite(wall.evaluate(u, &g, &exact, false)));
  (void)wall.evaluate(u, &g, &projected, true);
  const int negative = negative_eigenvalues(exact);
  std::printf("WIRE-WALL-POTENTIAL compressed wall: exact tangent %d negative pivots, projected %d\n",
              negative, negative_eigenvalues(projected));
  EXPECT_GT(negative, 0);
  EXPECT_EQ(negative_eigenvalues(projected), 0);
  EXPECT_TRUE(positive_definite_after_shift(projected - exact, 1e-9 * scale));
  // Both from one pass over the cells: each the one its own evaluation gives, to the bit.
  VectorXd g_both;
  Eigen::SparseMatrix<double> exact_both, projected_both;
  const double e_both = wall.evaluate_both(u, &g_both, exact_both, projected_both);
  EXPECT_EQ(e_both, wall.evaluate(u, nullptr, nullptr));
  EXPECT_EQ((g_both - g).cwiseAbs().maxCoeff(), 0.0);
  for (const auto& [one_pass, own] :
       {std::pair{&exact_both, &exact}, {&projected_both, &projected}}) {
    ASSERT_EQ(one_pass->nonZeros(), own->nonZeros());
    EXPECT_EQ(Eigen::MatrixXd(*one_pass - *own).cwiseAbs().maxCoeff(), 0.0);
  }
}

namespace {

/// The straight-tube wire (DER, N = 32) aimed at the structured tube's node, against `wall`:
/// its rigid-wall state and the potential's solution.
struct PotentialRun {
  contact::PotentialContactSolution solution;
  double rigid_force = 0.0;
  /// The rigid-wall solve's force against the cylinder on which the tip's hemisphere rests on the
  /// faceted wall at the solution's tip (radius a + wall_shift, wall_shift ≤ 0: the faces lie
  /// inside the cylinder, and the hemisphere sits in the groove between two of them).
  double faceted_force = 0.0;
  double wall_shift = 0.0;
  double EI = 0.0;
  Vec3 clamp = Vec3::Zero();
};

/// How far inside the cylinder r = a a ball of radius r_w rests on the faceted inner wall, at the
/// azimuth and height of `tip` (m, ≤ 0): the largest ρ at which the ball centred ρ from the axis
/// clears every inner-wall triangle, found by bisection on the mesh's own closest points, + r_w −
/// a.
double resting_shift(const TetMesh& mesh, const Vec3& tip, double radius) {
  const Vec3 radial = Vec3(tip.x(), tip.y(), 0).normalized();
  std::vector<Triangle> near;
  for (const Triangle& t : mesh.group_triangles(mesh.require_group("inner_wall", 2, "tube"))) {
    if ((mesh.nodes[t[0]] - tip).norm() < 3e-3) near.push_back(t);
  }
  const auto clears = [&](double rho) {
    const Vec3 centre = rho * radial + Vec3(0, 0, tip.z());
    for (const Triangle& t : near) {
      const Vec3 q =
          closest_point_on_triangle(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], centre);
      if ((q - centre).norm() < radius) return false;
    }
    return true;
  };
  double lo = kA - 2 * radius, hi = kA;  // clears at lo, not at hi
  for (int i = 0; i < 60; ++i) (clears(0.5 * (lo + hi)) ? lo : hi) = 0.5 * (lo + hi);
  return lo + radius - kA;
}

PotentialRun potential_run(const TetMesh& mesh, const Vec3& target, const contact::WallPotential& wall,
                           const std::vector<int>& candidates,
                           contact::PotentialContactOptions o = {}) {
  const double d = 0.356e-3;
  const double c = kA - d / 2;
  const double length = rod_theory::straight_tube_contact(kTheta, c / kZc).length * kZc;
  Wire w(d, length, 32, Vec3(0, 0, target.z() - kZc));
  const RigidRun rigid = rigid_run(w);
  o.force_scale = w.EI / (kZc * kZc);
  PotentialRun run;
  run.solution = contact::solve_wire_wall_potential(w.rod, w.radius, wall, mesh, candidates,
                                                    rigid.x, o);
  run.rigid_force = rigid.force;
  run.wall_shift = resting_shift(mesh, run.solution.x.segment<3>(3 * w.layout.tip_node), w.radius);
  run.faceted_force = rigid_run(w, run.wall_shift).force;
  run.EI = w.EI;
  run.clamp = contact::potential_clamp_reaction(w.rod, run.solution);
  return run;
}

[[maybe_unused]] double sum(const std::vector<double>& v) {
  double s = 0.0;
  for (const double x : v) s += x;
  return s;
}

}  // namespace

// The rigid limit, both walls: the scenes' wall made 10⁶ times stiffer. The force must be the
// rigid-wall solve's of the same discrete wire (which is the shooting reference's
// F z_c²/EI = 0.470968 within DER's error at N = 32, 4.26e-4) against the cylinder on which the
// tip's hemisphere rests on the faceted wall (the faces lie inside the exact cylinder, and a ball
// aimed at an edge between two sits in their groove; 4.5 µm inside moves the force by 0.5 %). On
// the structured tube (level 0, nodes ~1 mm apart, far more than r_w = 0.178 mm) no node is under
// the tip: only the tip's contact with the faces holds it. On the line-of-contact mesh (0.08 mm
// within 1 mm of the aimed point) it rests on nodes and faces. The linear and the neo-Hookean walls
// (two assemblies) give the same force at this strain.
TEST(WireWallPotentialSlow, RigidLimitApproachesTheRigidWallSolve) {
  struct Case {
    const char* name;
    TetMesh mesh;
  };
  const std::vector<Case> cases{{"structured tube, level 0", tube_mesh()},
                                {"line-of-contact mesh", line_of_contact_mesh()}};
  for (const Case& c : cases) {
    const std::vector<int> nodes = nodes_within(c.mesh, kAimPoint, 1.6e-3);
    const fem::ElasticityProblem problem = wall_problem(kWallE * 1e6);
    const fem::ElasticitySolver linear(c.mesh, problem);
    const contact::LinearWall linear_wall(linear.free_displacement_system());
    const contact::NeoHookeanWall neo_wall(c.mesh, problem);
    std::vector<double> forces;
    for (const contact::WallPotential* wall :
         {static_cast<const contact::WallPotential*>(&linear_wall),
          static_cast<const contact::WallPotential*>(&neo_wall)}) {
      const PotentialRun run = potential_run(c.mesh, kAimPoint, *wall, nodes);
      const contact::PotentialContactSolution& s = run.solution;
      const double F = s.total_force_on_wall().norm();
      std::printf(
          "WIRE-WALL-POTENTIAL rigid limit (%s, %s): F %.6e N, F z^2/EI %.6f, against the "
          "rigid-wall solve %+.2e, against it where the tip rests on the faceted wall (%.2f um "
          "inside) %+.2e, %zu "
          "pressed, %d rounds, %d Newton, penetration %.1e m, %.2f s\n",
          c.name, wall == &linear_wall ? "linear" : "neo-Hookean", F, F * kZc * kZc / run.EI,
          F / run.rigid_force - 1, -run.wall_shift * 1e6, F / run.faceted_force - 1,
          s.pressed.size(), s.rounds, s.newton_iterations, s.max_penetration, s.seconds);
      EXPECT_GE(s.pressed.size(), 1u);
      EXPECT_NEAR(F / run.faceted_force, 1.0, 1e-4) << c.name;
      // The wire's clamp balances the force on the wall (the contact's share at the wire is
      // equal and opposite by construction; this checks the wire's own equilibrium).
      EXPECT_LT((run.clamp - s.total_force_on_wall()).norm(), 1e-6 * F);
      forces.push_back(F);
    }
    EXPECT_NEAR(forces[0], forces[1], 1e-6 * forces[0]) << c.name;
  }
}

// A P2 wall pressed at its mid-edge nodes too (PotentialContactOptions::mid_edge_candidates, the
// default), on the structured tube: made 10⁶ times stiffer, its force is the rigid-wall solve's
// against the faceted wall where the tip rests (the split faces lie in the same flat triangles),
// as in the rigid-limit test above, and deal.II's linear P2 wall (LinearWall::edge_nodes) gives
// the same force (1e-6) with its mid-edge nodes pressed; at 30 times the scenes' wall (a dent of
// about r_w) the wire's clamp and the wall's supports (its own internal forces on the held rows)
// balance to 1e-9 of the force with mid-edge nodes among the pressed (their forces reach the wall
// whole).
TEST(WireWallPotentialSlow, AP2WallPressedAtItsMidEdgeNodesMeetsTheRigidLimitAndBalances) {
  const TetMesh& mesh = tube_mesh();
  const std::vector<int> nodes = nodes_within(mesh, kAimPoint, 3e-3);
  for (const double stiffer : {1e6, 30.0}) {
    fem::ElasticityProblem problem = wall_problem(kWallE * stiffer);
    problem.options.degree = 2;
    const contact::NeoHookeanWall wall(mesh, problem);
    const PotentialRun run = potential_run(mesh, kAimPoint, wall, nodes);
    const contact::PotentialContactSolution& s = run.solution;
    const double F = s.total_force_on_wall().norm();
    const Vec3 supports = wall.support_reaction(s.u);
    std::printf(
        "WIRE-WALL-POTENTIAL P2 wall x%g, mid-edge candidates: F %.6e N, against the rigid-wall "
        "solve where the tip rests on the faceted wall %+.2e, clamp + supports |%.2e| N (%.1e of "
        "F), %zu pressed (%d mid-edge nodes), %d Newton, %.1f s\n",
        stiffer, F, F / run.faceted_force - 1, (run.clamp + supports).norm(),
        (run.clamp + supports).norm() / F, s.pressed.size(), s.pressed_edge_nodes,
        s.newton_iterations, s.seconds);
    EXPECT_GT(s.pressed_edge_nodes, 0);  // the balance holds with mid-edge nodes bearing
    EXPECT_LT((run.clamp + supports).norm(), 1e-9 * F);
    if (stiffer < 1e3) continue;
    EXPECT_NEAR(F / run.faceted_force, 1.0, 1e-4);
    // deal.II's linear P2 wall (LinearWall, its own assembly) at the same strain: the same force.
    const fem::ElasticitySolver linear(mesh, problem);
    fem::FreeDisplacementSystem system = linear.free_displacement_system();
    linear.set_row_points(system);
    const contact::LinearWall linear_wall(std::move(system));
    const contact::PotentialContactSolution l =
        potential_run(mesh, kAimPoint, linear_wall, nodes).solution;
    std::printf("WIRE-WALL-POTENTIAL linear P2 wall x%g: F %.6e N (%+.2e), %d mid-edge nodes\n",
                stiffer, l.total_force_on_wall().norm(), l.total_force_on_wall().norm() / F - 1,
                l.pressed_edge_nodes);
    EXPECT_GT(l.pressed_edge_nodes, 0);
    EXPECT_NEAR(l.total_force_on_wall().norm(), F, 1e-6 * F);
  }
}

// A wall 30 times the scenes' (the dent twice r_w, strains beyond 0.4), neo-Hookean: the wire's
// clamp and the wall's supports (their reactions from the wall's own internal forces at the held
// DoFs) balance to 1e-9 of the force; the penalty law's force tends to Alart–Curnier's at first
// order in 1/k (k, 2k, 4k) and its extrapolation to infinite stiffness meets it within the
// extrapolation's own error estimate and 1e-5 relative; Levenberg–Marquardt's damped Newton steps
// end at the same pressed nodes and force (1e-8), the augmented Lagrangian's rounds at the same
// pressed nodes and force (1e-6) in more Newton steps.
TEST(WireWallPotentialSlow, TwoFormulationsAndActionReactionOnAFiniteStrainWall) {
  const TetMesh mesh = line_of_contact_mesh();
  const std::vector<int> nodes = nodes_within(mesh, kAimPoint, 1.6e-3);
  const contact::NeoHookeanWall wall(mesh, wall_problem(kWallE * 30));
  const PotentialRun run = potential_run(mesh, kAimPoint, wall, nodes);
  const contact::PotentialContactSolution& s = run.solution;
  const double F = s.total_force_on_wall().norm();
  const Vec3 supports = wall.support_reaction(s.u);
  const double strain = wall.largest_strain(mesh, s.u);
  std::printf(
      "WIRE-WALL-POTENTIAL 30x neo-Hookean: F %.8e N (rigid %+.2e), %zu pressed, strain %.3f, "
      "clamp + supports |%.2e| N (%.1e of F), %d rounds, %d Newton, %.1f s\n",
      F, F / run.rigid_force - 1, s.pressed.size(), strain, (run.clamp + supports).norm(),
      (run.clamp + supports).norm() / F, s.rounds, s.newton_iterations, s.seconds);
  EXPECT_GT(s.pressed.size(), 10u);
  EXPECT_GT(strain, 0.1);
  EXPECT_LT((run.clamp + supports).norm(), 1e-9 * F);
  // Levenberg–Marquardt's damped Newton steps end at the same minimiser.
  contact::PotentialContactOptions damped;
  damped.damped_newton = true;
  const PotentialRun d = potential_run(mesh, kAimPoint, wall, nodes, damped);
  std::printf("WIRE-WALL-POTENTIAL damped Newton: F %.8e N, %zu pressed, %d Newton (undamped %d)\n",
              d.solution.total_force_on_wall().norm(), d.solution.pressed.size(),
              d.solution.newton_iterations, s.newton_iterations);
  EXPECT_EQ(d.solution.pressed, s.pressed);
  EXPECT_NEAR(d.solution.total_force_on_wall().norm(), F, 1e-8 * F);
  // The augmented Lagrangian's rounds (multipliers updated once Newton has converged for them)
  // end at Alart–Curnier's solution (multipliers updated with every Newton step), in more steps.
  // The rounds stop when no force changes by more than k × 1e-9 m, ~1e-4 of a node's force here:
  // their force is within 1e-6 (it differs by 1e-7).
  contact::PotentialContactOptions rounds;
  rounds.law = contact::ContactLaw::augmented_lagrangian;
  const PotentialRun al = potential_run(mesh, kAimPoint, wall, nodes, rounds);
  std::printf(
      "WIRE-WALL-POTENTIAL augmented Lagrangian: F %.8e N, %zu pressed, %d rounds, %d Newton "
      "(Alart-Curnier %d)\n",
      al.solution.total_force_on_wall().norm(), al.solution.pressed.size(), al.solution.rounds,
      al.solution.newton_iterations, s.newton_iterations);
  EXPECT_EQ(al.solution.pressed, s.pressed);
  EXPECT_NEAR(al.solution.total_force_on_wall().norm(), F, 1e-6 * F);
  EXPECT_LT(s.newton_iterations, al.solution.newton_iterations);
  std::vector<double> penalty;
  for (const double factor : {1.0, 2.0, 4.0}) {
    contact::PotentialContactOptions o;
    o.law = contact::ContactLaw::penalty;
    o.penalty_stiffness = factor * s.penalty_stiffness;
    const PotentialRun p = potential_run(mesh, kAimPoint, wall, nodes, o);
    penalty.push_back(p.solution.total_force_on_wall().norm());
  }
  // F(k) = F∞ + c/k: the penalty's distance from Alart–Curnier's force halves with each doubling
  // of k (penalty[2] − F is ~1e-8 N: an F off by a few 1e-9 N moves the ratios out of 2 ± 0.6).
  // The differences between the penalty's own forces are no measure of the order here: they are
  // 1–2e-8 N, and each solve's force moves by ~2e-9 N between builds (the solves stop at their
  // round-off floor): their observed order is 0.9 on one build, 1.35 on another. The two finest
  // give F∞ = 2 F(4k) − F(2k).
  const double halving_1 = (penalty[0] - F) / (penalty[1] - F);
  const double halving_2 = (penalty[1] - F) / (penalty[2] - F);
  const double extrapolated = 2 * penalty[2] - penalty[1];
  const double estimate = std::abs(penalty[2] - penalty[1]);
  std::printf(
      "WIRE-WALL-POTENTIAL penalty k x1,2,4: %.8e %.8e %.8e N (their distance from "
      "Alart-Curnier's halves by %.2f, %.2f), extrapolated %.8e, Alart-Curnier %.8e (%+.1e, "
      "estimate %.1e)\n",
      penalty[0], penalty[1], penalty[2], halving_1, halving_2, extrapolated, F,
      extrapolated / F - 1, estimate / F);
  EXPECT_NEAR(halving_1, 2.0, 0.6);
  EXPECT_NEAR(halving_2, 2.0, 0.6);
  EXPECT_LT(std::abs(extrapolated - F), std::max(estimate, 1e-5 * F));
}

// A model's own energy as the wall (FormWall): msm's linear P1 tetrahedron (LinearTetTerm, its own
// assembly) in the potential solve gives deal.II's linear P1 wall's contact (LinearWall) on the
// same mesh and supports, 100 times the scenes' wall: the same pressed nodes and force to 1e-8.
TEST(WireWallPotentialSlow, ModelEnergyWallEqualsTheFemWall) {
  const TetMesh mesh = line_of_contact_mesh();
  const std::vector<int> nodes = nodes_within(mesh, kAimPoint, 1.6e-3);
  const fem::ElasticityProblem problem = wall_problem(kWallE * 100);
  const fem::ElasticitySolver linear(mesh, problem);
  const contact::LinearWall fem_wall(linear.free_displacement_system());
  const msm::LinearTetTerm term(mesh.nodes, mesh.tets,
                                msm::lame_parameters(kWallE * 100, problem.material.poisson_ratio));
  std::vector<char> held(mesh.nodes.size(), 0);
  for (const char* group : {"inlet", "outlet"}) {
    for (const int n : mesh.group_nodes(mesh.require_group(group, 2, "tube"))) held[n] = 1;
  }
  std::vector<int> free_index(3 * mesh.nodes.size(), -1);
  std::vector<std::array<int, 3>> rows(mesh.nodes.size(), {-1, -1, -1});
  int next = 0;
  Eigen::VectorXd rest(3 * mesh.nodes.size());
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    rest.segment<3>(3 * static_cast<Eigen::Index>(n)) = mesh.nodes[n];
    if (held[n]) continue;
    for (int c = 0; c < 3; ++c) rows[n][c] = free_index[3 * n + c] = next++;
  }
  const contact::FormWall model_wall(term, rest, free_index, rows);
  const PotentialRun a = potential_run(mesh, kAimPoint, fem_wall, nodes);
  const PotentialRun b = potential_run(mesh, kAimPoint, model_wall, nodes);
  const double Fa = a.solution.total_force_on_wall().norm();
  const double Fb = b.solution.total_force_on_wall().norm();
  std::printf("WIRE-WALL-POTENTIAL 100x: deal.II P1 %.10e N (%zu pressed), msm P1 %.10e N (%zu "
              "pressed), %+.1e\n",
              Fa, a.solution.pressed.size(), Fb, b.solution.pressed.size(), Fb / Fa - 1);
  EXPECT_EQ(a.solution.pressed, b.solution.pressed);
  EXPECT_NEAR(Fa, Fb, 1e-8 * Fa);
}

// A model's wall counts the tets it carries that are inverted (FormWall::inverted_tets): two
// tets sharing the face 0-1-2, the apex 3 above it and 4 below; apex 3 pushed 1.5 units down,
// through the shared face, folds the first tet and leaves the second, whose nodes did not move,
// as it is. With node 4 held, only the first tet is the wall's.
TEST(WireWallPotential, AModelWallCountsItsInvertedTets) {
  TetMesh mesh;
  mesh.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0.2, 0.2, 1), Vec3(0.2, 0.2, -1)};
  mesh.tets = {{0, 1, 2, 3}, {0, 2, 1, 4}};
  ASSERT_GT(signed_volume(mesh.nodes[0], mesh.nodes[1], mesh.nodes[2], mesh.nodes[3]), 0.0);
  ASSERT_GT(signed_volume(mesh.nodes[0], mesh.nodes[2], mesh.nodes[1], mesh.nodes[4]), 0.0);
  const msm::LinearTetTerm term(mesh.nodes, mesh.tets, msm::lame_parameters(1e4, 0.3));
  Eigen::VectorXd rest(15);
  for (int n = 0; n < 5; ++n) rest.segment<3>(3 * n) = mesh.nodes[static_cast<std::size_t>(n)];
  const auto wall_with = [&](bool hold_4, std::vector<int>& free_index,
                             std::vector<std::array<int, 3>>& rows) {
    free_index.assign(15, -1);
    rows.assign(5, {-1, -1, -1});
    int next = 0;
    for (int n = 0; n < 5; ++n) {
      if (hold_4 && n == 4) continue;
      for (int c = 0; c < 3; ++c) rows[n][c] = free_index[3 * n + c] = next++;
    }
    return next;
  };
  std::vector<int> free_index;
  std::vector<std::array<int, 3>> rows;
  const int all = wall_with(false, free_index, rows);
  const contact::FormWall wall(term, rest, free_index, rows);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(all);
  EXPECT_EQ(wall.inverted_tets(mesh, u), std::optional<std::size_t>(0));
  u[rows[3][2]] = -1.5;
  EXPECT_EQ(wall.inverted_tets(mesh, u), std::optional<std::size_t>(1));

  const int some = wall_with(true, free_index, rows);
  const contact::FormWall held(term, rest, free_index, rows);
  Eigen::VectorXd v = Eigen::VectorXd::Zero(some);
  v[rows[3][2]] = -1.5;
  EXPECT_EQ(held.inverted_tets(mesh, v), std::optional<std::size_t>(1));
  v[rows[3][2]] = 0.0;
  EXPECT_EQ(held.inverted_tets(mesh, v), std::optional<std::size_t>(0));
  rows.assign(5, {-1, -1, -1});  // no node free: no tet is the wall's
  const contact::FormWall none(term, rest, std::vector<int>(15, -1), rows);
  EXPECT_FALSE(none.inverted_tets(mesh, Eigen::VectorXd()).has_value());
}

// By hand: from 4e-7 towards 4e-5 in steps of 10 are 4e-7, 4e-6 and the target; in steps of √10,
// five rungs; a target at or below the first is solved alone; with a ratio that does not divide
// the span evenly the steps are still the ratio, ending on the target, the first at or below
// `first`.
TEST(ContinuationRungs, StepsOfTheRatioEndingOnTheTarget) {
  const auto near = [](const std::vector<double>& got, const std::vector<double>& want) {
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t k = 0; k < want.size(); ++k) EXPECT_NEAR(got[k], want[k], 1e-12 * want[k]);
  };
  near(contact::continuation_rungs(4e-7, 10.0, 4e-5), {4e-7, 4e-6, 4e-5});
  near(contact::continuation_rungs(4e-7, std::sqrt(10.0), 4e-5),
       {4e-7, 4e-7 * std::sqrt(10.0), 4e-6, 4e-6 * std::sqrt(10.0), 4e-5});
  near(contact::continuation_rungs(4e-6, 10.0, 4e-6), {4e-6});
  near(contact::continuation_rungs(4e-6, 10.0, 1e-6), {1e-6});
  near(contact::continuation_rungs(1e-6, 3.0, 4e-6), {4e-6 / 9.0, 4e-6 / 3.0, 4e-6});
}

// The wall's start (a stiffness continuation's rung): the wire at a tenth of its EI solved first,
// then the wire at its EI from that equilibrium (the softer wire's centreline, the wall's dented
// displacement) reaches the equilibrium the solve from the rigid-lumen state with the wall at rest
// reaches (the same minimiser of Π: the same pressed nodes, the force to 1e-7). The rigid-lumen
// shape a continuation starts every rung from does not depend on EI (the rod's energy scales
// with E): the softer wire's rigid-wall solve gives the same centreline to 1e-9 of the radius.
TEST(WireWallPotentialSlow, ContinuationFromASofterWireReachesTheDirectSolve) {
  const TetMesh mesh = line_of_contact_mesh();
  const std::vector<int> nodes = nodes_within(mesh, kAimPoint, 1.6e-3);
  const contact::NeoHookeanWall wall(mesh, wall_problem(kWallE * 30));
  const PotentialRun direct = potential_run(mesh, kAimPoint, wall, nodes);

  const double d = 0.356e-3, c = kA - d / 2;
  const double length = rod_theory::straight_tube_contact(kTheta, c / kZc).length * kZc;
  const Vec3 origin(0, 0, kAimPoint.z() - kZc);
  msm::rods::RodMaterial soft = kNitinol;
  soft.young /= 10;
  soft.shear /= 10;
  Wire w_soft(d, length, 32, origin, soft), w(d, length, 32, origin);
  const RigidRun rigid_soft = rigid_run(w_soft), rigid = rigid_run(w);
  EXPECT_LT((rigid_soft.x - rigid.x).cwiseAbs().maxCoeff(), 1e-9 * w.radius);
  contact::PotentialContactOptions o;
  o.force_scale = w_soft.EI / (kZc * kZc);
  const contact::PotentialContactSolution s_soft = contact::solve_wire_wall_potential(
      w_soft.rod, w_soft.radius, wall, mesh, nodes, rigid_soft.x, o);
  o.force_scale = w.EI / (kZc * kZc);
  const contact::PotentialContactSolution s = contact::solve_wire_wall_potential(
      w.rod, w.radius, wall, mesh, nodes, s_soft.x, o, s_soft.u);
  const double F = s.total_force_on_wall().norm();
  const double F_direct = direct.solution.total_force_on_wall().norm();
  std::printf(
      "WIRE-WALL-POTENTIAL continuation: EI/10 %.8e N (%d Newton), then EI %.8e N (%d Newton) "
      "against the direct %.8e N (%d Newton), %+.1e\n",
      s_soft.total_force_on_wall().norm(), s_soft.newton_iterations, F, s.newton_iterations,
      F_direct, direct.solution.newton_iterations, F / F_direct - 1);
  EXPECT_EQ(s.pressed, direct.solution.pressed);
  EXPECT_NEAR(F, F_direct, 1e-7 * F_direct);
  EXPECT_THROW((void)contact::solve_wire_wall_potential(w.rod, w.radius, wall, mesh, nodes,
                                                        s_soft.x, o, VectorXd::Zero(5)),
               InputError);
}

// The wall condensed on a band (CondensedLinearWall) against a direct sparse solve of the whole
// wall (Eigen's LDLᵀ, not the condensation's CHOLMOD): under forces f on the band's nodes and
// none elsewhere the whole field v solves K v = f; at the band's rows u = v the condensed energy
// is ½ fᵀv, its gradient is f, and its whole field (nodal) is v.
TEST(CondensedLinearWall, IsTheWholeWallLoadedOnlyOnItsBand) {
  const TetMesh& mesh = tube_mesh();
  const fem::ElasticitySolver linear(mesh, wall_problem(kWallE));
  const fem::FreeDisplacementSystem system = linear.free_displacement_system();
  const std::vector<int> band = nodes_within(mesh, mesh.nodes[aim_node(mesh)], 2.5e-3);
  ASSERT_GE(band.size(), 4u);
  const contact::CondensedLinearWall wall(system, band);
  ASSERT_EQ(wall.num_dofs(), static_cast<int>(3 * band.size()));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  VectorXd f = VectorXd::Zero(system.K.rows()), f_band(wall.num_dofs());
  for (std::size_t k = 0; k < band.size(); ++k) {
    for (int c = 0; c < 3; ++c) {
      const double value = 1e-3 * unit(rng);
      f[system.node_rows[static_cast<std::size_t>(band[k])][c]] = value;
      f_band[static_cast<Eigen::Index>(3 * k) + c] = value;
    }
  }
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> direct(system.K);
  ASSERT_EQ(direct.info(), Eigen::Success);
  const VectorXd v = direct.solve(f);
  std::vector<Vec3> field(mesh.nodes.size(), Vec3::Zero());
  for (std::size_t n = 0; n < field.size(); ++n) {
    for (int c = 0; c < 3; ++c) {
      if (system.node_rows[n][c] >= 0) field[n][c] = v[system.node_rows[n][c]];
    }
  }
  const VectorXd u = wall.band_rows(field);
  VectorXd gradient;
  Eigen::SparseMatrix<double> hessian;
  const double energy = wall.evaluate(u, &gradient, &hessian);
  EXPECT_NEAR(energy, 0.5 * f.dot(v), 1e-10 * std::abs(f.dot(v)));
  EXPECT_LT((gradient - f_band).cwiseAbs().maxCoeff(), 1e-9 * f_band.cwiseAbs().maxCoeff());
  EXPECT_LT((VectorXd(hessian * u) - gradient).norm(), 1e-12 * gradient.norm());
  const std::vector<Vec3> whole = wall.nodal(u);
  double largest = 0.0, difference = 0.0;
  for (std::size_t n = 0; n < whole.size(); ++n) {
    largest = std::max(largest, field[n].norm());
    difference = std::max(difference, (whole[n] - field[n]).norm());
  }
  EXPECT_LT(difference, 1e-9 * largest);
  // The band grown in two steps (only the new nodes' columns solved) is the same wall.
  const std::vector<int> first(band.begin(), band.begin() + static_cast<long>(band.size() / 2));
  contact::CondensedLinearWall grown(system, first);
  grown.grow({band.begin() + static_cast<long>(band.size() / 2), band.end()});
  EXPECT_NEAR(grown.evaluate(u, nullptr, nullptr), energy, 1e-10 * energy);
  EXPECT_THROW(grown.grow({band.front()}), InputError);
  // A band node held by a support is refused.
  std::vector<int> held = band;
  held.push_back(mesh.group_nodes(mesh.require_group("inlet", 2, "tube")).front());
  EXPECT_THROW(contact::CondensedLinearWall(system, held), InputError);
}

// The wire on a band grown from the 0.25 mm round the aimed point (solve_wire_wall_potential_
// growing) reaches the equilibrium of the same potential on the whole wall (LinearWall, every
// inner-wall node within 2.5 mm a candidate; the line of contact reaches 1.7 mm), 30 times the
// scenes' wall (a dent of about 2 r_w):
// the same pressed nodes, the force to 1e-7 and the pressed nodes' displacements within a few
// times the solves' gap tolerance (1e-9 m).
TEST(WireWallPotentialSlow, AGrownCondensedBandReachesTheWholeWallsEquilibrium) {
  const TetMesh mesh = line_of_contact_mesh();
  const fem::ElasticitySolver linear(mesh, wall_problem(kWallE * 30));
  const fem::FreeDisplacementSystem system = linear.free_displacement_system();
  const contact::LinearWall whole_wall(system);
  const PotentialRun whole =
      potential_run(mesh, kAimPoint, whole_wall, nodes_within(mesh, kAimPoint, 2.5e-3));

  const double d = 0.356e-3, c = kA - d / 2;
  const double length = rod_theory::straight_tube_contact(kTheta, c / kZc).length * kZc;
  Wire w(d, length, 32, Vec3(0, 0, kAimPoint.z() - kZc));
  const RigidRun rigid = rigid_run(w);
  contact::PotentialContactOptions o;
  o.force_scale = w.EI / (kZc * kZc);
  const contact::GrownPotentialContact grown = contact::solve_wire_wall_potential_growing(
      w.rod, w.radius, system, mesh, nodes_within(mesh, kAimPoint, 0.25e-3), rigid.x, o);
  const double F = grown.solution.total_force_on_wall().norm();
  const double F_whole = whole.solution.total_force_on_wall().norm();
  const std::vector<Vec3> u_whole = whole_wall.nodal(whole.solution.u);
  const std::vector<Vec3> u_band = grown.wall->nodal(grown.solution.u);
  double dent = 0.0, difference = 0.0;
  for (const int n : whole.solution.pressed) {
    dent = std::max(dent, u_whole[static_cast<std::size_t>(n)].norm());
    difference = std::max(
        difference,
        (u_band[static_cast<std::size_t>(n)] - u_whole[static_cast<std::size_t>(n)]).norm());
  }
  std::printf(
      "WIRE-WALL-POTENTIAL condensed band: %.10e N (%zu pressed, %zu band nodes after %d growths, "
      "%d Newton, set-up %.2f s, solve %.2f s) against the whole wall %.10e N (%zu pressed, %d "
      "Newton, %.2f s), %+.1e; dent %.3f mm, displacements within %.1e m\n",
      F, grown.solution.pressed.size(), grown.wall->band().size(), grown.rounds,
      grown.solution.newton_iterations, grown.wall->setup_seconds(), grown.solution.seconds,
      F_whole, whole.solution.pressed.size(), whole.solution.newton_iterations,
      whole.solution.seconds, F / F_whole - 1, dent * 1e3, difference);
  EXPECT_GE(grown.rounds, 1);
  EXPECT_EQ(grown.solution.pressed, whole.solution.pressed);
  EXPECT_NEAR(F, F_whole, 1e-7 * F_whole);
  // Both stop when no pressed node is open or penetrating by more than the gap tolerance.
  EXPECT_LT(difference, 5 * o.gap_tolerance);
}

namespace {

/// The clamped–free elastica under a dead end load P along the clamp's axis (the wall's normal:
/// the tip slides on the frictionless wall) at end shortening Δ (Timoshenko & Gere, Theory of
/// Elastic Stability, §2.7): with k = sin(α/2), α the tip's rotation, λ = K(k)/L and
/// Δ/L = 2 − 2E(k)/K(k); the load P = EI λ², the tip's sideways deflection 2k/λ. The rod is
/// inextensible there; here its axial strain P/EA takes P·L/EA of the shortening (to first order:
/// the axial force is P cos θ, θ ≤ α ≈ 8°), found by fixed point.
struct Elastica {
  double force = 0.0;       ///< N
  double deflection = 0.0;  ///< m
};
Elastica clamped_free_elastica(double EI, double EA, double L, double shortening) {
  Elastica out;
  for (int pass = 0; pass < 20; ++pass) {
    const double bent = shortening - out.force * L / EA;
    double lo = 1e-9, hi = 0.99;  // k: Δ/L rises with k
    for (int i = 0; i < 200; ++i) {
      const double k = 0.5 * (lo + hi);
      const double d = 2.0 - 2.0 * std::comp_ellint_2(k) / std::comp_ellint_1(k);
      (d < bent / L ? lo : hi) = k;
    }
    const double k = 0.5 * (lo + hi), lambda = std::comp_ellint_1(k) / L;
    out = {EI * lambda * lambda, 2.0 * k / lambda};
  }
  return out;
}

}  // namespace

// A wire pushed end-on against a wall buckles (a guidewire meeting an obstruction): the nitinol
// wire (d = 0.356 mm, 10 mm, DER N = 32) clamped 0.5 % of its length closer to a steel-stiff block
// (E = 1.424e11 Pa, 3 mm, clamped at its far face) than the tip's hemisphere reaches, its axis
// along the face's normal within 1e-4 rad. Straight, the wire would press with EA·Δ/L ≈ 24 N, 26
// times Euler's load π²EI/4L²: a saddle of Π, which the minimiser must leave for the bent
// minimum. The force and the tip's sideways deflection are the clamped–free elastica's at that
// end shortening (1.0024 Euler loads, 0.88 mm) within DER's and the tilt's error (the tilt moves
// the force by ∓0.12 % on the two branches). Leaving the saddle along Π's negative curvature, the
// wire bends the way its clamp leans, the branch of lower energy; steps on the PSD-projected
// Hessian alone, which does not see that curvature, end on the other branch (1.0035 Euler
// loads).
TEST(WireWallPotential, AWirePushedEndOnAgainstAWallBucklesIntoTheElastica) {
  const double block = 3e-3, length = 10e-3, diameter = 0.356e-3, r = diameter / 2;
  const double shortening = 0.005 * length, tilt = 1e-4;
  TetMesh mesh = test::cube_mesh(6, block);
  const PhysicalGroup& top = mesh.require_group("z1", 2, "block");
  mesh.groups.push_back({"inner_wall", 2, 20, top.elements});
  fem::ElasticityProblem problem;
  problem.material.youngs_modulus = kWallE * 1e7;
  problem.material.poisson_ratio = 0.3;
  problem.dirichlet = {fem::DirichletCondition::clamped("z0")};
  const fem::ElasticitySolver linear(mesh, problem);
  const contact::LinearWall wall(linear.free_displacement_system());
  const std::vector<int> candidates =
      mesh.group_nodes(mesh.require_group("inner_wall", 2, "block"));

  msm::rods::RodSpec spec = msm::rods::uniform_rod(kNitinol, length, diameter, 32);
  const Vec3 clamp(0.5 * block, 0.5 * block, block + r + length - shortening);
  spec.origin = clamp;
  spec.direction = Vec3(std::sin(tilt), 0.0, -std::cos(tilt));
  msm::rods::DerRod rod(msm::rods::make_layout(spec));
  const msm::rods::SectionStiffness section = msm::rods::solid_section(kNitinol, diameter);
  const double EI = section.EI;
  const Elastica truth = clamped_free_elastica(EI, section.EA, length, shortening);
  contact::PotentialContactOptions o;
  o.force_scale = truth.force;
  const contact::PotentialContactSolution s =
      contact::solve_wire_wall_potential(rod, r, wall, mesh, candidates, rod.rest_state(), o);
  const int tip = rod.layout().tip_node;
  const Vec3 tip_at = s.x.segment<3>(3 * tip);
  const double F = s.total_force_on_wall().norm();
  const double sideways = std::hypot(tip_at.x() - clamp.x(), tip_at.y() - clamp.y());
  const double euler = M_PI * M_PI * EI / (4 * length * length);
  std::printf(
      "WIRE-WALL-POTENTIAL end-on wire: F %.6e N (%.5f Euler loads; elastica %.5f), tip %.4f mm "
      "sideways (elastica %.4f), tip node %.2e m above the face less r_w, %d Newton, %d rounds\n",
      F, F / euler, truth.force / euler, sideways * 1e3, truth.deflection * 1e3,
      tip_at.z() - block - r, s.newton_iterations, s.rounds);
  EXPECT_NEAR(F / truth.force, 1.0, 3e-3);
  EXPECT_NEAR(sideways / truth.deflection, 1.0, 5e-3);
  EXPECT_GT(tip_at.x(), clamp.x());  // bent the way the clamp leans
}
