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

/// The coupled system's state on one active set: the wall's displacement along each candidate's
/// direction, and per active candidate its nearest centreline point, normal ν and gap.
struct ActiveGeometry {
  VectorXd along;  ///< (Wλ)_j for every candidate, m
  std::vector<Nearest> nearest;
  std::vector<Vector3d> nu;
  VectorXd gap;
};

class Coupled {
 public:
  Coupled(const ContactWire& wire, const CondensedWall& wall, const TetMesh& mesh)
      : wire_(wire), W_(wall.compliance()), n_(wall.directions()) {
    points_.reserve(wall.nodes().size());
    for (const int node : wall.nodes()) points_.push_back(mesh.nodes[node]);
  }

  [[nodiscard]] int num_candidates() const { return static_cast<int>(points_.size()); }

  /// P_j = X_j + (Wλ)_j n_j.
  [[nodiscard]] Vector3d point(int j, const VectorXd& along) const {
    return points_[j] + along[j] * n_[j];
  }

  [[nodiscard]] VectorXd wall_along(const std::vector<int>& active, const VectorXd& lambda) const {
    VectorXd along = VectorXd::Zero(num_candidates());
    for (std::size_t k = 0; k < active.size(); ++k) along += W_.col(active[k]) * lambda[k];
    return along;
  }

  [[nodiscard]] double gap_of(int j, const VectorXd& x, const VectorXd& along) const {
    const Vector3d p = point(j, along);
    const Nearest c = nearest_on_centreline(x, wire_.first_node, wire_.last_node, p);
    return (p - c.c).norm() - wire_.radius;
  }

  ActiveGeometry geometry(const std::vector<int>& active, const VectorXd& x,
                          const VectorXd& lambda) const {
    ActiveGeometry g;
    g.along = wall_along(active, lambda);
    g.gap.resize(static_cast<Eigen::Index>(active.size()));
    for (std::size_t k = 0; k < active.size(); ++k) {
      const Vector3d p = point(active[k], g.along);
      g.nearest.push_back(nearest_on_centreline(x, wire_.first_node, wire_.last_node, p));
      const Vector3d d = p - g.nearest.back().c;
      g.nu.push_back(d / d.norm());
      g.gap[static_cast<Eigen::Index>(k)] = d.norm() - wire_.radius;
    }
    return g;
  }

  /// Rod rows: ∇E + J_cᵀμ + Σ_k λ_k B_kᵀ n_k (held dofs included).
  VectorXd rod_residual(const std::vector<int>& active, const VectorXd& x, const VectorXd& mu,
                        const VectorXd& lambda, const ActiveGeometry& g) const {
    VectorXd r;
    wire_.form->gradient(x, r);
    if (wire_.constraints && mu.size() > 0) {
      msm::SparseMatrix J;
      wire_.constraints->jacobian(x, J);
      r += J.transpose() * mu;
    }
    for (std::size_t k = 0; k < active.size(); ++k) {
      const Nearest& c = g.nearest[k];
      const Vector3d f = lambda[static_cast<Eigen::Index>(k)] * n_[active[k]];
      r.segment<3>(3 * c.a) += (1.0 - c.s) * f;
      r.segment<3>(3 * (c.a + 1)) += c.s * f;
    }
    return r;
  }

  /// ∂(rod rows, constraint rows, gap rows)/∂(x, μ, λ_A), held dofs' rows and columns the
  /// identity's.
  MatrixXd jacobian(const std::vector<int>& active, const VectorXd& x, const VectorXd& mu,
                    const VectorXd& lambda, const ActiveGeometry& g, int n, int mc) const {
    const int ma = static_cast<int>(active.size());
    MatrixXd A = MatrixXd::Zero(n + mc + ma, n + mc + ma);
    msm::SparseMatrix H;
    wire_.form->hessian(x, H, false);
    A.topLeftCorner(n, n) = MatrixXd(H);
    if (mc > 0) {
      msm::SparseMatrix J, Hc;
      wire_.constraints->jacobian(x, J);
      wire_.constraints->weighted_hessian(x, mu, Hc);
      A.topLeftCorner(n, n) += MatrixXd(Hc);
      const MatrixXd Jd(J);
      A.block(0, n, n, mc) = Jd.transpose();
      A.block(n, 0, mc, n) = Jd;
    }
    for (int k = 0; k < ma; ++k) {
      const int j = active[k];
      const Nearest& c = g.nearest[k];
      const Vector3d& nk = n_[j];
      const int ia = 3 * c.a, ib = 3 * (c.a + 1), col = n + mc + k;
      // ∂(B_kᵀ n_k)/∂λ_k at fixed s, and the gap row −ν_kᵀ B_k, (ν_k·n_k) W_kl.
      A.block<3, 1>(ia, col) += (1.0 - c.s) * nk;
      A.block<3, 1>(ib, col) += c.s * nk;
      A.block<1, 3>(col, ia) -= (1.0 - c.s) * g.nu[k].transpose();
      A.block<1, 3>(col, ib) -= c.s * g.nu[k].transpose();
      for (int l = 0; l < ma; ++l) A(col, n + mc + l) += g.nu[k].dot(nk) * W_(j, active[l]);
      if (!c.interior) continue;
      // The split's change: s = (P − x_a)·e/|e|², so ∂s/∂x_a = (2 s e − e − d)/|e|²,
      // ∂s/∂x_b = (d − 2 s e)/|e|², ∂s/∂λ_l = (e·n_k/|e|²) W_kl; B_kᵀ n_k changes by (−n_k, n_k)
      // ds. (The gap rows have no such term: ν_k ⟂ e at an interior nearest point.)
      const double ee = c.e.squaredNorm(), lk = lambda[k];
      const Vector3d d = point(j, g.along) - x.segment<3>(ia);
      const Vector3d dsa = (2.0 * c.s * c.e - c.e - d) / ee, dsb = (d - 2.0 * c.s * c.e) / ee;
      A.block<3, 3>(ia, ia) -= lk * nk * dsa.transpose();
      A.block<3, 3>(ia, ib) -= lk * nk * dsb.transpose();
      A.block<3, 3>(ib, ia) += lk * nk * dsa.transpose();
      A.block<3, 3>(ib, ib) += lk * nk * dsb.transpose();
      const double ds_dalong = c.e.dot(nk) / ee;
      for (int l = 0; l < ma; ++l) {
        const double ds = ds_dalong * W_(j, active[l]);
        A.block<3, 1>(ia, n + mc + l) -= lk * ds * nk;
        A.block<3, 1>(ib, n + mc + l) += lk * ds * nk;
      }
    }
    for (int i = 0; i < n; ++i) {  // held dofs: Δ = 0
      if (!wire_.fixed[i]) continue;
      A.row(i).setZero();
      A.col(i).setZero();
      A(i, i) = 1.0;
    }
    return A;
  }

 private:
  const ContactWire& wire_;
  const MatrixXd& W_;
  const std::vector<Vec3>& n_;
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

}  // namespace

Vec3 WireWallSolution::total_force_on_wall(const CondensedWall& wall) const {
  Vec3 f = Vec3::Zero();
  for (const int j : active) f += force[j] * wall.directions()[static_cast<std::size_t>(j)];
  return f;
}

namespace {

/// The coupled state a solve starts from and leaves at equilibrium.
struct CoupledState {
  VectorXd x, mu, lambda;
  std::vector<char> active;
};

/// Sequential Signorini solves from `state`, which it leaves at equilibrium.
void solve_sequence(const Coupled& coupled, const ContactWire& wire, const WireWallOptions& options,
                    CoupledState& state, WireWallSolution& out) {
  const int m = coupled.num_candidates();
  const int n = static_cast<int>(state.x.size());
  const int mc = static_cast<int>(state.mu.size());
  const int r = n + mc;
  std::vector<int> all(static_cast<std::size_t>(m));
  for (int j = 0; j < m; ++j) all[static_cast<std::size_t>(j)] = j;
  VectorXd& x = state.x;
  VectorXd& mu = state.mu;
  VectorXd& lambda = state.lambda;
  std::vector<char>& active = state.active;
  // The rod's rows are linearised about (x, λ) and condensed onto every candidate's gap:
  //   K Δy + B̃ (λ' − λ) = −R,   g + G Δy + D (λ' − λ) = g' ≥ 0,  λ' ≥ 0,  λ'·g' = 0,
  // y = (x, μ), so g' = q + M λ' with M = D − G K⁻¹B̃, a Signorini problem solved exactly
  // (solve_signorini on M's symmetric part; the skew part, O(the angle between n_j and the
  // capsule's normal), is evaluated at the current λ, so a fixed point is an exact solution).
  const double extent = x.head(3 * (wire.last_node + 1)).cwiseAbs().maxCoeff();
  double last_step = std::numeric_limits<double>::infinity();
  bool settled = false;
  for (int it = 0;; ++it) {
    const ActiveGeometry g = coupled.geometry(all, x, lambda);
    VectorXd R(r);
    R.head(n) = coupled.rod_residual(all, x, mu, lambda, g);
    for (int i = 0; i < n; ++i) {
      if (wire.fixed[i]) R[i] = 0.0;
    }
    double cmax = 0.0;
    if (mc > 0) {
      VectorXd c;
      wire.constraints->evaluate(x, c);
      R.tail(mc) = c;
      cmax = c.cwiseAbs().maxCoeff();
    }
    out.residual = R.head(n).norm();
    double worst_gap = 0.0;  // penetration, or a pressed candidate's separation
    for (int j = 0; j < m; ++j) {
      worst_gap = std::max(worst_gap, lambda[j] > 0.0 ? std::abs(g.gap[j]) : -g.gap[j]);
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
    if (it == options.max_newton || !R.allFinite()) {
      std::ostringstream msg;
      msg << "solve_wire_wall_contact: no equilibrium in " << options.max_newton << " iterations ("
          << std::count(active.begin(), active.end(), 1) << " candidates in contact, rod residual "
          << out.residual << " N, max |c| " << cmax << ", worst gap " << worst_gap << " m)";
      throw std::runtime_error(msg.str());
    }
    const MatrixXd A = coupled.jacobian(all, x, mu, lambda, g, n, mc);
    const Eigen::PartialPivLU<MatrixXd> K(A.topLeftCorner(r, r));
    const MatrixXd X = K.solve(A.topRightCorner(r, m));
    const VectorXd y = K.solve(R);
    const MatrixXd M = A.bottomRightCorner(m, m) - A.bottomLeftCorner(m, r) * X;
    const MatrixXd Msym = 0.5 * (M + M.transpose());
    const VectorXd q = g.gap - A.bottomLeftCorner(m, r) * y - Msym * lambda;
    const SignoriniSolution lcp = solve_signorini(Msym, q, 0.01 * options.gap_tolerance);
    // Full steps first (quadratic once the active set holds); from the 8th on, half steps: the
    // skew part evaluated at the last λ can make full steps cycle between active sets on a
    // contact deep enough that n_j and the capsule's normal part by tens of degrees.
    const double alpha = it < 8 ? 1.0 : 0.5;
    const VectorXd step = -alpha * (y + X * (lcp.force - lambda));
    last_step = step.head(3 * (wire.last_node + 1)).cwiseAbs().maxCoeff();
    x += step.head(n);
    if (mc > 0) mu += step.tail(mc);
    lambda += alpha * (lcp.force - lambda);
    // A candidate the Signorini solve released decays by half per damped step and would stay
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

}  // namespace

namespace {

/// The equilibrium from `state`.
WireWallSolution solve_from(const ContactWire& wire, const CondensedWall& wall, const TetMesh& mesh,
                            CoupledState state, const WireWallOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const int m = static_cast<int>(wall.nodes().size());
  WireWallSolution out;
  const Coupled coupled(wire, wall, mesh);
  solve_sequence(coupled, wire, options, state, out);
  out.x = state.x;
  out.rod_multipliers = state.mu;
  out.force = state.lambda;
  for (int j = 0; j < m; ++j) {
    if (state.lambda[j] > 0.0) out.active.push_back(j);
  }
  std::vector<int> all(static_cast<std::size_t>(m));
  for (int j = 0; j < m; ++j) all[static_cast<std::size_t>(j)] = j;
  const VectorXd along = coupled.wall_along(all, state.lambda);
  out.gap.resize(m);
  for (int j = 0; j < m; ++j) out.gap[j] = coupled.gap_of(j, state.x, along);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace

WireWallSolution solve_wire_wall_contact(const ContactWire& wire, const CondensedWall& wall,
                                         const TetMesh& mesh, const Eigen::VectorXd& start,
                                         const std::vector<int>& initial_active,
                                         const WireWallOptions& options) {
  check(wire, start);
  const int m = static_cast<int>(wall.nodes().size());
  const int mc = wire.constraints ? wire.constraints->num_constraints() : 0;
  CoupledState state{start, VectorXd::Zero(mc), VectorXd::Zero(m),
                     std::vector<char>(static_cast<std::size_t>(m), 0)};
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
    out.wall = std::make_unique<CondensedWall>(
        system, nodes, into_wall_directions(mesh, nodes, growth.surface_group));
  };
  build();
  out.solution = solve_wire_wall_contact(wire, *out.wall, mesh, start, initial_active, options);
  for (;;) {
    std::vector<char> in(mesh.nodes.size(), 0), grow(mesh.nodes.size(), 0);
    for (const int node : nodes) in[static_cast<std::size_t>(node)] = 1;
    std::vector<char> pressed(mesh.nodes.size(), 0);
    for (const int j : out.solution.active) pressed[static_cast<std::size_t>(nodes[j])] = 1;
    // A pressed candidate on the band's edge: its surface neighbours outside the band join.
    for (const Triangle& t : triangles) {
      bool any = false;
      for (int k = 0; k < 3; ++k) any = any || pressed[static_cast<std::size_t>(t[k])];
      if (!any) continue;
      for (int k = 0; k < 3; ++k) {
        if (!in[static_cast<std::size_t>(t[k])]) grow[static_cast<std::size_t>(t[k])] = 1;
      }
    }
    // A non-candidate that the displaced wall brings within `margin` of the wire's surface.
    const std::vector<Vec3> u = out.wall->displacement(out.solution.force);
    for (const int node : surface) {
      if (in[static_cast<std::size_t>(node)]) continue;
      if (capsule_gap(wire, out.solution.x, mesh.nodes[node] + u[node]) < growth.margin) {
        grow[static_cast<std::size_t>(node)] = 1;
      }
    }
    std::vector<int> added;
    for (std::size_t node = 0; node < grow.size(); ++node) {
      if (grow[node]) added.push_back(static_cast<int>(node));
    }
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
    CoupledState state{out.solution.x, out.solution.rod_multipliers, VectorXd::Zero(m),
                       std::vector<char>(static_cast<std::size_t>(m), 0)};
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

double capsule_gap(const ContactWire& wire, const Eigen::VectorXd& x, const Vec3& point) {
  const Nearest c = nearest_on_centreline(x, wire.first_node, wire.last_node, point);
  return (point - c.c).norm() - wire.radius;
}

Vec3 clamp_reaction(const ContactWire& wire, const CondensedWall& wall, const TetMesh& mesh,
                    const WireWallSolution& solution) {
  const Coupled coupled(wire, wall, mesh);
  VectorXd lambda(static_cast<Eigen::Index>(solution.active.size()));
  for (std::size_t k = 0; k < solution.active.size(); ++k) {
    lambda[static_cast<Eigen::Index>(k)] = solution.force[solution.active[k]];
  }
  const ActiveGeometry g = coupled.geometry(solution.active, solution.x, lambda);
  const VectorXd r =
      coupled.rod_residual(solution.active, solution.x, solution.rod_multipliers, lambda, g);
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
