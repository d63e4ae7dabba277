#include "msm/rods/constrained_newton.hpp"

#include <Eigen/SparseLU>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace vessel::msm::rods {

namespace {

int num_constraints(const ConstrainedProblem& p) {
  return p.constraints ? p.constraints->num_constraints() : 0;
}

struct KktResidual {
  VectorXd gradient;  ///< ∇L on free dofs (zero on held ones)
  VectorXd c;
};

KktResidual residual(const ConstrainedProblem& p, const VectorXd& x, const VectorXd& lambda) {
  KktResidual r;
  p.form->gradient(x, r.gradient);
  r.gradient -= p.external_force;
  if (p.inertia_mass.size() > 0) {
    r.gradient += p.inertia_mass.cwiseProduct(x - p.inertia_target) / (p.time_step * p.time_step);
  }
  if (p.constraints) {
    SparseMatrix J;
    p.constraints->jacobian(x, J);
    r.gradient += J.transpose() * lambda;
    p.constraints->evaluate(x, r.c);
  }
  for (int i = 0; i < r.gradient.size(); ++i) {
    if (p.fixed[i]) r.gradient[i] = 0.0;
  }
  return r;
}

SparseMatrix kkt_matrix(const ConstrainedProblem& p, const VectorXd& x, const VectorXd& lambda) {
  const int n = static_cast<int>(x.size());
  const int m = num_constraints(p);
  SparseMatrix H, Hc, J(m, n);
  p.form->hessian(x, H, false);
  if (p.constraints) {
    p.constraints->weighted_hessian(x, lambda, Hc);
    p.constraints->jacobian(x, J);
    H += Hc;
  }
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(H.nonZeros() + 2 * J.nonZeros() + n);
  for (int k = 0; k < H.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(H, k); it; ++it) {
      if (!p.fixed[it.row()] && !p.fixed[it.col()]) t.emplace_back(it.row(), it.col(), it.value());
    }
  }
  for (int i = 0; i < n; ++i) {
    if (p.fixed[i]) {
      t.emplace_back(i, i, 1.0);
    } else if (p.inertia_mass.size() > 0) {
      t.emplace_back(i, i, p.inertia_mass[i] / (p.time_step * p.time_step));
    }
  }
  for (int k = 0; k < J.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(J, k); it; ++it) {
      if (p.fixed[it.col()]) continue;
      t.emplace_back(n + it.row(), it.col(), it.value());
      t.emplace_back(it.col(), n + it.row(), it.value());
    }
  }
  SparseMatrix K(n + m, n + m);
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

}  // namespace

ConstrainedResult solve_constrained(const ConstrainedProblem& problem, const VectorXd& start,
                                    const VectorXd& lambda_start,
                                    const ConstrainedOptions& options) {
  const int n = static_cast<int>(start.size());
  const int m = num_constraints(problem);
  VectorXd x = start;
  VectorXd lambda = lambda_start.size() == m ? lambda_start : VectorXd::Zero(m);
  const double fs = std::max(options.force_scale, problem.external_force.norm());
  KktResidual r = residual(problem, x, lambda);
  ConstrainedResult result;
  Eigen::SparseLU<SparseMatrix> lu;
  bool analysed = false;
  double previous = std::numeric_limits<double>::infinity();
  for (int it = 0; it <= options.max_iterations; ++it) {
    const double cmax = r.c.size() > 0 ? r.c.cwiseAbs().maxCoeff() : 0.0;
    const double g = r.gradient.norm();
    // Converged at the tolerance, or at the round-off floor: a stiff penalty (κ ≫ EI/L²) leaves
    // ∇L at about ε·κ; there a Newton step no longer halves it.
    const bool stalled = g <= 1e-4 * fs && g > 0.5 * previous;
    previous = g;
    if ((g <= options.tolerance * fs || stalled) && cmax <= options.constraint_tolerance) {
      result.x = x;
      result.lambda = lambda;
      result.iterations = it;
      result.residual = r.gradient.norm();
      result.constraint_residual = cmax;
      return result;
    }
    if (it == options.max_iterations) break;
    const SparseMatrix K = kkt_matrix(problem, x, lambda);
    if (!analysed) {
      lu.analyzePattern(K);
      analysed = true;
    }
    lu.factorize(K);
    if (lu.info() != Eigen::Success) throw std::runtime_error("solve_constrained: singular KKT matrix");
    VectorXd rhs(n + m);
    rhs << -r.gradient, -r.c;
    const VectorXd step = lu.solve(rhs);
    // Full Newton steps: with a stiff penalty the KKT residual grows on the way to the
    // solution (the frames lag the edges by κ·θ³ after a step), so a residual-decrease test cuts
    // good steps to nothing. Globalisation is by load increments (the callers halve them).
    x += step.head(n);
    if (problem.project) problem.project(x);
    lambda += step.tail(m);
    r = residual(problem, x, lambda);
    if (!std::isfinite(r.gradient.norm()) || !std::isfinite(r.c.norm())) break;
  }
  std::ostringstream msg;
  msg << "solve_constrained: no convergence in " << options.max_iterations
      << " iterations, residual " << r.gradient.norm() << " N, constraints " << r.c.norm();
  throw std::runtime_error(msg.str());
}

}  // namespace vessel::msm::rods
