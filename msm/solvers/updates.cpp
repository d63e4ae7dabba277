#include "msm/solvers/updates.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "meshes/foundation/errors.hpp"
#include "msm/linalg/linear_solver.hpp"
#include "msm/solvers/static_solver.hpp"

namespace vessel::msm {

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void check_size(const Problem& p, const VectorXd& f) {
  if (f.size() != p.num_dofs()) {
    throw InputError("update: expected a load vector of " + std::to_string(p.num_dofs()) +
                     " entries (3 per node), got " + std::to_string(f.size()));
  }
}

/// The stiffness at rest with the fixed dofs' rows and columns replaced by the identity.
SparseMatrix stiffness_at_rest(const Problem& p) {
  SparseMatrix K;
  p.form->hessian(p.rest, K, false);
  apply_dirichlet(K, p.fixed);
  return K;
}

/// "linear": K(x0) u = f with K factorised once at set-up (solve_linear's model). The response
/// to loads on a fixed set S of dofs is the linear map u = K⁻¹[:, S] f_S, so set-up also solves
/// for the columns of K⁻¹ on the dofs the problem's own load acts on (the precomputed elementary
/// deformations of Cotin, Delingette & Ayache 1999, "Real-time elastic deformations of soft
/// tissues for surgery simulation", IEEE TVCG 5(1)), and an update whose load stays on S
/// superposes them: n·|S| multiply-adds, against two sweeps over the factor for a solve. Only
/// where |S|·n ≤ the factor's entries (never more numbers to read than one sweep of the factor);
/// a load with any other dof loaded is solved with the factor as before.
class LinearUpdater final : public Updater {
 public:
  explicit LinearUpdater(const Problem& p) : p_(p) {
    const double t0 = now();
    solver_.factorize(stiffness_at_rest(p_));
    const auto n = static_cast<Eigen::Index>(p_.num_dofs());
    column_.assign(static_cast<std::size_t>(n), -1);
    std::vector<Eigen::Index> support;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (!p_.fixed[i] && p_.external_force[i] != 0.0) support.push_back(i);
    }
    const auto m = static_cast<Eigen::Index>(support.size());
    if (m > 0 && static_cast<double>(m) * static_cast<double>(n) <= solver_.factor_entries()) {
      Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(n, m);
      for (Eigen::Index j = 0; j < m; ++j) {
        unit(support[j], j) = 1.0;
        column_[static_cast<std::size_t>(support[j])] = static_cast<int>(j);
      }
      responses_ = solver_.solve_columns(unit);
      support_ = std::move(support);
      loads_on_support_.resize(m);
    }
    x_ = p_.rest;
    f_ = VectorXd::Zero(n);
    u_ = VectorXd::Zero(n);
    setup_seconds_ = now() - t0;
  }

  UpdateResult update(const VectorXd& external_force) override {
    check_size(p_, external_force);
    const double t0 = now();
    UpdateResult r;
    r.iterations = 1;
    r.superposed = !support_.empty();
    for (Eigen::Index i = 0; i < f_.size(); ++i) {
      f_[i] = p_.fixed[i] ? 0.0 : external_force[i];
      if (f_[i] != 0.0 && column_[static_cast<std::size_t>(i)] < 0) r.superposed = false;
    }
    if (r.superposed) {
      for (std::size_t j = 0; j < support_.size(); ++j) {
        loads_on_support_[static_cast<Eigen::Index>(j)] = f_[support_[j]];
      }
      u_.noalias() = responses_ * loads_on_support_;
    } else {
      solver_.solve_into(f_, u_);  // one solve into kept storage (no allocation per update)
    }
    x_ = p_.rest + u_;
    r.seconds = now() - t0;
    return r;
  }

  [[nodiscard]] int factorisations() const override { return solver_.numeric_factorisations(); }

 private:
  Problem p_;
  CholmodSolver solver_;
  VectorXd f_, u_;
  std::vector<Eigen::Index> support_;  ///< S: the dofs the prepared responses are for
  std::vector<int> column_;            ///< per dof, its column in responses_ (−1: none)
  Eigen::MatrixXd responses_;          ///< K⁻¹[:, S], n × |S|
  VectorXd loads_on_support_;          ///< f_S
};

/// "static": warm-started modified Newton, full Newton where the reused factorisation stops
/// converging fast (the chord and Shamanskii methods of Kelley 2003, "Solving Nonlinear Equations
/// with Newton's Method": the factorisation kept while the iteration contracts).
class StaticNewtonUpdater final : public Updater {
 public:
  StaticNewtonUpdater(const Problem& p, const StaticOptions& so, const UpdateOptions& uo)
      : p_(p), so_(so), uo_(uo) {
    so_.load_steps = 1;  // each update is one load increment from the previous equilibrium
    const double t0 = now();
    const SparseMatrix K = stiffness_at_rest(p_);
    // solve_static's round-off floor of the residual, ε·max|K_ii|·(model size)·√n.
    roundoff_ = std::numeric_limits<double>::epsilon() * K.diagonal().cwiseAbs().maxCoeff() *
                (p_.rest.maxCoeff() - p_.rest.minCoeff()) *
                std::sqrt(static_cast<double>(p_.num_dofs()));
    solver_.factorize(K);
    x_ = p_.rest;
    setup_seconds_ = now() - t0;
  }

  UpdateResult update(const VectorXd& external_force) override {
    check_size(p_, external_force);
    const double t0 = now();
    const int factorisations0 = solver_.numeric_factorisations();
    p_.external_force = external_force;
    const double target = so_.tolerance * std::max(external_force.norm(), so_.force_scale);
    const double stop = std::max(target, roundoff_);
    UpdateResult r;
    p_.potential_gradient(x_, g_);
    double residual = g_.norm();
    // Modified Newton: the step −F⁻¹∇Π with the factorisation F held, kept while the residual
    // contracts by `contraction` per step; a step that does not is discarded. Then (Shamanskii)
    // F is replaced once by the exact Hessian at the state reached, if positive definite, and the
    // iteration goes on with it; a second failure hands over to full Newton.
    bool refreshed = false;
    for (int k = 0; residual > stop && k < uo_.max_reused_iterations; ++k) {
      trial_ = x_ - solver_.solve(g_);
      p_.potential_gradient(trial_, gt_);
      const double next = gt_.norm();
      if (!(next <= uo_.contraction * residual)) {
        if (refreshed || !refactorise_at(x_)) break;
        refreshed = true;
        continue;
      }
      x_.swap(trial_);
      g_.swap(gt_);
      residual = next;
      ++r.iterations;
      if (!refreshed) ++r.reused_iterations;
    }
    if (residual > stop) {
      const StaticResult full = solve_static(p_, so_, x_, solver_);
      x_ = full.x;
      residual = full.residual;
      r.iterations += full.iterations;
    }
    r.residual = residual;
    r.factorisations = solver_.numeric_factorisations() - factorisations0;
    r.seconds = now() - t0;
    return r;
  }

  [[nodiscard]] int factorisations() const override { return solver_.numeric_factorisations(); }

 private:
  /// Factorises the exact Hessian at x; false if it is not positive definite. Then later
  /// updates skip the refactorisation (a wrinkling membrane's Hessian stays indefinite, and a
  /// failed factorisation costs as much as a good one): full Newton, which projects, takes over.
  bool refactorise_at(const VectorXd& x) {
    if (!refresh_exact_) return false;
    p_.form->hessian(x, H_, false);
    apply_dirichlet(H_, p_.fixed);
    refresh_exact_ = solver_.try_factorize(H_);
    return refresh_exact_;
  }

  Problem p_;
  StaticOptions so_;
  UpdateOptions uo_;
  CholmodSolver solver_;
  double roundoff_ = 0.0;
  bool refresh_exact_ = true;  ///< false once an exact Hessian failed to factorise
  VectorXd g_, gt_, trial_;
  SparseMatrix H_;
};

}  // namespace

bool supports_updates(const SolverSpec& spec) {
  return spec.kind == SolverKind::static_newton || spec.kind == SolverKind::linear;
}

std::unique_ptr<Updater> prepare_updates(const Problem& problem, const SolverSpec& spec,
                                         const UpdateOptions& options) {
  switch (spec.kind) {
    case SolverKind::static_newton:
      return std::make_unique<StaticNewtonUpdater>(problem, spec.static_options, options);
    case SolverKind::linear: return std::make_unique<LinearUpdater>(problem);
    default: break;
  }
  throw InputError("solver " + to_string(spec) +
                   ": no prepared updates (static and linear have them; integrators are timed "
                   "per step)");
}

}  // namespace vessel::msm
