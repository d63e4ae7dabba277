// Many contacts against a rigid tube: a long wire clamped on the axis at both ends of a straight
// tube, its ends brought together until it lies on the wall as a helix. Away from the ends it is
// Lubinski's weightless helix (Lubinski, Althouse & Logan 1962; Mitchell 1988): axial compressive
// force F = 8π²EI/p² and contact force per length w = r_c F²/(4EI), r_c the clearance between
// the tube's axis and the wire's centreline. Those are the small-angle limit of the Kirchhoff
// helix on a cylinder (below, exact_helix), which also judges the discretisation. Rows printed as
// "HELIX model N ..." for docs/rods.md.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <vector>

#include "msm/rods/der_rod.hpp"
#include "msm/rods/rigid_wall.hpp"

namespace vessel::msm::rods::test {
namespace {

using std::numbers::pi;

// A 0.356 mm (0.014") solid nitinol core in a 3 mm lumen (inner radius 1.5 mm).
const RodMaterial kNitinol{48e9, 48e9 / 2.66, 6450.0};
constexpr double kWire = 0.356e-3;
constexpr double kClearance = 1.5e-3 - kWire / 2;  // r_c, m
// Ten pitches of about 160 mm: r_c·2π/p ≈ 0.05, so the helix angle's corrections to Lubinski's
// small-angle relations stay near 0.3 % (exact_helix).
constexpr double kPitchGuess = 0.16;
constexpr double kLength = 10 * kPitchGuess;

/// The Kirchhoff helix on a cylinder of radius R (centreline), axial wavenumber k (rad/m, its
/// sign the handedness), twisting moment M3 (N·m, right-handed about the tangent): with α the
/// helix angle (tan α = R k), curvature κ = sin²α/R and torsion τ = sin α cos α/R, the moment
/// m = EI κ b + M3 t and the force n = N_t t + N_b b with N_b = κ(M3 − EI τ) (from m′ + t × n = 0),
/// the wall's force per arc length w = N_b τ − N_t κ along the inward normal (from n′ + f = 0). The
/// clamps hold the wire on the axis, where the axial moment is M3 alone; it is constant along the
/// wire (the wall's force is radial), which gives the axial force
///   F = 2 EI sin²α cos α / R² + M3 (2 cos α + 1)(cos α − 1)/(R sin α).
/// For small α and M3 = 0: F = 2EIk² = 8π²EI/p² and w = R F²/(4EI), Lubinski's helix.
struct HelixRelations {
  double force = 0.0;             ///< F from (R, k, M3), N
  double force_per_length = 0.0;  ///< w from (R, k, M3, measured F), N/m
};

HelixRelations exact_helix(double EI, double R, double k, double M3, double measured_force) {
  const double a = std::atan(R * k), s = std::sin(a), c = std::cos(a);
  const double kappa = s * s / R, tau = s * c / R;
  HelixRelations h;
  h.force = 2.0 * EI * s * s * c / (R * R) + M3 * (2.0 * c + 1.0) * (c - 1.0) / (R * s);
  const double Nb = kappa * (M3 - EI * tau);
  const double Nt = -(measured_force + Nb * s) / c;  // n·e_z = −F
  h.force_per_length = Nb * tau - Nt * kappa;
  return h;
}

/// The starting guess: a helix of wavenumber k on the wall (radius R), its radius ramped from
/// the axis over the first and last quarter pitch (tangent along the axis at both clamps), sampled
/// at equal arc length l = L/N. Its axial extent Z (the clamps' distance) makes the arc length L.
/// The ramp is short because a free span buckles on its own under F = 2EIk² beyond p/√2: from a
/// half-pitch ramp the free spans bulge through the wall and full Newton steps diverge.
struct Guess {
  std::vector<Eigen::Vector3d> nodes;  ///< N + 1 material nodes
  std::vector<char> on_wall;
  double span = 0.0;  ///< Z, m
};

Guess helical_guess(double R, double k, double L, int N) {
  const double ramp = 0.5 * pi / std::abs(k);  // a quarter pitch
  const auto point = [&](double z, double Z) {
    double h = 1.0;
    if (z < ramp) h = std::pow(std::sin(0.5 * pi * z / ramp), 2);
    if (Z - z < ramp) h = std::pow(std::sin(0.5 * pi * (Z - z) / ramp), 2);
    return Eigen::Vector3d(R * h * std::cos(k * z), R * h * std::sin(k * z), z);
  };
  constexpr int kFine = 400000;
  const auto arc = [&](double Z, std::vector<double>* s) {
    double total = 0.0;
    Eigen::Vector3d prev = point(0.0, Z);
    if (s) s->assign(1, 0.0);
    for (int i = 1; i <= kFine; ++i) {
      const Eigen::Vector3d p = point(Z * i / kFine, Z);
      total += (p - prev).norm();
      prev = p;
      if (s) s->push_back(total);
    }
    return total;
  };
  double lo = L * (1.0 - R * R * k * k), hi = L;  // arc(lo) < L ≤ arc(hi)
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (arc(mid, nullptr) < L ? lo : hi) = mid;
  }
  Guess g;
  g.span = 0.5 * (lo + hi);
  std::vector<double> s;
  arc(g.span, &s);
  int j = 0;
  for (int i = 0; i <= N; ++i) {
    const double target = L * i / N;
    while (j + 1 < kFine && s[j + 1] < target) ++j;
    const double t = std::clamp((target - s[j]) / (s[j + 1] - s[j]), 0.0, 1.0);
    const double z = g.span * (j + t) / kFine;
    g.nodes.push_back(point(z, g.span));
    g.on_wall.push_back(z >= ramp && g.span - z >= ramp);
  }
  g.nodes.front() = Eigen::Vector3d::Zero();
  g.nodes.back() = Eigen::Vector3d(0.0, 0.0, g.span);
  return g;
}

struct HelixRun {
  int segments = 0;
  double pitch = 0.0, force = 0.0, start_force = 0.0, force_per_length = 0.0, twist_moment = 0.0;
  double radius_spread = 0.0;  ///< max − min radius of the middle third's nodes, m
  int middle_nodes = 0, middle_contacts = 0, contacts = 0, changes = 0;
  double min_gap = 0.0, seconds = 0.0;
};

/// DER with N segments, both ends clamped on the axis, from the helical guess.
HelixRun der_helix(int N) {
  const auto t0 = std::chrono::steady_clock::now();
  RodSpec spec = uniform_rod(kNitinol, kLength, kWire, N);
  spec.direction = Eigen::Vector3d::UnitZ();
  spec.clamp_end = true;
  DerRod rod(make_layout(spec));
  const int tip = rod.layout().tip_node;
  const double l = kLength / N;
  const Guess guess = helical_guess(kClearance, 2.0 * pi / kPitchGuess, kLength, N);
  VectorXd x = rod.rest_state();
  std::vector<int> initial;
  for (int i = 0; i <= N; ++i) {
    x.segment<3>(3 * (i + 1)) = guess.nodes[i];
    if (guess.on_wall[i] && i >= 1 && i + 1 <= N - 1) initial.push_back(i + 1);
  }
  x.segment<3>(0) = Eigen::Vector3d(0.0, 0.0, -l);
  x.segment<3>(3 * (tip + 1)) = Eigen::Vector3d(0.0, 0.0, guess.span + l);
  rod.update_reference(x);
  const StraightTube tube(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), kClearance);
  const double EI = rod.layout().section[1].EI;
  ConstrainedOptions options;
  options.force_scale = EI * std::pow(2.0 * pi / kPitchGuess, 2);
  const ContactSolution c = solve_wall_contact(rod, nullptr, rod.clamp_fixed(), x, tube, 2, tip - 1,
                                               options, 4 * N, {}, initial);
  HelixRun run;
  run.segments = N;
  run.changes = c.active_set_changes;
  run.contacts = static_cast<int>(c.nodes.size());
  run.min_gap = c.min_gap;
  // The clamps' reactions: the held dofs' energy gradient (no contact acts on them).
  VectorXd g;
  rod.gradient(c.x, g);
  run.force = -(g[3 * tip + 2] + g[3 * (tip + 1) + 2]);
  run.start_force = g[2] + g[3 * 1 + 2];
  run.twist_moment = g[rod.twist_dof(rod.layout().num_edges() - 1)];
  // The middle third: pitch from the centreline's angle about the axis against z (least
  // squares), contact force per arc length from the nodes' forces over their Voronoi lengths.
  const int first = 1 + (N + 2) / 3, last = 1 + (2 * N) / 3;
  std::vector<double> phi, z;
  double rmin = 1e9, rmax = 0.0;
  for (int i = first; i <= last; ++i) {
    const Eigen::Vector3d p = c.x.segment<3>(3 * i);
    double a = std::atan2(p.y(), p.x());
    if (!phi.empty()) a += 2.0 * pi * std::round((phi.back() - a) / (2.0 * pi));
    phi.push_back(a);
    z.push_back(p.z());
    rmin = std::min(rmin, std::hypot(p.x(), p.y()));
    rmax = std::max(rmax, std::hypot(p.x(), p.y()));
  }
  run.radius_spread = rmax - rmin;
  const double n = static_cast<double>(phi.size());
  double sz = 0, sp = 0, szz = 0, szp = 0;
  for (std::size_t i = 0; i < phi.size(); ++i) {
    sz += z[i];
    sp += phi[i];
    szz += z[i] * z[i];
    szp += z[i] * phi[i];
  }
  const double k = (n * szp - sz * sp) / (n * szz - sz * sz);
  run.pitch = 2.0 * pi / k;  // signed: the handedness
  run.middle_nodes = static_cast<int>(phi.size());
  double total = 0.0;
  for (std::size_t a = 0; a < c.nodes.size(); ++a) {
    if (c.nodes[a] >= first && c.nodes[a] <= last) {
      total += c.forces[a];
      ++run.middle_contacts;
    }
  }
  run.force_per_length = total / (n * l);
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return run;
}

double load_average() {
  std::ifstream f("/proc/loadavg");
  double a = 0.0;
  f >> a;
  return a;
}

// The exact helix's relations reduce to Lubinski's as the helix angle vanishes, with a relative
// deviation of order (R k)²: at M3 = 0, F = 2EIk² cos³α.
TEST(LubinskiHelix, ExactHelixTendsToLubinskiAtSmallAngles) {
  const double EI = 4e-5, k = 40.0;
  for (double R : {1e-3, 1e-4, 1e-5}) {
    const double F = 2.0 * EI * k * k;
    const HelixRelations h = exact_helix(EI, R, k, 0.0, F);
    const double rk2 = R * R * k * k;
    EXPECT_NEAR(h.force / F - 1.0, -1.5 * rk2, 0.1 * rk2) << R;
    EXPECT_NEAR(h.force_per_length / (R * F * F / (4.0 * EI)) - 1.0, 0.0, 3.0 * rk2) << R;
  }
}

TEST(LubinskiHelix, DerWireBuckledInARigidTube) {
  const double EI = solid_section(kNitinol, kWire).EI;
  double previous_force = 0.0, previous_w = 0.0;
  for (int N : {240, 480, 960}) {
    const HelixRun r = der_helix(N);
    const double p = std::abs(r.pitch), k = 2.0 * pi / r.pitch;
    const double lub_force = r.force * p * p / (8.0 * pi * pi * EI) - 1.0;
    const double lub_w = r.force_per_length * 4.0 * EI / (kClearance * r.force * r.force) - 1.0;
    const HelixRelations exact = exact_helix(EI, kClearance, k, r.twist_moment, r.force);
    const double exact_force = r.force / exact.force - 1.0;
    const double exact_w = r.force_per_length / exact.force_per_length - 1.0;
    std::printf(
        "HELIX DER N %d (%.1f per pitch) F %.6e N (start clamp %.6e) p %.6e m w %.6e N/m M3 %.3e "
        "N·m | Lubinski F %+.3e w %+.3e | exact helix F %+.3e w %+.3e | middle contacts %d/%d, "
        "contacts %d, changes %d, min gap %.1e m, %.1f s, load %.2f\n",
        N, N * p / kLength, r.force, r.start_force, p, r.force_per_length, r.twist_moment,
        lub_force, lub_w, exact_force, exact_w, r.middle_contacts, r.middle_nodes, r.contacts,
        r.changes, r.min_gap, r.seconds, load_average());
    // Equal and opposite clamp reactions (the wall's forces are radial), to the Newton tolerance
    // summed over the nodes; the middle third lies on the wall, node by node.
    EXPECT_NEAR(r.start_force / r.force, 1.0, 1e-8) << N;
    EXPECT_EQ(r.middle_contacts, r.middle_nodes) << N;
    EXPECT_GE(r.min_gap, -1e-12) << N;
    EXPECT_LE(std::abs(lub_force), 0.02) << N;
    EXPECT_LE(std::abs(lub_w), 0.02) << N;
    // The discretisation: against the exact helix, the force's error falls at second order
    // (measured: 4.0 and 3.9 times per doubling) and w's stays below 1e-4 and falls.
    if (previous_force != 0.0) {
      EXPECT_GT(std::abs(previous_force / exact_force), 3.0) << N;
      EXPECT_LT(std::abs(exact_w), std::abs(previous_w)) << N;
    }
    EXPECT_LE(std::abs(exact_w), 1e-4) << N;
    previous_force = exact_force;
    previous_w = exact_w;
  }
}

}  // namespace
}  // namespace vessel::msm::rods::test
