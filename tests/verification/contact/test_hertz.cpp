// The contact core on Hertz's closed forms. A rigid paraboloid (the wire's rounded tip, radius R)
// pressed with a force F into a thick P1 block clamped at its base, the contact zone found by the
// solve (contact::press_rigid_indenter on a contact::CondensedWall). Half-space closed forms
// (Johnson, Contact Mechanics, §4.2; guidewire_notes.md): a = (3FR/4E*)^(1/3), δ = a²/R,
// p(r) = p₀√(1 − r²/a²), E* = E/(1 − ν²); outside the zone u_z(r) = p₀/(2aE*) ·
// [(2a² − r²) asin(a/r) + a√(r² − a²)]. The block is finite, so the approach is compared relative
// to a surface point at r₀ = 3a, which takes the clamped base's far field out; a comes from the
// forces' second moment, Σλr²/Σλ = 2a²/5 for Hertz's pressure.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "../../fem/cube_mesh.hpp"
#include "fem_reference/elasticity.hpp"
#include "verification/contact/condensed_wall.hpp"
#include "verification/contact/signorini.hpp"

using namespace vessel;

namespace {

constexpr double kE = 14.24e3, kNu = 0.3, kR = 5e-3, kA = 0.5e-3;  // a/R = 0.1
const double kEStar = kE / (1 - kNu * kNu);
const double kForce = 4 * kEStar * kA * kA * kA / (3 * kR);
const double kP0 = 2 * kA * kEStar / (std::numbers::pi * kR);

/// Half-space surface displacement under Hertz's pressure, outside the zone (r ≥ a).
double hertz_uz_outside(double r) {
  return kP0 / (2 * kA * kEStar) *
         ((2 * kA * kA - r * r) * std::asin(kA / r) + kA * std::sqrt(r * r - kA * kA));
}

/// A block |x|, |y| ≤ 15a, −15a ≤ z ≤ 0 of n³ hexahedra (six tets each), graded towards the
/// origin of its top face by x = W sinh(β ξ)/sinh β: cells near the contact are n-independent
/// in shape and about 4.4a/n wide.
TetMesh graded_block(int n) {
  TetMesh m = test::cube_mesh(n, 1.0);
  const double W = 15 * kA, beta = 4.0;
  const auto grade = [&](double t) { return W * std::sinh(beta * t) / std::sinh(beta); };
  for (Vec3& x : m.nodes) x = Vec3(grade(2 * x.x() - 1), grade(2 * x.y() - 1), -grade(1 - x.z()));
  return m;
}

struct HertzRun {
  double a_ratio = 0, approach_ratio = 0, force_ratio = 0;
  int candidates = 0, active = 0;
};

HertzRun press(int n) {
  const TetMesh mesh = graded_block(n);
  fem::ElasticityProblem p;
  p.material.youngs_modulus = kE;
  p.material.poisson_ratio = kNu;
  p.options.degree = 1;
  p.dirichlet = {fem::DirichletCondition::clamped("z0")};
  const fem::ElasticitySolver solver(mesh, p);
  // Candidates: the top face's nodes within 1.6a of the axis, pushed along −z; gap r²/2R.
  std::vector<int> nodes;
  std::vector<Vec3> directions;
  std::vector<double> gaps;
  int far = -1;
  const double r0 = 3 * kA;
  for (int i = 0; i < static_cast<int>(mesh.nodes.size()); ++i) {
    const Vec3& x = mesh.nodes[i];
    if (std::abs(x.z()) > 1e-12) continue;
    const double r = std::hypot(x.x(), x.y());
    if (far < 0 ||
        std::abs(r - r0) < std::abs(std::hypot(mesh.nodes[far].x(), mesh.nodes[far].y()) - r0))
      far = i;
    if (r > 1.6 * kA) continue;
    nodes.push_back(i);
    directions.emplace_back(0, 0, -1);
    gaps.push_back(r * r / (2 * kR));
  }
  const contact::CondensedWall wall(solver.free_displacement_system(), nodes, directions);
  const Eigen::VectorXd h = Eigen::Map<const Eigen::VectorXd>(gaps.data(), gaps.size());
  const contact::RigidPress pr = contact::press_rigid_indenter(wall.compliance(), h, kForce, 1e-15);
  double second = 0.0, sum = 0.0;
  HertzRun run;
  run.candidates = static_cast<int>(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const Vec3& x = mesh.nodes[nodes[i]];
    second += pr.contact.force[i] * (x.x() * x.x() + x.y() * x.y());
    sum += pr.contact.force[i];
    run.active += pr.contact.active[i];
  }
  run.force_ratio = sum / kForce;
  run.a_ratio = std::sqrt(2.5 * second / sum) / kA;
  const std::vector<Vec3> u = wall.displacement(pr.contact.force);
  const double r_far = std::hypot(mesh.nodes[far].x(), mesh.nodes[far].y());
  // The indenter's approach relative to the surface at r_far (u_z < 0 there: pushed down).
  const double relative = pr.approach - (-u[far].z());
  run.approach_ratio = relative / (kA * kA / kR - hertz_uz_outside(r_far));
  std::printf(
      "HERTZ n %d: %d candidates, %d in contact, a/a_Hertz %.4f, relative approach / "
      "Hertz %.4f (r0 = %.2f a), W set-up %.2f s\n",
      n, run.candidates, run.active, run.a_ratio, run.approach_ratio, r_far / kA,
      wall.setup_seconds());
  return run;
}

}  // namespace

TEST(HertzContact, RigidSphereOnABlockConvergesToTheClosedForm) {
  const int n[3] = {12, 18, 24};
  HertzRun runs[3];
  for (int k = 0; k < 3; ++k) runs[k] = press(n[k]);
  for (const HertzRun& r : runs) EXPECT_NEAR(r.force_ratio, 1.0, 1e-12);
  // Each refinement closer; the finest within a few % (reached: 2.1 % and 3.0 %; at n = 32,
  // 0.6 % and 2.2 %). The active set's edge moves node by node, so the errors fall unevenly and
  // an extrapolation with an observed order is not reliable here.
  for (int k = 1; k < 3; ++k) {
    EXPECT_LT(std::abs(runs[k].a_ratio - 1), std::abs(runs[k - 1].a_ratio - 1)) << k;
    EXPECT_LT(std::abs(runs[k].approach_ratio - 1), std::abs(runs[k - 1].approach_ratio - 1)) << k;
  }
  EXPECT_NEAR(runs[2].a_ratio, 1.0, 0.035);
  EXPECT_NEAR(runs[2].approach_ratio, 1.0, 0.045);
}

namespace {

/// A rigid cylinder (the wire's body, radius R along y) pressed into a slab in plane strain
/// (rollers u_y = 0 on both faces y = 0 and y = L): half-width b = √(4P′R/(πE*)) for a force P′
/// per length, p(x) = p₀√(1 − x²/b²), so Σλx²/Σλ = b²/4 (Johnson, Contact Mechanics, §5.6).
/// Returns b / b_Hertz for the slab graded like graded_block in x and z, n cells across.
double cylinder_half_width_ratio(int n) {
  const double b = kA, length = 4.4 * b;  // y cells as wide as the contact's x cells
  const double per_length = std::numbers::pi * kEStar * b * b / (4 * kR);
  TetMesh mesh = graded_block(n);
  for (Vec3& x : mesh.nodes) x.y() = (x.y() / (15 * kA) + 1) * 0.5 * length;
  fem::ElasticityProblem p;
  p.material.youngs_modulus = kE;
  p.material.poisson_ratio = kNu;
  p.options.degree = 1;
  p.dirichlet = {fem::DirichletCondition::clamped("z0"), fem::DirichletCondition::roller("y0", 1),
                 fem::DirichletCondition::roller("y1", 1)};
  const fem::ElasticitySolver solver(mesh, p);
  std::vector<int> nodes;
  std::vector<Vec3> directions;
  std::vector<double> gaps;
  for (int i = 0; i < static_cast<int>(mesh.nodes.size()); ++i) {
    const Vec3& x = mesh.nodes[i];
    if (std::abs(x.z()) > 1e-12 || std::abs(x.x()) > 1.6 * b) continue;
    nodes.push_back(i);
    directions.emplace_back(0, 0, -1);
    gaps.push_back(x.x() * x.x() / (2 * kR));
  }
  const contact::CondensedWall wall(solver.free_displacement_system(), nodes, directions);
  const Eigen::VectorXd h = Eigen::Map<const Eigen::VectorXd>(gaps.data(), gaps.size());
  const contact::RigidPress pr =
      contact::press_rigid_indenter(wall.compliance(), h, per_length * length, 1e-15);
  double second = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const double x = mesh.nodes[nodes[i]].x();
    second += pr.contact.force[i] * x * x;
    sum += pr.contact.force[i];
  }
  const double ratio = 2 * std::sqrt(second / sum) / b;
  std::printf("HERTZ cylinder n %d: %zu candidates, b/b_Hertz %.4f, W set-up %.2f s\n", n,
              nodes.size(), ratio, wall.setup_seconds());
  return ratio;
}

}  // namespace

TEST(HertzContact, RigidCylinderOnASlabInPlaneStrainConvergesToTheClosedForm) {
  // Reached: 1.1 %, 0.22 %, 0.28 % at n = 12, 18, 24. Below ~0.3 % it stops improving (not
  // attributed; the slab's finite depth, 15b over a clamped base, is one candidate).
  const double coarse = cylinder_half_width_ratio(12);
  EXPECT_NEAR(coarse, 1.0, 0.02);
  for (const int n : {18, 24}) EXPECT_NEAR(cylinder_half_width_ratio(n), 1.0, 0.005) << n;
}
