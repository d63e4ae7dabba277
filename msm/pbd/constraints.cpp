#include "msm/pbd/constraints.hpp"

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>

#include "meshes/foundation/errors.hpp"
#include "msm/form/divergence_error.hpp"

namespace vessel::msm {

namespace {
inline Vec3 node(const VectorXd& x, int i) { return x.segment<3>(3 * i); }

double dihedral_angle(const Vec3& pi, const Vec3& pj, const Vec3& pk, const Vec3& pn) {
  const Vec3 n1 = (pj - pi).cross(pk - pi);
  const Vec3 n2 = (pj - pi).cross(pn - pi);
  const double d = std::clamp(n1.dot(n2) / (n1.norm() * n2.norm()), -1.0, 1.0);
  return std::acos(d);  // seed 002: C_dih + φ0' = acos(n1·n2/(|n1||n2|))
}

double force_angle(const Vec3& pi, const Vec3& pj, const Vec3& f) {
  const Vec3 d = pi - pj;
  const double c = std::clamp(d.dot(f) / (d.norm() * f.norm()), -1.0, 1.0);
  return std::acos(c);
}
}  // namespace

ConstraintValue evaluate(const Constraint& c, const VectorXd& x) {
  ConstraintValue v;
  switch (c.type) {
    case ConstraintType::stretch: {
      // seed 002: C_len(p) = |p_i − p_j| − |p_i⁰ − p_j⁰|.
      const Vec3 d = node(x, c.nodes[0]) - node(x, c.nodes[1]);
      const double L = d.norm();
      v.count = 2;
      v.C = L - c.rest;
      if (L <= 0) {
        v.valid = false;
        return v;
      }
      v.grad[0] = d / L;
      v.grad[1] = -d / L;
      return v;
    }
    case ConstraintType::dihedral: {
      // seed 002 C_dih, gradient of Müller et al. (2007, PBD, appendix A) with p_i at the origin:
      // p2 = p_j − p_i, p3 = p_k − p_i, p4 = p_n − p_i, n1 = p2×p3/|p2×p3|, n2 = p2×p4/|p2×p4|,
      // d = n1·n2, q3 = (p2×n2 + (n1×p2)d)/|p2×p3|, q4 = (p2×n1 + (n2×p2)d)/|p2×p4|,
      // q2 = −(p3×n2 + (n1×p3)d)/|p2×p3| − (p4×n1 + (n2×p4)d)/|p2×p4|, q1 = −q2 − q3 − q4;
      // these q are −∂d/∂p (checked against finite differences), so ∇C = q/√(1 − d²).
      const Vec3 pi = node(x, c.nodes[0]);
      const Vec3 p2 = node(x, c.nodes[1]) - pi;
      const Vec3 p3 = node(x, c.nodes[2]) - pi;
      const Vec3 p4 = node(x, c.nodes[3]) - pi;
      v.count = 4;
      const Vec3 c23 = p2.cross(p3);
      const Vec3 c24 = p2.cross(p4);
      const double l23 = c23.norm(), l24 = c24.norm();
      if (l23 <= 0 || l24 <= 0) {
        v.valid = false;
        return v;
      }
      const Vec3 n1 = c23 / l23, n2 = c24 / l24;
      const double d = std::clamp(n1.dot(n2), -1.0, 1.0);
      v.C = std::acos(d) - c.rest;
      const double s = std::sqrt(std::max(1.0 - d * d, 0.0));
      if (s < 1e-9) {  // flat (or folded) pair: the acos gradient is undefined
        v.valid = false;
        return v;
      }
      const Vec3 q3 = (p2.cross(n2) + n1.cross(p2) * d) / l23;
      const Vec3 q4 = (p2.cross(n1) + n2.cross(p2) * d) / l24;
      const Vec3 q2 =
          -(p3.cross(n2) + n1.cross(p3) * d) / l23 - (p4.cross(n1) + n2.cross(p4) * d) / l24;
      const Vec3 q1 = -q2 - q3 - q4;
      v.grad = {q1 / s, q2 / s, q3 / s, q4 / s};
      return v;
    }
    case ConstraintType::angle: {
      // seed 002 C_angle = acos(b/a) − φ0, a = |d||f|, b = d·f, d = p_i1 − p_j1;
      // ∇_{i1} C = −(|d|² f − b d)/(|d|² √(a² − b²)) = −∇_{j1} C.
      const Vec3 d = node(x, c.nodes[0]) - node(x, c.nodes[1]);
      const Vec3& f = c.direction;
      const double a = d.norm() * f.norm();
      const double b = d.dot(f);
      v.count = 2;
      v.C = std::acos(std::clamp(b / a, -1.0, 1.0)) - c.rest;
      const double root = std::sqrt(std::max(a * a - b * b, 0.0));
      if (a <= 0 || root <= 1e-12 * a) {
        v.valid = false;
        return v;
      }
      const Vec3 g = -(d.squaredNorm() * f - b * d) / (d.squaredNorm() * root);
      v.grad[0] = g;
      v.grad[1] = -g;
      return v;
    }
  }
  return v;
}

Vec3 seed002_stretch_correction(const Vec3& pi, const Vec3& pj, double rest_length) {
  const Vec3 d = pi - pj;
  return -(d.norm() - rest_length) / 2.0 * d / d.norm();
}

Vec3 seed002_angle_correction(const Vec3& pi, const Vec3& pj, const Vec3& f, double rest_angle) {
  const Vec3 d = pi - pj;
  const double a = d.norm() * f.norm();
  const double b = d.dot(f);
  return (std::acos(b / a) - rest_angle) / (2.0 * std::sqrt(a * a - b * b)) *
         (d.squaredNorm() * f - b * d);
}

std::vector<Constraint> build_pbd_constraints(const SpringNetwork& net,
                                              const std::vector<Vec3>& loads,
                                              const PbdConstraintOptions& o) {
  std::vector<Constraint> out;
  const VectorXd x0 = [&] {
    VectorXd x(3 * static_cast<Eigen::Index>(net.nodes.size()));
    for (std::size_t i = 0; i < net.nodes.size(); ++i)
      x.segment<3>(3 * static_cast<Eigen::Index>(i)) = net.nodes[i];
    return x;
  }();
  if (o.stretch) {
    for (const Spring& s : net.springs) {
      if (s.family != SpringFamily::structural && s.family != SpringFamily::volume) continue;
      Constraint c;
      c.type = ConstraintType::stretch;
      c.nodes = {s.a, s.b, 0, 0};
      c.rest = s.rest_length;
      c.compliance = s.law.k1 > 0 ? 1.0 / s.law.k1 : 0.0;
      out.push_back(c);
    }
  }
  if (o.dihedral) {
    using Edge = std::pair<int, int>;
    std::map<Edge, std::vector<int>> opposite;
    for (const Triangle& t : net.triangles) {
      for (int k = 0; k < 3; ++k) {
        const int a = t[k], b = t[(k + 1) % 3];
        opposite[a < b ? Edge{a, b} : Edge{b, a}].push_back(t[(k + 2) % 3]);
      }
    }
    for (const auto& [e, opp] : opposite) {
      if (opp.size() != 2) continue;
      Constraint c;
      c.type = ConstraintType::dihedral;
      c.nodes = {e.first, e.second, opp[0], opp[1]};
      c.rest = dihedral_angle(net.nodes[e.first], net.nodes[e.second], net.nodes[opp[0]],
                              net.nodes[opp[1]]);
      c.compliance = o.bending_compliance;
      out.push_back(c);
    }
  }
  if (o.angle) {
    for (const Spring& s : net.springs) {
      if (s.family != SpringFamily::structural) continue;
      for (int end = 0; end < 2; ++end) {
        const int i = end == 0 ? s.a : s.b;
        const int j = end == 0 ? s.b : s.a;
        if (i >= static_cast<int>(loads.size()) || loads[i].squaredNorm() == 0.0) continue;
        Constraint c;
        c.type = ConstraintType::angle;
        c.nodes = {i, j, 0, 0};
        c.direction = loads[i];
        c.rest = force_angle(net.nodes[i], net.nodes[j], loads[i]);
        c.compliance = o.angle_compliance;
        if (evaluate(c, x0).valid) out.push_back(c);
      }
    }
  }
  return out;
}

PbdResult run_pbd(const Problem& p, const std::vector<Constraint>& constraints, const PbdOptions& o,
                  const VectorXd& x0) {
  if (!(o.dt > 0) || !std::isfinite(o.dt)) {
    throw InputError("dt: expected a finite time step > 0 s, got " + std::to_string(o.dt));
  }
  if (o.iterations < 1) {
    throw InputError("iterations: expected ≥ 1, got " + std::to_string(o.iterations));
  }
  if (!(o.velocity_damping >= 0 && o.velocity_damping < 1)) {
    throw InputError("velocity_damping: expected a value in [0, 1), got " +
                     std::to_string(o.velocity_damping));
  }
  const auto t0 = std::chrono::steady_clock::now();
  const int n = p.num_dofs();
  const double h = o.dt;
  VectorXd w(n);  // inverse mass per dof
  for (int i = 0; i < n; ++i) w[i] = p.fixed[i] ? 0.0 : 1.0 / p.mass[i];
  PbdResult r;
  r.x = x0.size() == n ? x0 : p.rest;
  r.v = VectorXd::Zero(n);
  std::vector<double> lambda(constraints.size());
  double extent = 0.0;
  for (Eigen::Index i = 0; i < 3; ++i) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (Eigen::Index k = i; k < n; k += 3) {
      lo = std::min(lo, p.rest[k]);
      hi = std::max(hi, p.rest[k]);
    }
    if (n > 0) extent += (hi - lo) * (hi - lo);
  }
  double ke_limit = o.blowup_factor * std::max({p.external_force.norm() * std::sqrt(extent),
                                                0.5 * r.v.dot(p.mass.cwiseProduct(r.v)), 1e-300});
  for (int step = 1; step <= o.steps; ++step) {
    VectorXd xp = r.x + h * r.v + h * h * w.cwiseProduct(p.external_force);
    std::fill(lambda.begin(), lambda.end(), 0.0);
    for (int it = 0; it < o.iterations; ++it) {
      for (std::size_t ci = 0; ci < constraints.size(); ++ci) {
        const Constraint& c = constraints[ci];
        const ConstraintValue cv = evaluate(c, xp);
        if (!cv.valid) continue;
        double denom = 0.0;
        for (int k = 0; k < cv.count; ++k) {
          denom += cv.grad[k].dot(w.segment<3>(3 * c.nodes[k]).cwiseProduct(cv.grad[k]));
        }
        const double alpha = c.compliance / (h * h);  // XPBD α̃ = α/h²
        if (denom + alpha <= 0) continue;
        const double dl = (-cv.C - alpha * lambda[ci]) / (denom + alpha);
        lambda[ci] += dl;
        for (int k = 0; k < cv.count; ++k) {
          xp.segment<3>(3 * c.nodes[k]) +=
              dl * w.segment<3>(3 * c.nodes[k]).cwiseProduct(cv.grad[k]);
        }
      }
    }
    r.v = (1.0 - o.velocity_damping) * (xp - r.x) / h;
    r.x = xp;
    for (int i = 0; i < n; ++i) {
      if (!std::isfinite(r.x[i]) || !std::isfinite(r.v[i])) {
        throw DivergenceError(step, i / 3, std::numeric_limits<double>::quiet_NaN(),
                              "non-finite PBD position or velocity");
      }
    }
    // Energy blow-up: the kinetic energy beyond what the loads could ever supply.
    const double kinetic = 0.5 * r.v.dot(p.mass.cwiseProduct(r.v));
    // The first step may release the energy of initially violated constraints: it sets the scale.
    if (step == 1) ke_limit = std::max(ke_limit, o.blowup_factor * kinetic);
    if (kinetic > ke_limit) {
      Eigen::Index worst = 0;
      r.v.cwiseAbs().maxCoeff(&worst);
      throw DivergenceError(
          step, static_cast<int>(worst / 3), kinetic,
          "PBD kinetic energy above the blow-up limit " + std::to_string(ke_limit) + " J");
    }
    r.steps = step;
    if (o.on_step) o.on_step(step, r.x);
  }
  for (const Constraint& c : constraints) {
    if (c.type == ConstraintType::stretch)
      r.max_violation = std::max(r.max_violation, std::abs(evaluate(c, r.x).C));
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace vessel::msm
