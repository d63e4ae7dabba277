#include "msm/solvers/static_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

#include "meshes/foundation/errors.hpp"
#include "msm/linalg/linear_solver.hpp"
#include "msm/solvers/exact_backoff.hpp"
#include "msm/solvers/steihaug.hpp"

namespace vessel::msm {

namespace {
double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

namespace {

/// Deterministic start vector for the power iteration (zero on fixed dofs).
VectorXd start_vector(const std::vector<char>& fixed) {
  std::mt19937_64 rng(20241121);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VectorXd v(static_cast<Eigen::Index>(fixed.size()));
  for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = fixed[i] ? 0.0 : u(rng);
  return v / v.norm();
}

/// A direction of negative curvature of the exact Hessian H, found by power iteration on
/// Hp⁻¹(Hp − H) with the factorisation of the projected Hessian Hp ⪰ H already in `solver`: its
/// eigenvalues are 1 − λ for the generalised eigenproblem H v = λ Hp v, so the dominant one belongs
/// to the most negative λ. Warm-started from `v` (kept between Newton iterations). Returns vᵀHv
/// (N/m per m², negative if a direction was found), v normalised to unit length.
double negative_curvature(const SparseMatrix& H, const SparseMatrix& Hp,
                          const CholmodSolver& solver, int iterations, VectorXd& v) {
  const SparseMatrix N = Hp - H;  // ⪰ 0: the clamped negative parts of the spring blocks
  for (int k = 0; k < iterations; ++k) {
    VectorXd y = solver.solve(N * v);
    const double n = y.norm();
    if (!(n > 0) || !std::isfinite(n)) return 0.0;
    v = y / n;
  }
  const double c = v.dot(H * v);
  const double cp = v.dot(Hp * v);
  return c < -1e-8 * std::abs(cp) ? c : 0.0;
}

/// Steihaug–Toint CG (msm/solvers/steihaug.hpp) on the exact Hessian H with the factorised
/// PSD-projected Hessian P as preconditioner and norm (‖v‖²_P = vᵀ(Pm)v, Pm the matrix whose
/// factorisation `solver` holds, up to its regularisation). P ⪰ H differs from H only on the
/// springs whose block was projected, so P⁻¹H is the identity plus a perturbation of low rank and
/// CG needs few iterations.
SteihaugStep steihaug_step(const SparseMatrix& H, const SparseMatrix& Pm,
                           const CholmodSolver& solver, const VectorXd& g, double radius,
                           double forcing, int max_iterations) {
  return steihaug_cg([&](const VectorXd& v, VectorXd& out) { out.noalias() = H * v; },
                     [&](const VectorXd& v, VectorXd& out) { out.noalias() = Pm * v; },
                     [&](const VectorXd& r, VectorXd& out) { out = solver.solve(r); }, g, radius,
                     forcing, max_iterations);
}

/// The first iterate: `start` if it has the model's size, else the rest shape; fixed dofs at rest.
VectorXd initial_point(const Problem& p, const VectorXd& start) {
  VectorXd x = start.size() == p.num_dofs() ? start : p.rest;
  for (int i = 0; i < p.num_dofs(); ++i) {
    if (p.fixed[i]) x[i] = p.rest[i];
  }
  return x;
}

/// The clock and the solver's counters at the start of a solve, so that a result reports only
/// the work of its own solve (the caller's solver may have factorised before).
struct SolveClock {
  double t0;
  int analyses0;
  int factorisations0;
  double factorisation_seconds0;

  explicit SolveClock(const CholmodSolver& solver)
      : t0(now()),
        analyses0(solver.symbolic_analyses()),
        factorisations0(solver.numeric_factorisations()),
        factorisation_seconds0(solver.factorisation_seconds()) {}

  void record(const CholmodSolver& solver, StaticResult& r) const {
    r.symbolic_analyses = solver.symbolic_analyses() - analyses0;
    r.numeric_factorisations = solver.numeric_factorisations() - factorisations0;
    r.factorisation_seconds = solver.factorisation_seconds() - factorisation_seconds0;
    r.seconds = now() - t0;
  }
};

/// Round-off floor of the residual: ε·(largest stiffness)·(model size)·√n, from the first
/// Hessian; below it the residual cannot be reduced, whatever the load.
double roundoff_floor(const Problem& p, const SparseMatrix& H) {
  const double size = (p.rest.maxCoeff() - p.rest.minCoeff());
  return std::numeric_limits<double>::epsilon() * H.diagonal().cwiseAbs().maxCoeff() * size *
         std::sqrt(static_cast<double>(p.num_dofs()));
}

/// Round-off of Π itself, J: a spring's energy carries its tension times the round-off of its
/// length, ε·L, and the tensions balance the load, so Π is uncertain by about ε·(model size)·
/// (load) — with a margin of 1e3 for the many springs that carry it. At small loads this is far
/// above 1e-12·|Π| (Π falls with the load squared, its round-off only with the load), and an
/// energy comparison cannot judge a step near the solution.
double energy_roundoff(const Problem& p, const VectorXd& g) {
  const double size = (p.rest.maxCoeff() - p.rest.minCoeff());
  return 1e3 * std::numeric_limits<double>::epsilon() * size *
         (p.external_force.lpNorm<1>() + g.lpNorm<1>());
}

/// Throws the solver's "did not converge" error naming the iteration, residual and target.
[[noreturn]] void throw_not_converged(const char* solver_name, const StaticResult& r,
                                      double target) {
  std::ostringstream msg;
  msg << solver_name << " did not converge: iteration " << r.iterations << ", residual "
      << r.residual << " N (target " << target << " N)";
  throw std::runtime_error(msg.str());
}

/// Widens the trust region's norm P by the regularisation CHOLMOD needed (and at least 1e-8 of
/// its diagonal), so that a direction P has no stiffness in (a membrane at rest, a compressed
/// pair at its saddle) still has a length.
void widen_trust_norm(const Problem& p, const CholmodSolver& solver, SparseMatrix& P) {
  const VectorXd diag = P.diagonal();
  const double floor = 1e-3 * diag.cwiseAbs().mean() + 1e-300;
  const double sigma = std::max(solver.last_regularisation(), 1e-8);
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    if (!p.fixed[i]) P.coeffRef(i, i) += sigma * std::max(diag[i], floor);
  }
}

/// Δ₀: the P-norm of the first projected Newton step, shortened to move no node by more than
/// 1 % of the model's size (its P-norm is meaningless where P is nearly singular).
double initial_radius(const Problem& p, const CholmodSolver& solver, const SparseMatrix& P,
                      const VectorXd& g) {
  VectorXd d0 = solver.solve(g);
  const double size = p.rest.maxCoeff() - p.rest.minCoeff();
  const double largest = d0.cwiseAbs().maxCoeff();
  if (largest > 1e-2 * size) d0 *= 1e-2 * size / largest;
  return std::sqrt(std::max(d0.dot(P * d0), 0.0));
}

/// The outcome of one trust-region iteration's trial steps.
struct TrustRegionStep {
  SteihaugStep step;  ///< the last CG step tried
  double rho = 0.0;   ///< its actual over predicted decrease
  bool accepted = false;
};

/// Trial steps at the current point, Δ shrinking after each rejected one: a rejected step
/// re-runs CG with the same H and P (no new factorisation). On acceptance moves r.x and
/// `energy` to the trial point.
TrustRegionStep trust_region_trials(const Problem& p, const SparseMatrix& H, const SparseMatrix& P,
                                    const CholmodSolver& solver, const VectorXd& g,
                                    double forcing, double& radius, double& energy,
                                    StaticResult& r) {
  TrustRegionStep t;
  VectorXd gt, Hd, trial;
  for (int attempt = 0; attempt < 60 && !t.accepted; ++attempt) {
    t.step = steihaug_step(H, P, solver, g, radius, forcing, 200);
    const SteihaugStep& step = t.step;
    Hd.noalias() = H * step.d;
    const double predicted = -(g.dot(step.d) + 0.5 * step.d.dot(Hd));
    trial = r.x + step.d;
    const double trial_energy = p.potential(trial);
    if (!std::isfinite(trial_energy) || !(predicted > 0.0)) {
      t.rho = -1.0;
    } else if (predicted <= 1e-11 * std::abs(energy)) {
      // The decrease is at the energy's round-off (its terms cancel to ~1e-13 of |Π|): judge
      // the step by the residual instead, as the line search does.
      p.potential_gradient(trial, gt);
      t.rho = gt.norm() < r.residual ? 1.0 : -1.0;
    } else {
      t.rho = (energy - trial_energy) / predicted;
    }
    const double length = std::sqrt(std::max(step.d.dot(P * step.d), 0.0));
    if (t.rho < 0.25) {
      radius = 0.25 * std::min(radius, length);
    } else if (t.rho > 0.75 && step.boundary) {
      radius *= 2.0;
    }
    if (t.rho > 1e-4) {
      t.accepted = true;
      r.x.swap(trial);
      energy = trial_energy;
      if (step.negative_curvature) ++r.negative_curvature_steps;
    } else {
      ++r.rejected_steps;
    }
    if (!(radius > 0.0)) break;
  }
  return t;
}

/// Trust-region Newton with Steihaug–Toint CG steps (Nocedal & Wright 2006, Algorithms 4.1 and
/// 7.2). Each iteration: the exact Hessian H and the PSD-projected Hessian P at x, P factorised
/// (CHOLMOD, regularised if singular); the step minimises the quadratic model with the exact H
/// within ‖d‖_P ≤ Δ; accepted if Π falls by at least 1e-4 of the model's predicted decrease;
/// Δ ×1/4 after a poor step (ratio < 1/4), ×2 after a good one that reached the boundary
/// (ratio > 3/4). Δ starts at the P-norm of the first projected Newton step. The CG forcing term
/// min(1/2, √(‖g‖/‖g₀‖)) gives superlinear convergence once the steps are interior
/// (Eisenstat & Walker 1996; Nocedal & Wright §7.1).
StaticResult trust_region_newton(const Problem& p, const StaticOptions& o, const VectorXd& start,
                                 CholmodSolver& solver) {
  const SolveClock clock(solver);
  StaticResult r;
  r.x = initial_point(p, start);
  const double target = o.tolerance * std::max(p.external_force.norm(), o.force_scale);
  VectorXd g;
  SparseMatrix H, P;
  double energy = p.potential(r.x);
  double roundoff = 0.0, radius = 0.0, first_residual = 0.0;
  for (r.iterations = 0; r.iterations <= o.max_iterations; ++r.iterations) {
    p.potential_gradient(r.x, g);
    r.residual = g.norm();
    if (!std::isfinite(r.residual)) break;
    if (first_residual == 0.0) first_residual = r.residual;
    if (r.residual <= std::max(target, roundoff)) {
      r.converged = true;
      break;
    }
    if (r.iterations == o.max_iterations) break;
    const double ta = now();
    p.form->hessian(r.x, H, false);
    apply_dirichlet(H, p.fixed);
    p.form->hessian(r.x, P, true);
    apply_dirichlet(P, p.fixed);
    r.assembly_seconds += now() - ta;
    if (roundoff == 0.0) roundoff = roundoff_floor(p, H);
    solver.factorize(P);
    widen_trust_norm(p, solver, P);
    if (radius == 0.0) radius = initial_radius(p, solver, P, g);
    const double forcing = std::min(0.5, std::sqrt(r.residual / first_residual));
    const TrustRegionStep t = trust_region_trials(p, H, P, solver, g, forcing, radius, energy, r);
    const SteihaugStep& step = t.step;
    if (step.boundary) ++r.boundary_steps;
    if (step.negative_curvature) ++r.indefinite_iterations;
    if (o.log) {
      *o.log << "  trust region " << r.iterations << ": residual " << r.residual << " N, ratio "
             << t.rho << ", " << step.iterations << " CG iterations"
             << (step.negative_curvature ? ", negative curvature"
                 : step.boundary         ? ", boundary"
                                         : "")
             << ", next radius " << radius << ", energy " << energy << " J\n";
    }
    if (!t.accepted) break;
  }
  clock.record(solver, r);
  if (!r.converged) throw_not_converged("static Newton (trust region)", r, target);
  return r;
}

/// What line-search Newton carries from one iteration to the next.
struct NewtonState {
  SparseMatrix H, Hp;            ///< exact and projected Hessians at the current point
  VectorXd curvature_direction;  ///< the power iteration's warm start
  double roundoff = 0.0;         ///< see roundoff_floor; 0 until the first Hessian
  ExactBackoff backoff;          ///< StaticOptions::exact_backoff

  explicit NewtonState(const StaticOptions& o) : backoff(o.exact_backoff) {}
};

/// Factorises the Newton matrix at r.x: the exact Hessian where it is positive definite
/// (quadratic convergence); where compression makes it indefinite, the per-spring PSD
/// projection (then regularised if still singular). Returns whether it was the exact one.
bool factorise_newton_matrix(const Problem& p, const StaticOptions& o, CholmodSolver& solver,
                             NewtonState& s, StaticResult& r) {
  double ta = now();
  p.form->hessian(r.x, s.H, false);
  r.assembly_seconds += now() - ta;
  if (s.roundoff == 0.0) s.roundoff = roundoff_floor(p, s.H);
  apply_dirichlet(s.H, p.fixed);
  const bool try_exact = s.backoff.try_exact();
  const bool exact = try_exact && solver.try_factorize(s.H);
  if (try_exact) s.backoff.record(exact);
  if (!exact) {
    ++r.indefinite_iterations;
    ta = now();
    p.form->hessian(r.x, s.Hp, o.project_psd);
    apply_dirichlet(s.Hp, p.fixed);
    r.assembly_seconds += now() - ta;
    solver.factorize(s.Hp);
  }
  return exact;
}

/// What the search for negative curvature found: vᵀHv (negative if found) and the blend τ.
struct CurvatureShift {
  double curvature = 0.0;
  double tau = 1.0;
};

/// A direction of negative curvature of the exact Hessian, searched where it is indefinite.
/// The projected Newton step alone cannot see it: near a saddle or buckling point (a membrane
/// wrinkling under the contact load) it then creeps away at a linear rate, tens of iterations
/// (measured: 50 at structured level 0). Moving along it lowers Π to second order. If found,
/// the Newton step `dx` is recomputed with a blend of the exact and projected Hessians.
CurvatureShift shift_for_negative_curvature(const Problem& p, const StaticOptions& o,
                                            CholmodSolver& solver, const VectorXd& g,
                                            NewtonState& s, StaticResult& r, VectorXd& dx) {
  CurvatureShift c;
  if (s.curvature_direction.size() != g.size()) s.curvature_direction = start_vector(p.fixed);
  const double tc = now();
  c.curvature = negative_curvature(s.H, s.Hp, solver, o.curvature_iterations,
                                   s.curvature_direction);
  r.curvature_seconds += now() - tc;
  if (c.curvature < 0.0 && o.curvature_shift < 1.0) {
    // The blend (1 − τ)H + τHp has the eigenvalues (1 − τ)λ + τ (relative to Hp): τ = (δ − λ)/(1
    // − λ) lifts the most negative λ found to δ. A Hessian modification in the spirit of Nocedal
    // & Wright (2006) §3.4, but only on the springs the projection changed. It keeps most of
    // the exact Hessian, so the step is long along soft (buckling) modes; if λ was not the most
    // negative eigenvalue the factorisation fails and the projected step is kept.
    const VectorXd& v = s.curvature_direction;
    const double lambda = c.curvature / v.dot(s.Hp * v);
    const double delta = std::max(o.curvature_shift, 0.0);
    c.tau = std::min(1.0, (delta - lambda) / (1.0 - lambda));
    SparseMatrix Ht = (1.0 - c.tau) * s.H + c.tau * s.Hp;
    if (solver.try_factorize(Ht)) {
      dx = -solver.solve(g);
    } else {
      c.tau = 1.0;
    }
  }
  return c;
}

/// The outcome of the line search along a Newton step.
struct LineSearch {
  VectorXd trial;
  double trial_energy = 0.0;
  double alpha = 1.0;
  bool accepted = false;
};

/// Backtracking (Armijo) line search on Π from x along dx. Near the solution the energy change
/// drops below round-off (|ΔΠ| ≲ 1e-12 |Π| or energy_roundoff): there a step is accepted if it
/// reduces the residual instead.
LineSearch armijo_search(const Problem& p, const VectorXd& x, const VectorXd& dx,
                         const VectorXd& g, double energy, double residual) {
  const double slope = g.dot(dx);
  const double noise = std::max(1e-12 * std::abs(energy), energy_roundoff(p, g));
  LineSearch l;
  VectorXd gt;
  l.trial_energy = energy;
  for (int ls = 0; ls < 40; ++ls) {
    l.trial = x + l.alpha * dx;
    l.trial_energy = p.potential(l.trial);
    if (!std::isfinite(l.trial_energy)) {
      l.alpha *= 0.5;
      continue;
    }
    if (l.trial_energy <= energy + 1e-4 * l.alpha * slope) {
      l.accepted = true;
      break;
    }
    if (std::abs(l.trial_energy - energy) <= noise) {
      p.potential_gradient(l.trial, gt);
      if (gt.norm() < residual) {
        l.accepted = true;
        break;
      }
    }
    l.alpha *= 0.5;
  }
  return l;
}

/// A step β along the negative-curvature direction v from r.x (0 if none lowers Π); moves r.x
/// and `energy` there. Searches ±v (sign: downhill at r.x) with expansion: Π(x + βv) falls as
/// ½β²vᵀHv until higher-order terms stop it. Starts at the Newton step's size (at least 1e-3 of
/// the displacement so far), grows ×4 while Π keeps falling.
double step_along_curvature(const Problem& p, const LineSearch& l, const VectorXd& dx,
                            NewtonState& s, double& energy, StaticResult& r) {
  VectorXd& v = s.curvature_direction;
  VectorXd gt;
  p.potential_gradient(r.x, gt);
  const double sign = gt.dot(v) > 0.0 ? -1.0 : 1.0;
  double b = std::max({l.accepted ? l.alpha * dx.cwiseAbs().maxCoeff() : 0.0,
                       1e-3 * (r.x - p.rest).cwiseAbs().maxCoeff(),
                       1e-9 * (p.rest.maxCoeff() - p.rest.minCoeff())}) /
             v.cwiseAbs().maxCoeff();
  double best = energy;
  double beta = 0.0;
  for (int k = 0; k < 16; ++k, b *= 4.0) {
    const double e = p.potential(r.x + sign * b * v);
    if (!(e < best)) break;
    best = e;
    beta = sign * b;
  }
  if (beta != 0.0) {
    r.x += beta * v;
    energy = best;
    ++r.negative_curvature_steps;
  }
  return beta;
}

StaticResult newton(const Problem& p, const StaticOptions& o, const VectorXd& start,
                    CholmodSolver& solver) {
  if (o.globalisation == StaticGlobalisation::trust_region) {
    return trust_region_newton(p, o, start, solver);
  }
  const SolveClock clock(solver);
  StaticResult r;
  r.x = initial_point(p, start);
  const double target = o.tolerance * std::max(p.external_force.norm(), o.force_scale);
  VectorXd g;
  NewtonState s(o);
  double energy = p.potential(r.x);
  for (r.iterations = 0; r.iterations <= o.max_iterations; ++r.iterations) {
    p.potential_gradient(r.x, g);
    r.residual = g.norm();
    if (!std::isfinite(r.residual)) break;
    if (r.residual <= std::max(target, s.roundoff)) {
      r.converged = true;
      break;
    }
    if (r.iterations == o.max_iterations) break;
    const bool exact = factorise_newton_matrix(p, o, solver, s, r);
    VectorXd dx = -solver.solve(g);
    CurvatureShift c;
    if (!exact && o.curvature_iterations > 0) {
      c = shift_for_negative_curvature(p, o, solver, g, s, r, dx);
    }
    LineSearch l = armijo_search(p, r.x, dx, g, energy, r.residual);
    if (!l.accepted && c.curvature >= 0.0) break;
    if (l.accepted) {
      r.x = l.trial;
      energy = l.trial_energy;
    }
    double beta = 0.0;
    if (c.curvature < 0.0) {
      beta = step_along_curvature(p, l, dx, s, energy, r);
      if (beta == 0.0 && !l.accepted) break;
    }
    if (o.log) {
      *o.log << "  newton " << r.iterations << ": residual " << r.residual << " N, step " << l.alpha
             << (exact ? ", exact Hessian" : ", projected Hessian") << ", regularisation "
             << solver.last_regularisation();
      if (c.tau < 1.0) *o.log << ", tau " << c.tau;
      if (c.curvature < 0.0) {
        *o.log << ", curvature " << c.curvature << " N/m, step " << beta << " m";
      }
      *o.log << ", energy " << energy << " J\n";
    }
  }
  clock.record(solver, r);
  if (!r.converged) throw_not_converged("static Newton", r, target);
  return r;
}

}  // namespace

StaticGlobalisation parse_static_globalisation(const std::string& name) {
  if (name == "line-search") return StaticGlobalisation::line_search;
  if (name == "trust-region") return StaticGlobalisation::trust_region;
  throw InputError("static globalisation: expected line-search or trust-region, got '" + name +
                   "'");
}

std::string to_string(StaticGlobalisation g) {
  return g == StaticGlobalisation::trust_region ? "trust-region" : "line-search";
}

StaticResult solve_static(const Problem& p, const StaticOptions& o, const VectorXd& start) {
  CholmodSolver solver;
  return solve_static(p, o, start, solver);
}

StaticResult solve_static(const Problem& p, const StaticOptions& o, const VectorXd& start,
                          CholmodSolver& solver) {
  if (o.load_steps <= 1) return newton(p, o, start, solver);
  // Load stepping: Newton on f_ext·s/N for s = 1..N, each from the previous equilibrium.
  const double t0 = now();
  Problem step = p;
  StaticResult total;
  total.x = start;
  for (int s = 1; s <= o.load_steps; ++s) {
    step.external_force = p.external_force * (static_cast<double>(s) / o.load_steps);
    const StaticResult r = newton(step, o, total.x, solver);
    total.x = r.x;
    total.iterations += r.iterations;
    total.residual = r.residual;
    total.converged = r.converged;
    total.symbolic_analyses += r.symbolic_analyses;
    total.numeric_factorisations += r.numeric_factorisations;
    total.indefinite_iterations += r.indefinite_iterations;
    total.negative_curvature_steps += r.negative_curvature_steps;
    total.boundary_steps += r.boundary_steps;
    total.rejected_steps += r.rejected_steps;
    total.factorisation_seconds += r.factorisation_seconds;
    total.assembly_seconds += r.assembly_seconds;
    total.curvature_seconds += r.curvature_seconds;
  }
  total.seconds = now() - t0;
  return total;
}

StaticResult solve_linear(const Problem& p) {
  const double t0 = now();
  SparseMatrix K;
  p.form->hessian(p.rest, K, false);
  apply_dirichlet(K, p.fixed);
  VectorXd f = p.external_force;
  for (int i = 0; i < f.size(); ++i) {
    if (p.fixed[i]) f[i] = 0.0;
  }
  CholmodSolver solver;
  solver.factorize(K);
  StaticResult r;
  r.x = p.rest + solver.solve(f);
  r.iterations = 1;
  r.converged = true;
  VectorXd Ku = K * (r.x - p.rest) - f;
  r.residual = Ku.norm();
  r.symbolic_analyses = solver.symbolic_analyses();
  r.numeric_factorisations = solver.numeric_factorisations();
  r.factorisation_seconds = solver.factorisation_seconds();
  r.seconds = now() - t0;
  return r;
}

}  // namespace vessel::msm
