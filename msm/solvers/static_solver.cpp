#include "msm/solvers/static_solver.hpp"

#include <chrono>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

#include "msm/solvers/linear_solver.hpp"

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

StaticResult newton(const Problem& p, const StaticOptions& o, const VectorXd& start,
                    CholmodSolver& solver) {
  const double t0 = now();
  const int analyses0 = solver.symbolic_analyses();
  const int factorisations0 = solver.numeric_factorisations();
  const double factorisation_seconds0 = solver.factorisation_seconds();
  StaticResult r;
  r.x = start.size() == p.num_dofs() ? start : p.rest;
  for (int i = 0; i < p.num_dofs(); ++i) {
    if (p.fixed[i]) r.x[i] = p.rest[i];
  }
  const double target = o.tolerance * std::max(p.external_force.norm(), o.force_scale);
  VectorXd g;
  SparseMatrix H, Hp;
  VectorXd curvature_direction;
  double energy = p.potential(r.x);
  // Round-off floor of the residual: ε·(largest stiffness)·(model size)·√n, set at the first
  // Hessian; below it the residual cannot be reduced, whatever the load.
  double roundoff = 0.0;
  int backoff = 0, skip_exact = 0;
  for (r.iterations = 0; r.iterations <= o.max_iterations; ++r.iterations) {
    p.potential_gradient(r.x, g);
    r.residual = g.norm();
    if (!std::isfinite(r.residual)) break;
    if (r.residual <= std::max(target, roundoff)) {
      r.converged = true;
      break;
    }
    if (r.iterations == o.max_iterations) break;
    // The exact Hessian where it is positive definite (quadratic convergence); where compression
    // makes it indefinite, the per-spring PSD projection (then regularised if still singular).
    double ta = now();
    p.form->hessian(r.x, H, false);
    r.assembly_seconds += now() - ta;
    if (roundoff == 0.0) {
      const double size = (p.rest.maxCoeff() - p.rest.minCoeff());
      roundoff = std::numeric_limits<double>::epsilon() * H.diagonal().cwiseAbs().maxCoeff() *
                 size * std::sqrt(static_cast<double>(p.num_dofs()));
    }
    apply_dirichlet(H, p.fixed);
    // A failed (indefinite) factorisation costs as much as a good one. After a failure, skip the
    // exact attempt for 1, 2, 4 (at most `exact_backoff`) iterations while it keeps failing.
    const bool try_exact = skip_exact == 0;
    if (skip_exact > 0) --skip_exact;
    const bool exact = try_exact && solver.try_factorize(H);
    if (exact) {
      backoff = 0;
    } else if (try_exact && o.exact_backoff > 0) {
      backoff = std::min(std::max(1, 2 * backoff), o.exact_backoff);
      skip_exact = backoff;
    }
    if (!exact) {
      ++r.indefinite_iterations;
      ta = now();
      p.form->hessian(r.x, Hp, o.project_psd);
      apply_dirichlet(Hp, p.fixed);
      r.assembly_seconds += now() - ta;
      solver.factorize(Hp);
    }
    VectorXd dx = -solver.solve(g);
    // A direction of negative curvature of the exact Hessian (only where it is indefinite). The
    // projected Newton step alone cannot see it: near a saddle or buckling point (a membrane
    // wrinkling under the contact load) it then creeps away at a linear rate, tens of iterations
    // (measured: 50 at structured level 0). Moving along it lowers Π to second order.
    double curvature = 0.0;
    double tau = 1.0;
    if (!exact && o.curvature_iterations > 0) {
      if (curvature_direction.size() != g.size()) curvature_direction = start_vector(p.fixed);
      const double tc = now();
      curvature = negative_curvature(H, Hp, solver, o.curvature_iterations, curvature_direction);
      r.curvature_seconds += now() - tc;
      if (curvature < 0.0 && o.curvature_shift < 1.0) {
        // The blend (1 − τ)H + τHp has the eigenvalues (1 − τ)λ + τ (relative to Hp): τ = (δ − λ)/(1
        // − λ) lifts the most negative λ found to δ. A Hessian modification in the spirit of Nocedal
        // & Wright (2006) §3.4, but only on the springs the projection changed. It keeps most of
        // the exact Hessian, so the step is long along soft (buckling) modes; if λ was not the most
        // negative eigenvalue the factorisation fails and the projected step is kept.
        const VectorXd& v = curvature_direction;
        const double lambda = curvature / v.dot(Hp * v);
        const double delta = std::max(o.curvature_shift, 0.0);
        tau = std::min(1.0, (delta - lambda) / (1.0 - lambda));
        SparseMatrix Ht = (1.0 - tau) * H + tau * Hp;
        if (solver.try_factorize(Ht)) {
          dx = -solver.solve(g);
        } else {
          tau = 1.0;
        }
      }
    }
    // Backtracking (Armijo) line search on Π. Near the solution the energy change drops below
    // round-off (|ΔΠ| ≲ 1e-12 |Π|): there a step is accepted if it reduces the residual instead.
    const double slope = g.dot(dx);
    double alpha = 1.0;
    VectorXd trial, gt;
    double trial_energy = energy;
    bool accepted = false;
    for (int ls = 0; ls < 40; ++ls) {
      trial = r.x + alpha * dx;
      trial_energy = p.potential(trial);
      if (!std::isfinite(trial_energy)) {
        alpha *= 0.5;
        continue;
      }
      if (trial_energy <= energy + 1e-4 * alpha * slope) {
        accepted = true;
        break;
      }
      if (std::abs(trial_energy - energy) <= 1e-12 * std::abs(energy)) {
        p.potential_gradient(trial, gt);
        if (gt.norm() < r.residual) {
          accepted = true;
          break;
        }
      }
      alpha *= 0.5;
    }
    if (!accepted && curvature >= 0.0) break;
    if (accepted) {
      r.x = trial;
      energy = trial_energy;
    }
    double beta = 0.0;
    if (curvature < 0.0) {
      // Search along ±v (sign: downhill at the new point) with expansion: Π(x + βv) falls as
      // ½β²vᵀHv until higher-order terms stop it. Start at the Newton step's size (at least
      // 1e-3 of the displacement so far), grow ×4 while Π keeps falling.
      VectorXd& v = curvature_direction;
      p.potential_gradient(r.x, gt);
      const double sign = gt.dot(v) > 0.0 ? -1.0 : 1.0;
      double b = std::max({accepted ? alpha * dx.cwiseAbs().maxCoeff() : 0.0,
                           1e-3 * (r.x - p.rest).cwiseAbs().maxCoeff(),
                           1e-9 * (p.rest.maxCoeff() - p.rest.minCoeff())}) /
                 v.cwiseAbs().maxCoeff();
      double best = energy;
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
      } else if (!accepted) {
        break;
      }
    }
    if (o.log) {
      *o.log << "  newton " << r.iterations << ": residual " << r.residual << " N, step " << alpha
             << (exact ? ", exact Hessian" : ", projected Hessian") << ", regularisation "
             << solver.last_regularisation();
      if (tau < 1.0) *o.log << ", tau " << tau;
      if (curvature < 0.0) *o.log << ", curvature " << curvature << " N/m, step " << beta << " m";
      *o.log << ", energy " << energy << " J\n";
    }
  }
  r.symbolic_analyses = solver.symbolic_analyses() - analyses0;
  r.numeric_factorisations = solver.numeric_factorisations() - factorisations0;
  r.factorisation_seconds = solver.factorisation_seconds() - factorisation_seconds0;
  r.seconds = now() - t0;
  if (!r.converged) {
    std::ostringstream msg;
    msg << "static Newton did not converge: iteration " << r.iterations << ", residual "
        << r.residual << " N (target " << target << " N)";
    throw std::runtime_error(msg.str());
  }
  return r;
}

}  // namespace

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
