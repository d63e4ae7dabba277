#include "verification/contact/wire_wall_contact.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "meshes/foundation/errors.hpp"
#include "verification/contact/signorini.hpp"

namespace vessel::contact {

ContactWire contact_wire(const msm::rods::Rod& rod, double radius) {
  ContactWire w;
  w.form = &rod;
  w.constraints = rod.constraints();
  w.fixed = rod.clamp_fixed();
  w.num_nodes = rod.num_nodes();
  w.first_node = rod.layout().first_node;
  w.last_node = rod.layout().tip_node;
  w.radius = radius;
  w.project = [&rod](Eigen::VectorXd& x) { rod.project(x); };
  return w;
}

namespace {

using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

/// The centreline point nearest p: on segment (a, a+1) at parameter s ∈ [0, 1].
struct Nearest {
  int a = 0;
  double s = 0.0;
  bool interior = false;  ///< 0 < s < 1 (else c is a node: a hemisphere's centre)
  Vector3d c, e;          ///< the point and the segment's vector
};

Nearest nearest_on_centreline(const VectorXd& x, int first, int last, const Vector3d& p) {
  Nearest best;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (int i = first; i < last; ++i) {
    const Vector3d xa = x.segment<3>(3 * i), e = x.segment<3>(3 * (i + 1)) - xa;
    const double ee = e.squaredNorm();
    const double t = std::clamp((p - xa).dot(e) / ee, 0.0, 1.0);
    const Vector3d c = xa + t * e;
    const double d2 = (p - c).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best = {i, t, t > 0.0 && t < 1.0, c, e};
    }
  }
  return best;
}

/// The coupled state at (x, λ, n): the wall's displacement u (3 per contact node), and per
/// contact node its displaced position P's nearest centreline point c, d = P − c, the side
/// σ = sign(d·ν_last) (ν_last the node's normal at the last iterate: −1 once the wire's centreline
/// has passed the node), the capsule's normal towards that side ν = σ d/|d|, and the signed gap
/// g = σ|d| − r_w.
struct Geometry {
  VectorXd u;  ///< u_j = Σ_l W_jl n_l λ_l, m (3 per contact node)
  std::vector<Nearest> nearest;
  std::vector<Vector3d> d, nu;
  VectorXd gap;
};

class Coupled {
 public:
  Coupled(const ContactWire& wire, const CondensedWall& wall, const TetMesh& mesh)
      : wire_(wire), W_(wall.compliance()) {
    const std::vector<int>& nodes = wall.nodes();
    const std::vector<Vec3>& axes = wall.directions();
    if (nodes.size() % 3 != 0) throw_not_componentwise();
    for (std::size_t k = 0; k < nodes.size(); k += 3) {
      for (int c = 0; c < 3; ++c) {
        if (nodes[k + c] != nodes[k] || (axes[k + c] - Vec3::Unit(c)).norm() != 0.0) {
          throw_not_componentwise();
        }
      }
      points_.push_back(mesh.nodes[nodes[k]]);
    }
  }

  [[nodiscard]] int num_candidates() const { return static_cast<int>(points_.size()); }
  [[nodiscard]] const MatrixXd& wall_compliance() const { return W_; }

  /// The wall's loads λ_l n_l stacked per component (N), the CondensedWall's force vector.
  [[nodiscard]] static VectorXd loads(const std::vector<Vec3>& n, const VectorXd& lambda) {
    VectorXd v(3 * lambda.size());
    for (Eigen::Index l = 0; l < lambda.size(); ++l) v.segment<3>(3 * l) = lambda[l] * n[l];
    return v;
  }

  Geometry geometry(const VectorXd& x, const VectorXd& lambda, const std::vector<Vec3>& n,
                    const std::vector<Vec3>& last_nu) const {
    Geometry g;
    g.u = W_ * loads(n, lambda);
    const int m = num_candidates();
    g.gap.resize(m);
    for (int j = 0; j < m; ++j) {
      const Vector3d p = points_[j] + g.u.segment<3>(3 * j);
      g.nearest.push_back(nearest_on_centreline(x, wire_.first_node, wire_.last_node, p));
      g.d.push_back(p - g.nearest.back().c);
      const double side = g.d.back().dot(last_nu[j]) >= 0.0 ? 1.0 : -1.0;
      g.nu.push_back(side * g.d.back().normalized());
      g.gap[j] = side * g.d.back().norm() - wire_.radius;
    }
    return g;
  }

  /// Rod rows: ∇E + J_cᵀμ + Σ_k λ_k B_kᵀ n_k (held dofs included).
  VectorXd rod_residual(const VectorXd& x, const VectorXd& mu, const VectorXd& lambda,
                        const std::vector<Vec3>& n, const Geometry& g) const {
    VectorXd r;
    wire_.form->gradient(x, r);
    if (wire_.constraints && mu.size() > 0) {
      msm::SparseMatrix J;
      wire_.constraints->jacobian(x, J);
      r += J.transpose() * mu;
    }
    for (int k = 0; k < num_candidates(); ++k) {
      if (lambda[k] == 0.0) continue;
      const Nearest& c = g.nearest[k];
      const Vector3d f = lambda[k] * n[k];
      r.segment<3>(3 * c.a) += (1.0 - c.s) * f;
      r.segment<3>(3 * (c.a + 1)) += c.s * f;
    }
    return r;
  }

  /// The linearised coupled system about (x, μ, λ) in the unknowns (Δx, Δμ, Δλ): the rod's rows
  /// ∇E + J_cᵀμ + Σ_k λ_k B_kᵀ n_k, the constraints' rows, and every node's gap
  /// g_j + ν_jᵀ(Σ_l W_jl n_l Δλ_l − B_j Δx) (ν_j the capsule's normal towards the node's side:
  /// the signed distance's gradient), so the gap uses the node's whole displacement.
  struct Linearised {
    MatrixXd A;  ///< square, gap rows last
    VectorXd R;  ///< the non-gap rows' residual (A Δ = −R)
  };
  Linearised linearise(const VectorXd& x, const VectorXd& mu, const VectorXd& lambda,
                       const std::vector<Vec3>& n, const Geometry& g, int nd, int mc) const {
    const int m = num_candidates();
    const int r = nd + mc;
    Linearised L;
    MatrixXd& A = L.A;
    A = MatrixXd::Zero(r + m, r + m);
    msm::SparseMatrix H;
    wire_.form->hessian(x, H, false);
    A.topLeftCorner(nd, nd) = MatrixXd(H);
    L.R = VectorXd::Zero(r);
    L.R.head(nd) = rod_residual(x, mu, lambda, n, g);
    if (mc > 0) {
      msm::SparseMatrix J, Hc;
      wire_.constraints->jacobian(x, J);
      wire_.constraints->weighted_hessian(x, mu, Hc);
      A.topLeftCorner(nd, nd) += MatrixXd(Hc);
      const MatrixXd Jd(J);
      A.block(0, nd, nd, mc) = Jd.transpose();
      A.block(nd, 0, mc, nd) = Jd;
      VectorXd c;
      wire_.constraints->evaluate(x, c);
      L.R.tail(mc) = c;
    }
    for (int j = 0; j < m; ++j) {
      const Nearest& c = g.nearest[j];
      const int ia = 3 * c.a, ib = 3 * (c.a + 1), col = r + j;
      // ∂(B_jᵀ n_j λ_j)/∂λ_j at fixed s, and the gap row's −ν_jᵀ B_j.
      A.block<3, 1>(ia, col) += (1.0 - c.s) * n[j];
      A.block<3, 1>(ib, col) += c.s * n[j];
      A.block<1, 3>(col, ia) -= (1.0 - c.s) * g.nu[j].transpose();
      A.block<1, 3>(col, ib) -= c.s * g.nu[j].transpose();
      for (int l = 0; l < m; ++l) {
        A(col, r + l) += g.nu[j].dot(W_.block<3, 3>(3 * j, 3 * l) * n[l]);
      }
      if (!c.interior || lambda[j] == 0.0) continue;
      // The split's change: s = (P − x_a)·e/|e|², so ∂s/∂x_a = (2 s e − e − d)/|e|²,
      // ∂s/∂x_b = (d − 2 s e)/|e|², ∂s/∂λ_l = e·(W_jl n_l)/|e|²; B_jᵀ n_j changes by (−n_j, n_j)
      // ds. (The gap rows have no such term: ν_j ⟂ e at an interior nearest point.)
      const double ee = c.e.squaredNorm();
      const Vector3d f = lambda[j] * n[j];
      const Vector3d d = points_[j] + g.u.segment<3>(3 * j) - x.segment<3>(ia);
      const Vector3d dsa = (2.0 * c.s * c.e - c.e - d) / ee, dsb = (d - 2.0 * c.s * c.e) / ee;
      A.block<3, 3>(ia, ia) -= f * dsa.transpose();
      A.block<3, 3>(ia, ib) -= f * dsb.transpose();
      A.block<3, 3>(ib, ia) += f * dsa.transpose();
      A.block<3, 3>(ib, ib) += f * dsb.transpose();
      for (int l = 0; l < m; ++l) {
        const double ds = c.e.dot(W_.block<3, 3>(3 * j, 3 * l) * n[l]) / ee;
        A.block<3, 1>(ia, r + l) -= ds * f;
        A.block<3, 1>(ib, r + l) += ds * f;
      }
    }
    for (int i = 0; i < nd; ++i) {  // held dofs: Δ = 0
      if (!wire_.fixed[i]) continue;
      A.row(i).setZero();
      A.col(i).setZero();
      A(i, i) = 1.0;
      L.R[i] = 0.0;
    }
    return L;
  }

 private:
  [[noreturn]] static void throw_not_componentwise() {
    throw std::invalid_argument(
        "solve_wire_wall_contact: the wall must be condensed on every component of its contact "
        "nodes (contact::every_component)");
  }
  const ContactWire& wire_;
  const MatrixXd& W_;
  std::vector<Vec3> points_;
};

void check(const ContactWire& wire, const Eigen::VectorXd& start) {
  if (!wire.form) throw std::invalid_argument("solve_wire_wall_contact: the wire has no form");
  if (!(wire.radius > 0.0)) {
    throw std::invalid_argument("solve_wire_wall_contact: the wire's radius must be positive");
  }
  if (start.size() != wire.form->num_dofs() ||
      static_cast<Eigen::Index>(wire.fixed.size()) != start.size() || wire.first_node < 0 ||
      wire.last_node <= wire.first_node || wire.last_node >= wire.num_nodes ||
      3 * wire.num_nodes > start.size()) {
    throw std::invalid_argument(
        "solve_wire_wall_contact: start, fixed and the centreline's nodes must fit the form's "
        "dofs");
  }
}

/// The coupled state a solve starts from and leaves at equilibrium.
struct CoupledState {
  VectorXd x, mu, lambda;
  std::vector<Vec3> n;   ///< each contact node's force direction
  std::vector<Vec3> nu;  ///< each contact node's normal ν at the last iterate (its side)
  std::vector<char> active;
};

/// Each node's normal out of the wire at x, the node at p: its side while it is outside the wire.
std::vector<Vec3> outward(const ContactWire& wire, const VectorXd& x, const std::vector<Vec3>& p) {
  std::vector<Vec3> nu;
  for (const Vec3& pj : p) {
    nu.push_back(
        (pj - nearest_on_centreline(x, wire.first_node, wire.last_node, pj).c).normalized());
  }
  return nu;
}

/// Sequential Signorini solves from `state`, which it leaves at equilibrium.
void solve_sequence(const Coupled& coupled, const ContactWire& wire, const WireWallOptions& options,
                    CoupledState& state, WireWallSolution& out) {
  const int m = coupled.num_candidates();
  const int nd = static_cast<int>(state.x.size());
  const int mc = static_cast<int>(state.mu.size());
  VectorXd& x = state.x;
  VectorXd& mu = state.mu;
  VectorXd& lambda = state.lambda;
  std::vector<Vec3>& dir = state.n;
  std::vector<char>& active = state.active;
  const double penalty_compliance =
      options.penalty_stiffness > 0.0 ? 1.0 / options.penalty_stiffness : 0.0;
  // The rod's rows are linearised about (x, λ) and condensed onto every candidate's gap:
  //   K Δy + B̃ (λ' − λ) = −R,   g + G Δy + D (λ' − λ) = g' ≥ 0,  λ' ≥ 0,  λ'·g' = 0,
  // y = (x, μ), so g' = q + M λ' with M = D − G K⁻¹B̃, a Signorini problem solved exactly
  // (solve_signorini on M's symmetric part; the skew part, O(the angle between n_j and ν_j) and
  // the force's split along a segment, is evaluated at the current λ, so a fixed point is an
  // exact solution). The penalty law λ = k max(0, −g) is the same problem on g + λ/k: M gains
  // 1/k on its diagonal.
  const double extent = x.head(3 * (wire.last_node + 1)).cwiseAbs().maxCoeff();
  double last_step = std::numeric_limits<double>::infinity();
  bool settled = false;
  for (int it = 0;; ++it) {
    const Geometry g = coupled.geometry(x, lambda, dir, state.nu);
    state.nu = g.nu;
    const Coupled::Linearised L = coupled.linearise(x, mu, lambda, dir, g, nd, mc);
    const int r = static_cast<int>(L.R.size());
    double cmax = 0.0;
    if (mc > 0) cmax = L.R.segment(nd, mc).cwiseAbs().maxCoeff();
    {
      VectorXd rod = coupled.rod_residual(x, mu, lambda, dir, g);
      for (int i = 0; i < nd; ++i) {
        if (wire.fixed[i]) rod[i] = 0.0;
      }
      out.residual = rod.norm();
    }
    double worst_gap = 0.0;  // penetration, or a pressed candidate's separation
    for (int j = 0; j < m; ++j) {
      const double gj = g.gap[j] + penalty_compliance * lambda[j];
      worst_gap = std::max(worst_gap, lambda[j] > 0.0 ? std::abs(gj) : -gj);
    }
    // Converged, or at round-off on a settled active set: the last step moved no position by
    // more than 1e-14 of the wire's extent (the stiff stretching term's cancellation floors ‖∇E‖
    // near 1e-10 N).
    const bool feasible =
        cmax <= options.constraint_tolerance && worst_gap <= options.gap_tolerance;
    if (feasible && (out.residual <= options.tolerance * options.force_scale ||
                     (settled && last_step <= 1e-14 * extent))) {
      return;
    }
    if (it == options.max_newton || !L.R.allFinite()) {
      std::ostringstream msg;
      msg << "solve_wire_wall_contact: no equilibrium in " << options.max_newton << " iterations ("
          << std::count(active.begin(), active.end(), 1) << " candidates in contact, rod residual "
          << out.residual << " N, max |c| " << cmax << ", worst gap " << worst_gap << " m)";
      throw std::runtime_error(msg.str());
    }
    const Eigen::PartialPivLU<MatrixXd> K(L.A.topLeftCorner(r, r));
    const MatrixXd X = K.solve(L.A.topRightCorner(r, m));
    const VectorXd y = K.solve(L.R);
    const MatrixXd M = L.A.bottomRightCorner(m, m) - L.A.bottomLeftCorner(m, r) * X;
    MatrixXd Msym = 0.5 * (M + M.transpose());
    const VectorXd q = g.gap - L.A.bottomLeftCorner(m, r) * y - Msym * lambda;
    Msym.diagonal().array() += penalty_compliance;
    const SignoriniSolution lcp = solve_signorini(Msym, q, 0.01 * options.gap_tolerance);
    // Full steps first (quadratic once the active set holds); from the 8th on, half steps, which
    // stop cycling between active sets. Either is cut so that no centreline node and no wall
    // node moves by more than options.max_move × r_w (the gaps are linearised about a surface
    // of curvature 1/r_w: a longer step can carry the wire through the wall).
    double alpha = it < 8 ? 1.0 : 0.5;
    const VectorXd dy = -(y + X * (lcp.force - lambda));
    const VectorXd du = coupled.wall_compliance() * Coupled::loads(dir, lcp.force - lambda);
    double move = 0.0;
    for (int i = wire.first_node; i <= wire.last_node; ++i) {
      move = std::max(move, dy.segment<3>(3 * i).norm());
    }
    for (int j = 0; j < m; ++j) move = std::max(move, du.segment<3>(3 * j).norm());
    if (alpha * move > options.max_move * wire.radius)
      alpha = options.max_move * wire.radius / move;
    const VectorXd step = alpha * dy;
    last_step = step.head(3 * (wire.last_node + 1)).cwiseAbs().maxCoeff();
    x += step.head(nd);
    if (mc > 0) mu += step.segment(nd, mc);
    lambda += alpha * (lcp.force - lambda);
    // A candidate the Signorini solve released decays by the damped steps and would stay
    // "pressed" (λ > 0, its gap open) for ever: released once below 1e-9 of the largest force.
    const double released = 1e-9 * lcp.force.maxCoeff();
    for (int j = 0; j < m; ++j) {
      if (lcp.force[j] == 0.0 && lambda[j] < released) lambda[j] = 0.0;
    }
    if (wire.project) wire.project(x);
    settled = std::equal(active.begin(), active.end(), lcp.active.begin());
    if (!settled) ++out.active_set_changes;
    active.assign(lcp.active.begin(), lcp.active.end());
    ++out.newton_iterations;
  }
}

/// The equilibrium from `state`.
WireWallSolution solve_from(const ContactWire& wire, const CondensedWall& wall, const TetMesh& mesh,
                            CoupledState state, const WireWallOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const Coupled coupled(wire, wall, mesh);
  const int m = coupled.num_candidates();
  WireWallSolution out;
  solve_sequence(coupled, wire, options, state, out);
  out.x = state.x;
  out.rod_multipliers = state.mu;
  out.force = state.lambda;
  out.direction = state.n;
  for (int j = 0; j < m; ++j) {
    if (state.lambda[j] > 0.0) out.active.push_back(j);
  }
  const Geometry g = coupled.geometry(state.x, state.lambda, state.n, state.nu);
  out.gap = g.gap;
  out.normal = g.nu;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace

Vec3 WireWallSolution::total_force_on_wall() const {
  Vec3 f = Vec3::Zero();
  for (const int j : active) f += force[j] * direction[static_cast<std::size_t>(j)];
  return f;
}

Eigen::VectorXd WireWallSolution::wall_loads() const {
  VectorXd v = VectorXd::Zero(3 * force.size());
  for (const int j : active)
    v.segment<3>(3 * j) = force[j] * direction[static_cast<std::size_t>(j)];
  return v;
}

WireWallSolution solve_wire_wall_contact(const ContactWire& wire, const CondensedWall& wall,
                                         const std::vector<Vec3>& directions, const TetMesh& mesh,
                                         const Eigen::VectorXd& start,
                                         const std::vector<int>& initial_active,
                                         const WireWallOptions& options) {
  check(wire, start);
  const int m = static_cast<int>(wall.nodes().size() / 3);
  if (static_cast<int>(directions.size()) != m) {
    throw std::invalid_argument("solve_wire_wall_contact: " + std::to_string(directions.size()) +
                                " directions for " + std::to_string(m) + " contact nodes");
  }
  const int mc = wire.constraints ? wire.constraints->num_constraints() : 0;
  std::vector<Vec3> points;
  for (std::size_t k = 0; k < wall.nodes().size(); k += 3)
    points.push_back(mesh.nodes[wall.nodes()[k]]);
  CoupledState state{
      start,      VectorXd::Zero(mc),           VectorXd::Zero(m),
      directions, outward(wire, start, points), std::vector<char>(static_cast<std::size_t>(m), 0)};
  for (const int j : initial_active) state.active[static_cast<std::size_t>(j)] = 1;
  return solve_from(wire, wall, mesh, std::move(state), options);
}

GrownContact solve_wire_wall_contact_growing(
    const ContactWire& wire, const fem::FreeDisplacementSystem& system, const TetMesh& mesh,
    std::vector<int> nodes, const Eigen::VectorXd& start, const std::vector<int>& initial_active,
    const WireWallOptions& options, const BandGrowth& growth) {
  check(wire, start);
  const std::vector<Triangle> triangles =
      mesh.group_triangles(mesh.require_group(growth.surface_group, 2, "wall mesh"));
  const std::vector<int> surface =
      mesh.group_nodes(mesh.require_group(growth.surface_group, 2, "wall mesh"));
  GrownContact out;
  auto build = [&] {
    const ComponentCandidates all = every_component(nodes);
    out.wall = std::make_unique<CondensedWall>(system, all.nodes, all.directions);
  };
  build();
  out.solution = solve_wire_wall_contact(wire, *out.wall,
                                         into_wall_directions(mesh, nodes, growth.surface_group),
                                         mesh, start, initial_active, options);
  for (;;) {
    std::vector<int> pressed;
    for (const int j : out.solution.active) pressed.push_back(nodes[static_cast<std::size_t>(j)]);
    const std::vector<Vec3> u = out.wall->displacement(out.solution.wall_loads());
    const std::vector<int> added = joining_the_band(mesh, triangles, surface, nodes, pressed, wire,
                                                    out.solution.x, u, growth.margin);
    if (added.empty()) break;
    if (out.rounds == growth.max_rounds) {
      throw std::runtime_error(
          "solve_wire_wall_contact_growing: the contact still reaches the "
          "band's edge after " +
          std::to_string(growth.max_rounds) + " growths (" + std::to_string(nodes.size()) +
          " candidates)");
    }
    // Re-solve from the last equilibrium, the old candidates' forces carried, the new ones' zero.
    const int m_old = static_cast<int>(nodes.size());
    nodes.insert(nodes.end(), added.begin(), added.end());
    build();
    const int m = static_cast<int>(nodes.size());
    std::vector<Vec3> moved;
    for (const int node : added) moved.push_back(mesh.nodes[node] + u[node]);
    CoupledState state{out.solution.x,      out.solution.rod_multipliers,
                       VectorXd::Zero(m),   into_wall_directions(mesh, nodes, growth.surface_group),
                       out.solution.normal, std::vector<char>(static_cast<std::size_t>(m), 0)};
    const std::vector<Vec3> fresh = outward(wire, out.solution.x, moved);
    state.nu.insert(state.nu.end(), fresh.begin(), fresh.end());
    state.lambda.head(m_old) = out.solution.force;
    for (const int j : out.solution.active) state.active[static_cast<std::size_t>(j)] = 1;
    const WireWallSolution last = std::move(out.solution);
    out.solution = solve_from(wire, *out.wall, mesh, std::move(state), options);
    out.solution.newton_iterations += last.newton_iterations;  // over every round
    out.solution.active_set_changes += last.active_set_changes;
    out.solution.seconds += last.seconds;
    ++out.rounds;
  }
  out.nodes = nodes;
  return out;
}

std::vector<int> joining_the_band(const TetMesh& mesh, const std::vector<Triangle>& triangles,
                                  const std::vector<int>& surface, const std::vector<int>& band,
                                  const std::vector<int>& pressed, const ContactWire& wire,
                                  const Eigen::VectorXd& x, const std::vector<Vec3>& displacement,
                                  double margin) {
  std::vector<char> in(mesh.nodes.size(), 0), bears(mesh.nodes.size(), 0),
      grow(mesh.nodes.size(), 0);
  for (const int n : band) in[static_cast<std::size_t>(n)] = 1;
  for (const int n : pressed) bears[static_cast<std::size_t>(n)] = 1;
  // A pressed candidate on the band's edge: its surface neighbours outside the band join.
  for (const Triangle& t : triangles) {
    bool any = false;
    for (int k = 0; k < 3; ++k) any = any || bears[static_cast<std::size_t>(t[k])];
    if (!any) continue;
    for (int k = 0; k < 3; ++k) {
      if (!in[static_cast<std::size_t>(t[k])]) grow[static_cast<std::size_t>(t[k])] = 1;
    }
  }
  // A node outside the band that the displaced wall brings within `margin` of the wire's surface.
  for (const int n : surface) {
    const auto i = static_cast<std::size_t>(n);
    if (!in[i] && capsule_gap(wire, x, mesh.nodes[i] + displacement[i]) < margin) grow[i] = 1;
  }
  std::vector<int> added;
  for (std::size_t n = 0; n < grow.size(); ++n) {
    if (grow[n]) added.push_back(static_cast<int>(n));
  }
  return added;
}

void GrownContact::pressed(std::vector<int>& mesh_nodes, std::vector<double>& forces) const {
  mesh_nodes.clear();
  forces.clear();
  for (const int j : solution.active) {
    mesh_nodes.push_back(nodes[static_cast<std::size_t>(j)]);
    forces.push_back(solution.force[j]);
  }
}

double capsule_gap(const ContactWire& wire, const Eigen::VectorXd& x, const Vec3& point) {
  const Nearest c = nearest_on_centreline(x, wire.first_node, wire.last_node, point);
  return (point - c.c).norm() - wire.radius;
}

Vec3 clamp_reaction(const ContactWire& wire, const CondensedWall& wall, const TetMesh& mesh,
                    const WireWallSolution& solution) {
  const Coupled coupled(wire, wall, mesh);
  const Geometry g =
      coupled.geometry(solution.x, solution.force, solution.direction, solution.normal);
  const VectorXd r = coupled.rod_residual(solution.x, solution.rod_multipliers, solution.force,
                                          solution.direction, g);
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < wire.num_nodes; ++i) {
    if (wire.fixed[3 * i] || wire.fixed[3 * i + 1] || wire.fixed[3 * i + 2]) {
      sum += r.segment<3>(3 * i);
    }
  }
  return sum;
}

std::vector<Vec3> into_wall_directions(const TetMesh& mesh, const std::vector<int>& nodes,
                                       const std::string& surface_group) {
  const PhysicalGroup& group = mesh.require_group(surface_group, 2, "wall mesh");
  std::vector<Vec3> sum(mesh.nodes.size(), Vec3::Zero());
  for (const Triangle& t : mesh.group_triangles(group)) {
    const Vec3 area2 =
        (mesh.nodes[t[1]] - mesh.nodes[t[0]]).cross(mesh.nodes[t[2]] - mesh.nodes[t[0]]);
    for (int k = 0; k < 3; ++k) sum[t[k]] += area2;
  }
  std::vector<Vec3> out;
  for (const int node : nodes) {
    if (node < 0 || static_cast<std::size_t>(node) >= sum.size() || sum[node].norm() == 0.0) {
      throw InputError("contact candidate node " + std::to_string(node) +
                       " is not a node of the group '" + surface_group + "'");
    }
    out.push_back(-sum[node].normalized());
  }
  return out;
}

}  // namespace vessel::contact
