// Region-of-interest models on a hand-placed spring chain: which nodes are held, which kept, and
// the restricted solve against the chain's closed form and against the full problem with the
// same nodes fixed (a second method).
#include <gtest/gtest.h>

#include <cmath>

#include "msm/terms/spring_model.hpp"
#include "msm/solvers/static_solver.hpp"
#include "msm/model/roi.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

constexpr double kSpacing = 1e-3;  // m
constexpr double kK = 10.0;        // N/m
constexpr double kForce = 1e-4;    // N

/// Eleven nodes on the x axis 1 mm apart, a spring of k = 10 N/m between neighbours.
msm::SpringNetwork chain() {
  msm::SpringNetwork net;
  for (int i = 0; i <= 10; ++i) {
    net.nodes.emplace_back(i * kSpacing, 0.0, 0.0);
    net.source_node.push_back(i);
  }
  for (int i = 0; i < 10; ++i) {
    msm::Spring s;
    s.a = i;
    s.b = i + 1;
    s.rest_length = kSpacing;
    s.law.k1 = kK;
    net.springs.push_back(s);
  }
  return net;
}

/// The chain with both end nodes fixed and an axial force on node 5. Only x moves: y and z are
/// fixed everywhere (an axial chain has no transverse stiffness at rest).
msm::Problem chain_problem(const msm::Form& form, const msm::SpringNetwork& net) {
  msm::Problem p;
  p.form = &form;
  p.rest = msm::flatten(net.nodes);
  const auto n = static_cast<Eigen::Index>(p.rest.size());
  p.external_force = Eigen::VectorXd::Zero(n);
  p.external_force[3 * 5] = kForce;
  p.mass = Eigen::VectorXd::Constant(n, 1e-3);
  p.fixed.assign(static_cast<std::size_t>(n), 0);
  for (Eigen::Index i = 0; i < n; i += 3) p.fixed[i + 1] = p.fixed[i + 2] = 1;
  for (int c = 0; c < 3; ++c) p.fixed[c] = p.fixed[30 + c] = 1;
  return p;
}

const Vec3 kCentre(5e-3, 0.0, 0.0);

}  // namespace

TEST(Roi, NodesBeyondTheRadiusAreMarked) {
  const std::vector<Vec3> nodes{{0, 0, 0}, {1e-3, 0, 0}, {0, 3e-3, 0}, {0, 0, -2.9e-3}};
  const std::vector<char> beyond = nodes_beyond(nodes, Vec3::Zero(), 2.95e-3);
  EXPECT_EQ(beyond, (std::vector<char>{0, 0, 1, 0}));
}

TEST(Roi, NodesBeyondRAreHeldWithinAreFreeAndTheRingIsKept) {
  const msm::SpringNetwork net = chain();
  const msm::SpringModel model(net);
  const msm::Problem full = chain_problem(model, net);
  // R = 2.5 mm about x = 5 mm: nodes 3..7 move; 0..2 and 8..10 are held.
  const std::vector<char> held = held_nodes(full, kCentre, 2.5e-3);
  EXPECT_EQ(held, (std::vector<char>{1, 1, 1, 0, 0, 0, 0, 0, 1, 1, 1}));
  const RoiNetwork roi = restrict_network(net, held);
  EXPECT_EQ(roi.moving_nodes, 5u);
  EXPECT_EQ(roi.full_index, (std::vector<int>{2, 3, 4, 5, 6, 7, 8}));  // with the ring 2 and 8
  ASSERT_EQ(roi.network.springs.size(), 6u);                           // 2-3 … 7-8
  EXPECT_EQ(roi.network.springs.front().a, 0);
  EXPECT_EQ(roi.network.springs.back().b, 6);
  EXPECT_EQ(roi.network.source_node.front(), 2);
  const msm::SpringModel roi_model(roi.network);
  const msm::Problem p = restrict_problem(full, roi, held, roi_model);
  ASSERT_EQ(p.num_dofs(), 21);
  // The ring is held in every direction; moving nodes keep the full problem's fixed flags.
  for (int c = 0; c < 3; ++c) {
    EXPECT_TRUE(p.fixed[c]);
    EXPECT_TRUE(p.fixed[18 + c]);
  }
  EXPECT_FALSE(p.fixed[3 * 3]);
  EXPECT_TRUE(p.fixed[3 * 3 + 1]);
  EXPECT_DOUBLE_EQ(p.external_force[3 * 3], kForce);  // node 5 is the region's node 3
}

TEST(Roi, RestrictedSolveMatchesTheClosedFormAndTheFullProblemWithTheSameNodesFixed) {
  const msm::SpringNetwork net = chain();
  const msm::SpringModel model(net);
  const msm::Problem full = chain_problem(model, net);
  // Whole chain: two chains of 5 springs in parallel, u5 = F / (2 k/5).
  const double u_full = msm::solve_static(full).x[15] - full.rest[15];
  EXPECT_NEAR(u_full, kForce * 5.0 / (2.0 * kK), 1e-12);

  const std::vector<char> held = held_nodes(full, kCentre, 2.5e-3);
  const RoiNetwork roi = restrict_network(net, held);
  const msm::SpringModel roi_model(roi.network);
  const msm::Problem p = restrict_problem(full, roi, held, roi_model);
  const Eigen::VectorXd x = msm::solve_static(p).x;
  // Region held at nodes 2 and 8: two chains of 3 springs, u5 = F / (2 k/3).
  const double u_roi = x[3 * 3] - p.rest[3 * 3];
  EXPECT_NEAR(u_roi, kForce * 3.0 / (2.0 * kK), 1e-12);
  // Node 4 (region node 2) moves 2/3 of node 5.
  EXPECT_NEAR(x[3 * 2] - p.rest[3 * 2], 2.0 / 3.0 * u_roi, 1e-12);

  // Second method: the full problem with the held nodes fixed by identity rows.
  msm::Problem fixed = full;
  for (std::size_t i = 0; i < held.size(); ++i) {
    if (held[i]) fixed.fixed[3 * i] = fixed.fixed[3 * i + 1] = fixed.fixed[3 * i + 2] = 1;
  }
  const Eigen::VectorXd xf = msm::solve_static(fixed).x;
  for (std::size_t k = 0; k < roi.full_index.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(roi.full_index[k]);
    EXPECT_NEAR((x.segment<3>(3 * static_cast<Eigen::Index>(k)) - xf.segment<3>(3 * i)).norm(), 0.0,
                1e-14);
  }
}

TEST(Roi, ARegionWithNoMovingNodeIsRefused) {
  const msm::SpringNetwork net = chain();
  const msm::SpringModel model(net);
  const msm::Problem full = chain_problem(model, net);
  // 0.4 mm about x = 5.5 mm reaches no node.
  EXPECT_THROW((void)held_nodes(full, Vec3(5.5e-3, 0, 0), 0.4e-3), std::runtime_error);
  // The end nodes are held even within R: they are fixed in every direction.
  const std::vector<char> held = held_nodes(full, Vec3::Zero(), 1.5e-3);
  EXPECT_EQ(held[0], 1);
  EXPECT_EQ(held[1], 0);
  EXPECT_EQ(held[2], 1);
}
