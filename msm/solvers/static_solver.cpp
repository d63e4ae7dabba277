#include "msm/solvers/static_solver.hpp"

#include <chrono>
#include <cmath>
#include <limits>
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

StaticResult newton(const Problem& p, const StaticOptions& o, const VectorXd& start) {
  const double t0 = now();
  StaticResult r;
  r.x = start.size() == p.num_dofs() ? start : p.rest;
  for (int i = 0; i < p.num_dofs(); ++i) {
    if (p.fixed[i]) r.x[i] = p.rest[i];
  }
  const double target = o.tolerance * std::max(p.external_force.norm(), o.force_scale);
  CholmodSolver solver;
  VectorXd g;
  SparseMatrix H;
  double energy = p.potential(r.x);
  // Round-off floor of the residual: ε·(largest stiffness)·(model size)·√n, set at the first
  // Hessian; below it the residual cannot be reduced, whatever the load.
  double roundoff = 0.0;
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
    p.form->hessian(r.x, H, false);
    if (roundoff == 0.0) {
      const double size = (p.rest.maxCoeff() - p.rest.minCoeff());
      roundoff = std::numeric_limits<double>::epsilon() * H.diagonal().cwiseAbs().maxCoeff() *
                 size * std::sqrt(static_cast<double>(p.num_dofs()));
    }
    apply_dirichlet(H, p.fixed);
    bool exact = solver.try_factorize(H);
    if (!exact) {
      if (o.project_psd) {
        p.form->hessian(r.x, H, true);
        apply_dirichlet(H, p.fixed);
      }
      solver.factorize(H);
    }
    const VectorXd dx = -solver.solve(g);
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
    if (!accepted) break;
    if (o.log) {
      *o.log << "  newton " << r.iterations << ": residual " << r.residual << " N, step " << alpha
             << (exact ? ", exact Hessian" : ", projected Hessian") << ", regularisation "
             << solver.last_regularisation() << ", energy " << trial_energy << " J\n";
    }
    r.x = trial;
    energy = trial_energy;
  }
  r.symbolic_analyses = solver.symbolic_analyses();
  r.numeric_factorisations = solver.numeric_factorisations();
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
  if (o.load_steps <= 1) return newton(p, o, start);
  // Load stepping: Newton on f_ext·s/N for s = 1..N, each from the previous equilibrium.
  const double t0 = now();
  Problem step = p;
  StaticResult total;
  total.x = start;
  for (int s = 1; s <= o.load_steps; ++s) {
    step.external_force = p.external_force * (static_cast<double>(s) / o.load_steps);
    const StaticResult r = newton(step, o, total.x);
    total.x = r.x;
    total.iterations += r.iterations;
    total.residual = r.residual;
    total.converged = r.converged;
    total.symbolic_analyses += r.symbolic_analyses;
    total.numeric_factorisations += r.numeric_factorisations;
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
  r.seconds = now() - t0;
  return r;
}

}  // namespace vessel::msm
