#include "verification/contact/signorini.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace vessel::contact {

namespace {

/// z on the set P (indices), solving W_PP z_P = −g0_P; zero elsewhere.
Eigen::VectorXd solve_on(const Eigen::MatrixXd& W, const Eigen::VectorXd& g0,
                         const std::vector<int>& P) {
  const auto k = static_cast<Eigen::Index>(P.size());
  Eigen::MatrixXd A(k, k);
  Eigen::VectorXd b(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    b[i] = -g0[P[i]];
    for (Eigen::Index j = 0; j < k; ++j) A(i, j) = W(P[i], P[j]);
  }
  const Eigen::VectorXd zp = A.llt().solve(b);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(g0.size());
  for (Eigen::Index i = 0; i < k; ++i) z[P[i]] = zp[i];
  return z;
}

}  // namespace

SignoriniSolution solve_signorini(const Eigen::MatrixXd& W, const Eigen::VectorXd& g0,
                                  double gap_tolerance) {
  const Eigen::Index m = g0.size();
  if (W.rows() != m || W.cols() != m) {
    throw std::invalid_argument("solve_signorini: W is " + std::to_string(W.rows()) + "x" +
                                std::to_string(W.cols()) + ", the gaps " + std::to_string(m));
  }
  SignoriniSolution s;
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m);
  std::vector<char> in_p(static_cast<std::size_t>(m), 0);
  std::vector<int> P;
  std::vector<char> barred(static_cast<std::size_t>(m), 0);  // entered, but not positive
  for (int outer = 0; outer < 3 * m + 10; ++outer) {
    const Eigen::VectorXd g = g0 + W * lambda;
    Eigen::Index enter = -1;
    double most = -gap_tolerance;
    for (Eigen::Index i = 0; i < m; ++i) {
      if (!in_p[i] && !barred[i] && g[i] < most) most = g[i], enter = i;
    }
    if (enter < 0) break;
    in_p[enter] = 1;
    P.push_back(static_cast<int>(enter));
    ++s.iterations;
    for (bool first = true;; first = false) {  // keeps λ ≥ 0 on the way to the set's solution
      const Eigen::VectorXd z = solve_on(W, g0, P);
      if (first && z[enter] <= 0.0) {  // round-off only (g_enter < 0 makes it positive in exact
        in_p[enter] = 0;               // arithmetic): leave it out rather than cycle
        P.pop_back();
        barred[enter] = 1;
        break;
      }
      double alpha = 1.0;
      for (const int i : P) {
        if (z[i] <= 0.0) alpha = std::min(alpha, lambda[i] / (lambda[i] - z[i]));
      }
      lambda += alpha * (z - lambda);
      if (alpha >= 1.0) break;
      std::vector<int> kept;
      for (const int i : P) {
        if (lambda[i] > 0.0 && z[i] > 0.0) {
          kept.push_back(i);
        } else if (z[i] <= 0.0 && lambda[i] <= 1e-15 * lambda.maxCoeff()) {
          lambda[i] = 0.0;  // the step stopped on it: it leaves the set
          in_p[i] = 0;
        } else {
          kept.push_back(i);
        }
      }
      P = kept;
      ++s.iterations;
    }
    std::fill(barred.begin(), barred.end(), 0);
    barred[enter] = !in_p[enter];
  }
  s.force = lambda;
  s.gap = g0 + W * lambda;
  s.active.assign(static_cast<std::size_t>(m), 0);
  for (Eigen::Index i = 0; i < m; ++i) s.active[i] = lambda[i] > 0.0;
  return s;
}

RigidPress press_rigid_indenter(const Eigen::MatrixXd& W, const Eigen::VectorXd& h,
                                double total_force, double gap_tolerance) {
  if (!(total_force > 0.0)) throw std::invalid_argument("press_rigid_indenter: force must be > 0");
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(h.size());
  RigidPress p;
  // Start with the first candidate to touch: Σλ(δ) = (δ − h_min) / W_kk on that set.
  Eigen::Index first = 0;
  h.minCoeff(&first);
  p.approach = h[first] + total_force * W(first, first);
  for (int k = 0; k < 200; ++k) {
    p.contact = solve_signorini(W, h - p.approach * ones, gap_tolerance);
    const double sum = p.contact.force.sum();
    if (std::abs(sum - total_force) <= 1e-12 * total_force) return p;
    // On this active set A: λ_A = W_AA⁻¹ (δ 1 − h_A), so Σλ = δ s − c with s = 1ᵀW_AA⁻¹1.
    std::vector<int> A;
    for (Eigen::Index i = 0; i < h.size(); ++i) {
      if (p.contact.active[i]) A.push_back(static_cast<int>(i));
    }
    const Eigen::VectorXd unit = solve_on(W, -ones, A);  // W_AA⁻¹ 1 on A
    const double slope = unit.sum();
    p.approach += (total_force - sum) / slope;
  }
  throw std::runtime_error("press_rigid_indenter: no active set reached the force in 200 steps");
}

}  // namespace vessel::contact
