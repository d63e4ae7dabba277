#include "msm/solvers/integrators.hpp"

#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "meshes/foundation/errors.hpp"
#include "msm/linalg/linear_solver.hpp"

namespace vessel::msm {

Integrator parse_integrator(const std::string& name) {
  if (name == "explicit-euler") return Integrator::explicit_euler;
  if (name == "symplectic-euler") return Integrator::symplectic_euler;
  if (name == "verlet") return Integrator::verlet;
  if (name == "implicit-euler") return Integrator::implicit_euler;
  throw InputError(
      "integrator: expected explicit-euler, symplectic-euler, verlet or "
      "implicit-euler; got '" +
      name + "'");
}

namespace {
/// "3.5e-07" rather than std::to_string's "0.000000": energies and residuals span many decades.
std::string sci(double v) {
  std::ostringstream s;
  s << std::setprecision(4) << v;
  return s.str();
}
}  // namespace

std::string to_string(Integrator i) {
  switch (i) {
    case Integrator::explicit_euler:
      return "explicit-euler";
    case Integrator::symplectic_euler:
      return "symplectic-euler";
    case Integrator::verlet:
      return "verlet";
    case Integrator::implicit_euler:
      return "implicit-euler";
  }
  return "unknown";
}

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Total force f = −∇E + f_damp + f_ext, zero on fixed dofs.
void total_force(const Problem& p, const VectorXd& x, const VectorXd& v, VectorXd& f,
                 VectorXd& scratch) {
  p.form->gradient(x, f);
  f = -f + p.external_force;
  p.form->damping_force(x, v, scratch);
  f += scratch;
  for (int i = 0; i < f.size(); ++i) {
    if (p.fixed[i]) f[i] = 0.0;
  }
}

using Vec3 = Eigen::Vector3d;

double bbox_diagonal(const VectorXd& x) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (Eigen::Index i = 0; i + 2 < x.size(); i += 3) {
    lo = lo.cwiseMin(x.segment<3>(i));
    hi = hi.cwiseMax(x.segment<3>(i));
  }
  return x.size() ? (hi - lo).norm() : 0.0;
}

/// Throws DivergenceError if x or v is not finite.
void check_finite(const Problem& p, int step, const VectorXd& x, const VectorXd& v) {
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(v[i])) {
      throw DivergenceError(step, static_cast<int>(i / 3), total_energy(p, x, v),
                            "non-finite position or velocity");
    }
  }
}

/// ½ vᵀ M v + Π(x) with the Form's energy E(x) already known (total_energy's expression).
double total_energy_given(const Problem& p, const VectorXd& x, const VectorXd& v,
                          double form_energy) {
  return 0.5 * v.dot(p.mass.cwiseProduct(v)) + (form_energy - p.external_force.dot(x - p.rest));
}

/// Throws DivergenceError if the total energy is not finite or beyond the limit.
void check_energy(const Problem& p, int step, const VectorXd& v, double limit, double energy) {
  if (!std::isfinite(energy) || energy > limit) {
    int worst = 0;
    double worst_ke = -1.0;
    for (Eigen::Index i = 0; i + 2 < v.size(); i += 3) {
      const double ke = p.mass[i] * v.segment<3>(i).squaredNorm();
      if (ke > worst_ke) {
        worst_ke = ke;
        worst = static_cast<int>(i / 3);
      }
    }
    throw DivergenceError(step, worst, energy,
                          "energy above the blow-up limit " + sci(limit) + " J");
  }
}

/// Throws DivergenceError if x or v is not finite or the energy is beyond the limit.
void check(const Problem& p, int step, const VectorXd& x, const VectorXd& v, double limit,
           double& energy) {
  check_finite(p, step, x, v);
  energy = total_energy(p, x, v);
  check_energy(p, step, v, limit, energy);
}

/// The explicit steps' total force from ∇E already known: f = −∇E + f_damp + f_ext, zero on fixed
/// dofs (total_force's arithmetic).
void explicit_force(const Problem& p, const VectorXd& grad, const VectorXd& x, const VectorXd& v,
                    VectorXd& f, VectorXd& scratch) {
  f = -grad + p.external_force;
  p.form->damping_force(x, v, scratch);
  f += scratch;
  for (int i = 0; i < f.size(); ++i) {
    if (p.fixed[i]) f[i] = 0.0;
  }
}

void hold_fixed_positions(const Problem& p, VectorXd& x) {
  for (int i = 0; i < x.size(); ++i) {
    if (p.fixed[i]) x[i] = p.rest[i];
  }
}

/// Implicit Euler's matrix A = M + h D + h² K with the fixed dofs' rows and columns replaced by
/// the identity (apply_dirichlet).
SparseMatrix implicit_euler_matrix(const Problem& p, double h, const SparseMatrix& K,
                                   const SparseMatrix& D) {
  SparseMatrix A = h * h * K + h * D;
  for (int i = 0; i < p.num_dofs(); ++i) A.coeffRef(i, i) += p.mass[i];
  apply_dirichlet(A, p.fixed);
  return A;
}

/// Baraff & Witkin (1998): (M + h D + h² K) Δv = h (f(x, v) − h K v); v += Δv; x += h v, with
/// `solver` holding the factorised left-hand side A and f the total force at (x, v). Solved for
/// v₁ = v + Δv directly: A v₁ = A v + h f − h² K v = (M + h D) v + h f, which needs no product
/// with K (7 M entries at level 2) and one with D only for a damped model. Same step; the two
/// forms differ by round-off.
void implicit_euler_update(const Problem& p, double h, const SparseMatrix& D, bool damped,
                           const CholmodSolver& solver, const VectorXd& f, VectorXd& x, VectorXd& v,
                           VectorXd& rhs, VectorXd& scratch) {
  rhs.noalias() = p.mass.cwiseProduct(v) + h * f;
  if (damped) {
    scratch.noalias() = D.transpose() * v;  // = D v (symmetric), walked as rows
    rhs.noalias() += h * scratch;
  }
  for (int i = 0; i < p.num_dofs(); ++i) {
    if (p.fixed[i]) rhs[i] = 0.0;
  }
  solver.solve_into(rhs, v);
  x += h * v;
}

/// Zero velocity and rest positions on the fixed dofs.
void hold_fixed_state(const Problem& p, VectorXd& x, VectorXd& v) {
  for (int i = 0; i < p.num_dofs(); ++i) {
    if (p.fixed[i]) {
      x[i] = p.rest[i];
      v[i] = 0.0;
    }
  }
}

/// Vectors every step reuses (no allocation per step).
struct StepBuffers {
  VectorXd f, scratch, rhs, dv;
  explicit StepBuffers(int n) : f(n), scratch(n), rhs(n), dv(n) {}
};

/// One step of an explicit integrator from (r.x, r.v), with ∇E there in `grad`. Verlet
/// evaluates E and ∇E at its new positions (into form_energy and grad) for its second half-kick.
void explicit_step(const Problem& p, Integrator integrator, double h, const VectorXd& inv_mass,
                   VectorXd& grad, double& form_energy, DynamicResult& r, StepBuffers& b) {
  switch (integrator) {
    case Integrator::explicit_euler: {
      // seed 000 eq. (3.7), both updates from the state at the start of the step.
      explicit_force(p, grad, r.x, r.v, b.f, b.scratch);
      r.x += h * r.v;
      r.v += h * inv_mass.cwiseProduct(b.f);
      break;
    }
    case Integrator::symplectic_euler: {
      explicit_force(p, grad, r.x, r.v, b.f, b.scratch);
      r.v += h * inv_mass.cwiseProduct(b.f);
      r.x += h * r.v;
      break;
    }
    case Integrator::verlet: {
      explicit_force(p, grad, r.x, r.v, b.f, b.scratch);
      const VectorXd v_half = r.v + 0.5 * h * inv_mass.cwiseProduct(b.f);
      r.x += h * v_half;
      hold_fixed_positions(p, r.x);  // (v_half is 0 there: x is unchanged, as before)
      form_energy = p.form->energy_gradient(r.x, grad);  // at the state checked below
      explicit_force(p, grad, r.x, v_half, b.f, b.scratch);
      r.v = v_half + 0.5 * h * inv_mass.cwiseProduct(b.f);
      break;
    }
    case Integrator::implicit_euler:
      break;  // implicit_step
  }
}

/// Implicit Euler's linear algebra, and what it keeps from one step to the next.
struct ImplicitState {
  CholmodSolver solver;
  PcgSolver pcg;
  SparseMatrix K, D;
  VectorXd dv_previous;  ///< PCG's warm start
  bool prefactored = false;     ///< implicit-euler-rest: A factorised once, at rest
  bool rest_iterative = false;  ///< implicit-euler-rest-pcg: A and its preconditioner at rest
  bool iterative = false;       ///< by PCG (at rest or at each step's state)
  bool damped = false;          ///< D (at rest, or at the step's state) is not zero

  ImplicitState(const DynamicOptions& o, int n) : dv_previous(VectorXd::Zero(n)) {
    const bool implicit = o.integrator == Integrator::implicit_euler;
    prefactored = implicit && o.implicit_matrix == ImplicitMatrix::rest_prefactored;
    rest_iterative = implicit && o.implicit_matrix == ImplicitMatrix::rest_pcg;
    iterative = rest_iterative || (implicit && o.implicit_matrix == ImplicitMatrix::current_pcg);
  }
};

/// Set-up of implicit-euler-rest(-pcg): K and D at rest, A factorised once for every step (or,
/// -pcg, A and its preconditioner built once). Returns its time, s (0 for the other methods).
double prepare_at_rest(const Problem& p, const DynamicOptions& o, ImplicitState& s) {
  if (!s.prefactored && !s.rest_iterative) return 0.0;
  const double t_setup = now();
  p.form->hessian(p.rest, s.K, o.project_psd);
  p.form->damping_jacobian(p.rest, s.D);
  s.damped = s.D.cwiseAbs().sum() > 0.0;
  if (s.prefactored) {
    s.solver.factorize(implicit_euler_matrix(p, o.dt, s.K, s.D));
  } else {
    s.pcg.compute(implicit_euler_matrix(p, o.dt, s.K, s.D), o.pcg);
  }
  return now() - t_setup;
}

/// The implicit Euler step A Δv = h (f − h K v) by PCG from the previous step's Δv (the
/// velocity change varies slowly from step to step); f, the total force at (x, v), in b.f.
void implicit_pcg_step(const Problem& p, const DynamicOptions& o, int step, ImplicitState& s,
                       DynamicResult& r, StepBuffers& b) {
  const double h = o.dt;
  const int n = p.num_dofs();
  if (!s.rest_iterative) {
    p.form->hessian(r.x, s.K, o.project_psd);
    p.form->damping_jacobian(r.x, s.D);
    s.pcg.compute(implicit_euler_matrix(p, h, s.K, s.D), o.pcg);
  }
  b.rhs.noalias() = s.K.transpose() * r.v;  // = K v (symmetric), walked as rows
  b.rhs = h * b.f - (h * h) * b.rhs;
  for (int i = 0; i < n; ++i) {
    if (p.fixed[i]) b.rhs[i] = 0.0;
  }
  b.dv = s.dv_previous;
  const PcgResult cg = s.pcg.solve(b.rhs, b.dv);
  if (!cg.converged) {
    throw std::runtime_error("implicit Euler (PCG): conjugate gradients stopped at step " +
                             std::to_string(step) + " after " + std::to_string(cg.iterations) +
                             " iterations with relative residual " + sci(cg.relative_residual) +
                             " (tolerance " + sci(o.pcg.tolerance) + ")");
  }
  r.linear_iterations += cg.iterations;
  r.max_linear_iterations = std::max(r.max_linear_iterations, cg.iterations);
  s.dv_previous = b.dv;
  r.v += b.dv;
  r.x += h * r.v;
}

/// One implicit Euler step from (r.x, r.v), with ∇E there in `grad`: by PCG, or by CHOLMOD with
/// A at rest (factorised once) or at this step's state (refactorised).
void implicit_step(const Problem& p, const DynamicOptions& o, int step, const VectorXd& grad,
                   ImplicitState& s, DynamicResult& r, StepBuffers& b) {
  const double h = o.dt;
  explicit_force(p, grad, r.x, r.v, b.f, b.scratch);  // the total force at (x, v)
  if (s.iterative) {
    implicit_pcg_step(p, o, step, s, r, b);
    return;
  }
  if (!s.prefactored) {  // K and D at this step's state, A refactorised
    p.form->hessian(r.x, s.K, o.project_psd);
    p.form->damping_jacobian(r.x, s.D);
    s.damped = s.D.cwiseAbs().sum() > 0.0;
    s.solver.factorize(implicit_euler_matrix(p, h, s.K, s.D));
  }
  implicit_euler_update(p, h, s.D, s.damped, s.solver, b.f, r.x, r.v, b.rhs, b.dv);
}

}  // namespace

double total_energy(const Problem& p, const VectorXd& x, const VectorXd& v) {
  return total_energy_given(p, x, v, p.form->energy(x));
}

DynamicResult integrate(const Problem& p, const DynamicOptions& o, const VectorXd& x0,
                        const VectorXd& v0) {
  if (!(o.dt > 0) || !std::isfinite(o.dt)) {
    throw InputError("dt: expected a finite time step > 0 s, got " + sci(o.dt));
  }
  if (o.steps < 0) throw InputError("steps: expected ≥ 0, got " + std::to_string(o.steps));
  const int n = p.num_dofs();
  DynamicResult r;
  r.x = x0.size() == n ? x0 : p.rest;
  r.v = v0.size() == n ? v0 : VectorXd::Zero(n);
  hold_fixed_state(p, r.x, r.v);
  const double h = o.dt;
  const double H0 = total_energy(p, r.x, r.v);
  const double scale = std::max(std::abs(H0), p.external_force.norm() * bbox_diagonal(p.rest));
  const double limit = std::abs(H0) + o.blowup_factor * std::max(scale, 1e-300);
  const VectorXd inv_mass = p.mass.cwiseInverse();
  StepBuffers buffers(n);
  ImplicitState implicit(o, n);
  r.setup_seconds = prepare_at_rest(p, o, implicit);
  const double t0 = now();
  double energy = H0;
  // Every integrator: ∇E at the state a step starts from comes from the previous step's
  // divergence check, which evaluates the energy and the gradient there in one pass
  // (Form::energy_gradient): one pass over the springs per step (Verlet: per force evaluation)
  // instead of a gradient plus a separate energy. Same numbers, same checks.
  VectorXd grad(n);
  double form_energy = 0.0;  // E at r.x, with grad, once a step has been checked
  if (o.steps > 0) p.form->gradient(r.x, grad);
  for (int step = 1; step <= o.steps; ++step) {
    if (o.integrator == Integrator::implicit_euler) {
      implicit_step(p, o, step, grad, implicit, r, buffers);
    } else {
      explicit_step(p, o.integrator, h, inv_mass, grad, form_energy, r, buffers);
    }
    hold_fixed_state(p, r.x, r.v);
    check_finite(p, step, r.x, r.v);
    // E and ∇E at the new state; ∇E is the next step's (Verlet evaluated both above).
    if (o.integrator != Integrator::verlet) form_energy = p.form->energy_gradient(r.x, grad);
    energy = total_energy_given(p, r.x, r.v, form_energy);
    check_energy(p, step, r.v, limit, energy);
    r.steps = step;
    if (o.on_step) o.on_step(step, r.x, r.v);
  }
  r.seconds = now() - t0;
  r.numeric_factorisations = implicit.solver.numeric_factorisations();
  r.factor_entries = implicit.solver.factor_entries();
  r.energy = energy;
  return r;
}

double max_frequency_bound(const Problem& p) {
  SparseMatrix K;
  p.form->hessian(p.rest, K, true);
  VectorXd row = VectorXd::Zero(K.rows());
  for (int k = 0; k < K.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(K, k); it; ++it) {
      if (!p.fixed[it.row()] && !p.fixed[it.col()]) row[it.row()] += std::abs(it.value());
    }
  }
  double w2 = 0.0;
  for (Eigen::Index i = 0; i < row.size(); ++i) {
    if (!p.fixed[i]) w2 = std::max(w2, row[i] / p.mass[i]);
  }
  return std::sqrt(w2);
}

RelaxationResult dynamic_relaxation(const Problem& p, const RelaxationOptions& o) {
  const double t0 = now();
  const int n = p.num_dofs();
  RelaxationResult r;
  r.dt = o.safety * 2.0 / max_frequency_bound(p);
  const double h = r.dt;
  const double target = o.tolerance * std::max(p.external_force.norm(), 1e-300);
  r.x = p.rest;
  VectorXd v = VectorXd::Zero(n), f(n), scratch(n), g(n);
  const VectorXd inv_mass = p.mass.cwiseInverse();
  const double limit = 1e3 * std::max(p.external_force.norm() * bbox_diagonal(p.rest), 1e-300);
  double energy = 0.0;
  double c = 0.0;  // mass-proportional damping coefficient, 1/s
  SparseMatrix K;
  for (r.steps = 1; r.steps <= o.max_steps; ++r.steps) {
    total_force(p, r.x, v, f, scratch);
    r.residual = f.norm();  // undamped model: f = −∇Π on free dofs (plus its damping, if any)
    if (r.residual <= target) break;
    if (r.steps % 20 == 1) {
      // Underwood (1983) adaptive damping: c = 2ω₀ with ω₀² the Rayleigh quotient
      // uᵀKu / uᵀMu of the current displacement u (K the stiffness, refreshed every 200 steps).
      if (r.steps % 200 == 1) {
        p.form->hessian(r.x, K, true);
        apply_dirichlet(K, p.fixed);
      }
      const VectorXd u = r.x - p.rest;
      const double uMu = u.dot(p.mass.cwiseProduct(u));
      if (uMu > 0) c = 2.0 * std::sqrt(std::max(u.dot(K * u) / uMu, 0.0));
    }
    // Damped leapfrog: v_{n+½} = ((1 − ch/2) v_{n−½} + h M⁻¹ f) / (1 + ch/2).
    v = ((1.0 - 0.5 * c * h) * v + h * inv_mass.cwiseProduct(f)) / (1.0 + 0.5 * c * h);
    r.x += h * v;
    if (r.steps % 64 == 0) check(p, r.steps, r.x, v, limit, energy);
  }
  r.seconds = now() - t0;
  p.potential_gradient(r.x, g);
  r.residual = g.norm();
  if (!(r.residual <= target)) {
    throw std::runtime_error("dynamic relaxation did not reach the residual tolerance in " +
                             std::to_string(o.max_steps) + " steps (residual " +
                             std::to_string(r.residual) + " N)");
  }
  return r;
}

}  // namespace vessel::msm
