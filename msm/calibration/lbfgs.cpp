#include "msm/calibration/lbfgs.hpp"

#include <cmath>
#include <deque>
#include <stdexcept>

namespace vessel::msm {

LbfgsResult minimize_lbfgs(const Objective& f, const Eigen::VectorXd& x0,
                           const LbfgsOptions& o) {
  if (o.memory < 1) throw std::invalid_argument("minimize_lbfgs: memory must be >= 1");
  LbfgsResult r;
  r.x = x0;
  Eigen::VectorXd g(x0.size());
  r.f = f(r.x, g);
  r.evaluations = 1;
  if (!std::isfinite(r.f)) throw std::invalid_argument("minimize_lbfgs: f(x0) is not finite");
  const double g_scale = std::max(1.0, g.lpNorm<Eigen::Infinity>());
  std::deque<Eigen::VectorXd> S, Y;
  std::deque<double> rho;
  Eigen::VectorXd x_new(x0.size()), g_new(x0.size());
  r.stop_reason = "iterations";
  for (r.iterations = 0; r.iterations < o.max_iterations; ++r.iterations) {
    r.gradient_norm = g.lpNorm<Eigen::Infinity>();
    if (r.gradient_norm <= o.gradient_tolerance * g_scale) {
      r.converged = true;
      r.stop_reason = "gradient";
      break;
    }
    // Two-loop recursion (Nocedal & Wright Algorithm 7.4): d = −H g.
    Eigen::VectorXd q = g;
    std::vector<double> alpha(S.size());
    for (int i = static_cast<int>(S.size()) - 1; i >= 0; --i) {
      alpha[i] = rho[i] * S[i].dot(q);
      q -= alpha[i] * Y[i];
    }
    double gamma = 1.0;
    if (!S.empty()) gamma = S.back().dot(Y.back()) / Y.back().squaredNorm();  // eq. 7.20
    Eigen::VectorXd d = gamma * q;
    for (std::size_t i = 0; i < S.size(); ++i) {
      const double beta = rho[i] * Y[i].dot(d);
      d += S[i] * (alpha[i] - beta);
    }
    d = -d;
    double slope = g.dot(d);
    if (!(slope < 0.0)) {  // not a descent direction (round-off): restart with steepest descent
      S.clear();
      Y.clear();
      rho.clear();
      d = -g;
      slope = -g.squaredNorm();
    }
    // First iteration: a step of unit length in the steepest direction's scale.
    double step = S.empty() ? std::min(1.0, 1.0 / std::max(1e-300, d.lpNorm<Eigen::Infinity>()))
                            : 1.0;
    double f_new = 0.0;
    bool accepted = false;
    for (int b = 0; b <= o.max_backtracks; ++b) {
      x_new = r.x + step * d;
      f_new = f(x_new, g_new);
      ++r.evaluations;
      if (std::isfinite(f_new) && f_new <= r.f + o.armijo * step * slope) {
        accepted = true;
        break;
      }
      step *= 0.5;
    }
    if (!accepted) {
      r.stop_reason = "line search";
      break;
    }
    const Eigen::VectorXd s = x_new - r.x;
    const Eigen::VectorXd y = g_new - g;
    const double sy = s.dot(y);
    if (sy > 1e-12 * s.norm() * y.norm()) {
      S.push_back(s);
      Y.push_back(y);
      rho.push_back(1.0 / sy);
      if (static_cast<int>(S.size()) > o.memory) {
        S.pop_front();
        Y.pop_front();
        rho.pop_front();
      }
    }
    const double decrease = r.f - f_new;
    r.x = x_new;
    g = g_new;
    r.f = f_new;
    if (o.on_iteration) o.on_iteration(r.iterations + 1, r.f, g.lpNorm<Eigen::Infinity>());
    if (decrease <= o.relative_decrease * std::max(1.0, std::abs(r.f))) {
      ++r.iterations;
      r.gradient_norm = g.lpNorm<Eigen::Infinity>();
      r.converged = r.gradient_norm <= o.gradient_tolerance * g_scale;
      r.stop_reason = r.converged ? "gradient" : "no decrease";
      break;
    }
  }
  r.gradient_norm = g.lpNorm<Eigen::Infinity>();
  return r;
}

}  // namespace vessel::msm
