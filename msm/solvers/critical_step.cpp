#include "msm/solvers/critical_step.hpp"

#include <Spectra/SymEigsSolver.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "msm/linalg/linear_solver.hpp"

namespace vessel::msm {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Velocity Verlet with damping (integrators.cpp: v½ = v + h/2·a(x, v), x₁ = x + h v½,
/// v₁ = v½ + h/2·a(x₁, v½)) on ẍ = −ω²x − γẋ. With s = h²ω²/2 and g = hγ/2 its amplification
/// matrix is
///   A = [[1 − s, h(1 − g)], [−(h/2)ω²(2 − g − s), (1 − g)(1 − g − s)]],
///   det A = (1 − g)²,  tr A = 1 + (1 − g)² − s(2 − g).
/// A real 2×2 matrix has both eigenvalues in the closed unit disc iff |det A| ≤ 1 and
/// |tr A| ≤ 1 + det A (Schur–Cohn/Jury criterion). |det| ≤ 1 gives h ≤ 4/γ; tr ≤ 1 + det holds
/// for g ≤ 2; −tr ≤ 1 + det gives F(h) = 4(1 + (1 − g)²) − h²ω²(2 − g) ≥ 0. Undamped: h ≤ 2/ω.
double verlet_margin(double h, double omega, double gamma) {
  const double g = 0.5 * h * gamma;
  return 4.0 * (1.0 + (1.0 - g) * (1.0 - g)) - h * h * omega * omega * (2.0 - g);
}

double verlet_critical(double omega, double gamma) {
  if (gamma <= 0.0) return omega > 0.0 ? 2.0 / omega : kInf;
  const double h_det = 4.0 / gamma;  // |det A| = 1 there
  if (omega <= 0.0) return h_det;
  // F(0) = 8 = F(4/γ): F is a cubic in h that may dip below 0 in between; the bound is its first
  // root. Scan finely, then bisect the first sign change.
  const int n = 4000;
  double prev = 0.0;
  for (int i = 1; i <= n; ++i) {
    const double h = h_det * i / n;
    if (verlet_margin(h, omega, gamma) < 0.0) {
      double lo = prev, hi = h;
      for (int k = 0; k < 100; ++k) {
        const double mid = 0.5 * (lo + hi);
        (verlet_margin(mid, omega, gamma) >= 0.0 ? lo : hi) = mid;
      }
      return lo;
    }
    prev = h;
  }
  return h_det;
}

/// y = A x for the scaled stiffness A = S K_ff S, S = M_ff^{-1/2}.
struct MatProd {
  using Scalar = double;
  const SparseMatrix* A;
  [[nodiscard]] Eigen::Index rows() const { return A->rows(); }
  [[nodiscard]] Eigen::Index cols() const { return A->cols(); }
  void perform_op(const double* x, double* y) const {
    Eigen::Map<VectorXd>(y, A->rows()) = *A * Eigen::Map<const VectorXd>(x, A->cols());
  }
};

/// y = S⁻¹ K_ff⁻¹ S⁻¹ x: its largest eigenvalue is 1/ω_min² (shift-invert about 0).
struct InverseProd {
  using Scalar = double;
  const CholmodSolver* solver;
  const VectorXd* sqrt_mass;
  [[nodiscard]] Eigen::Index rows() const { return sqrt_mass->size(); }
  [[nodiscard]] Eigen::Index cols() const { return sqrt_mass->size(); }
  void perform_op(const double* x, double* y) const {
    const VectorXd b = sqrt_mass->cwiseProduct(Eigen::Map<const VectorXd>(x, rows()));
    Eigen::Map<VectorXd>(y, rows()) = sqrt_mass->cwiseProduct(solver->solve(b));
  }
};

/// The free-dof block of a full symmetric matrix, scaled S·B·S by `scale` (per free dof).
SparseMatrix free_block(const SparseMatrix& B, const std::vector<int>& index,
                        const VectorXd& scale) {
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<std::size_t>(B.nonZeros()));
  for (int k = 0; k < B.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(B, k); it; ++it) {
      const int i = index[it.row()], j = index[it.col()];
      if (i >= 0 && j >= 0) t.emplace_back(i, j, scale[i] * it.value() * scale[j]);
    }
  }
  SparseMatrix A(scale.size(), scale.size());
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

/// Largest eigenpair of a symmetric operator of dimension n (Spectra Lanczos; dense for tiny n).
template <class Op>
std::pair<double, VectorXd> largest(Op op, int n, const SpectrumOptions& o, int& iters) {
  if (n <= 12) {
    Eigen::MatrixXd dense(n, n);
    VectorXd e = VectorXd::Zero(n), y(n);
    for (int j = 0; j < n; ++j) {
      e.setZero();
      e[j] = 1.0;
      op.perform_op(e.data(), y.data());
      dense.col(j) = y;
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (dense + dense.transpose()));
    iters = 0;
    return {es.eigenvalues()[n - 1], es.eigenvectors().col(n - 1)};
  }
  const int ncv = std::min(n, 30);
  Spectra::SymEigsSolver<Op> eigs(op, 1, ncv);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestAlge, o.max_iterations, o.tolerance);
  if (eigs.info() != Spectra::CompInfo::Successful) {
    throw std::runtime_error(
        "Lanczos (Spectra) did not converge on the largest eigenvalue of "
        "M^-1 K in " +
        std::to_string(o.max_iterations) + " restarts");
  }
  iters = static_cast<int>(eigs.num_iterations());
  return {eigs.eigenvalues()[0], eigs.eigenvectors().col(0)};
}

}  // namespace

double critical_step_mode(Integrator integrator, double omega, double gamma) {
  omega = std::max(omega, 0.0);
  gamma = std::max(gamma, 0.0);
  switch (integrator) {
    case Integrator::explicit_euler: {
      // Explicit Euler (seed 000 eq. 3.7) is y₁ = (I + hJ) y₀ on y = (x, v), J = [[0, 1],
      // [−ω², −γ]]: its amplification factors are 1 + hλ, λ² + γλ + ω² = 0. Stable iff
      // |1 + hλ|² = 1 + 2h Re λ + h²|λ|² ≤ 1, i.e. h ≤ −2 Re λ / |λ|².
      // Underdamped (γ < 2ω): λ = −ζω ± iω√(1 − ζ²), ζ = γ/(2ω): h ≤ 2ζω/ω² = 2ζ/ω = γ/ω².
      // Overdamped: λ real, the fast root |λ| = γ/2 + √(γ²/4 − ω²): h ≤ 2/|λ| (between 2/γ at
      // ω → 0 and 4/γ at ω = γ/2). So h_crit(ω) rises on [0, γ/2] and falls as γ/ω² beyond:
      // the most restrictive mode is either the highest or the lowest one.
      // Undamped: |1 + ihω| > 1 for every h > 0 (energy × (1 + h²ω²) per step).
      if (gamma <= 0.0) return 0.0;
      if (gamma < 2.0 * omega) return gamma / (omega * omega);
      return 2.0 / (0.5 * gamma + std::sqrt(0.25 * gamma * gamma - omega * omega));
    }
    case Integrator::symplectic_euler: {
      // v₁ = (1 − hγ)v − hω²x, x₁ = x + h v₁: A = [[1 − h²ω², h(1 − hγ)], [−hω², 1 − hγ]],
      // det A = 1 − hγ, tr A = 2 − hγ − h²ω². Jury: |det| ≤ 1 ⇒ h ≤ 2/γ; −tr ≤ 1 + det ⇒
      // h²ω² + 2hγ − 4 ≤ 0 ⇒ h ≤ (√(γ² + 4ω²) − γ)/ω² = 4/(γ + √(γ² + 4ω²)), always the tighter
      // one; 2/ω undamped. The damping force uses the old velocity, so damping *shrinks* the
      // step, and the highest mode is always the most restrictive.
      if (omega <= 0.0) return gamma > 0.0 ? 2.0 / gamma : kInf;
      return 4.0 / (gamma + std::sqrt(gamma * gamma + 4.0 * omega * omega));
    }
    case Integrator::verlet:
      return verlet_critical(omega, gamma);
    case Integrator::implicit_euler:
      // Backward Euler: factors 1/(1 − hλ), modulus < 1 whenever Re λ ≤ 0 and λ ≠ 0.
      return kInf;
  }
  return 0.0;
}

double power_iteration_omega_max(const Problem& p, double tolerance, int max_iterations) {
  const int n = p.num_dofs();
  VectorXd scale = VectorXd::Zero(n);  // M^{-1/2} on the free dofs, 0 on the fixed ones
  for (int i = 0; i < n; ++i) scale[i] = p.fixed[i] ? 0.0 : 1.0 / std::sqrt(p.mass[i]);
  SparseMatrix K;
  p.form->hessian(p.rest, K, false);
  VectorXd y(n);
  for (int i = 0; i < n; ++i) y[i] = scale[i] > 0 ? std::sin(0.7 * i + 0.3) + 1.5 : 0.0;
  if (y.norm() == 0.0) return 0.0;
  y.normalize();
  double rayleigh = 0.0;
  for (int k = 0; k < max_iterations; ++k) {
    const VectorXd w = scale.cwiseProduct(K * scale.cwiseProduct(y));
    const double next = y.dot(w);  // ‖y‖ = 1
    const double norm = w.norm();
    if (norm == 0.0) return 0.0;
    y = w / norm;
    const bool settled = std::abs(next - rayleigh) <= tolerance * std::abs(next);
    rayleigh = next;
    if (settled) break;
  }
  return std::sqrt(std::max(rayleigh, 0.0));
}

Spectrum analyse_spectrum(const Problem& p, const SpectrumOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  Spectrum s;
  s.gershgorin = max_frequency_bound(p);
  const int n = p.num_dofs();
  std::vector<int> index(static_cast<std::size_t>(n), -1);
  int nf = 0;
  for (int i = 0; i < n; ++i) {
    if (!p.fixed[i]) index[i] = nf++;
  }
  s.free_dofs = nf;
  if (nf == 0) return s;
  VectorXd inv_sqrt_mass(nf), sqrt_mass(nf);
  for (int i = 0; i < n; ++i) {
    if (index[i] >= 0) {
      sqrt_mass[index[i]] = std::sqrt(p.mass[i]);
      inv_sqrt_mass[index[i]] = 1.0 / sqrt_mass[index[i]];
    }
  }
  SparseMatrix K, C;
  p.form->hessian(p.rest, K, false);  // exact Hessian at rest
  p.form->damping_jacobian(p.rest, C);
  const SparseMatrix A = free_block(K, index, inv_sqrt_mass);
  const SparseMatrix Cs = free_block(C, index, inv_sqrt_mass);
  // Rayleigh quotient of the damping on a mode y of the scaled problem: γ = yᵀ S C S y / yᵀ y.
  auto damping_rate = [&](const VectorXd& y) { return y.dot(Cs * y) / y.squaredNorm(); };

  int iters = 0;
  const auto [lmax, ymax] = largest(MatProd{&A}, nf, o, iters);
  s.lanczos_iterations = iters;
  s.omega_max = std::sqrt(std::max(lmax, 0.0));
  s.gamma_max = damping_rate(ymax);
  // Bounds of the Rayleigh quotient of S C S (Gershgorin discs; exact for a diagonal C).
  s.gamma_lo = nf > 0 ? kInf : 0.0;
  s.gamma_hi = 0.0;
  {
    VectorXd diag = VectorXd::Zero(nf), off = VectorXd::Zero(nf);
    for (int k = 0; k < Cs.outerSize(); ++k) {
      for (SparseMatrix::InnerIterator it(Cs, k); it; ++it) {
        (it.row() == it.col() ? diag[it.row()] : off[it.row()]) +=
            it.row() == it.col() ? it.value() : std::abs(it.value());
      }
    }
    for (int i = 0; i < nf; ++i) {
      s.gamma_lo = std::min(s.gamma_lo, diag[i] - off[i]);
      s.gamma_hi = std::max(s.gamma_hi, diag[i] + off[i]);
    }
    s.gamma_lo = std::max(s.gamma_lo, 0.0);  // C is positive semi-definite
  }

  if (o.lowest) {
    s.has_lowest = true;
    const SparseMatrix Kff = free_block(K, index, VectorXd::Ones(nf));
    CholmodSolver solver;
    if (!solver.try_factorize(Kff)) {
      s.omega_min = 0.0;  // K singular on the free dofs: a mechanism (zero-frequency mode)
      s.gamma_min = 0.0;
    } else {
      int it2 = 0;
      const auto [linv, ymin_scaled] = largest(InverseProd{&solver, &sqrt_mass}, nf, o, it2);
      s.omega_min = linv > 0 ? 1.0 / std::sqrt(linv) : 0.0;
      // The eigenvector of S⁻¹K⁻¹S⁻¹ is the same y as for S K S.
      s.gamma_min = damping_rate(ymin_scaled);
    }
  }
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

double guaranteed_critical_step(Integrator integrator, const Spectrum& s) {
  if (s.gamma_hi <= 0.0) {
    // No damping: the modes decouple exactly (M⁻¹K alone), the prediction is exact.
    return critical_step_mode(integrator, s.omega_max, 0.0);
  }
  // ω_min: from shift-invert Lanczos when computed, else 0 (a wider rectangle: still a bound).
  const double w_lo = s.has_lowest ? s.omega_min : 0.0;
  switch (integrator) {
    case Integrator::explicit_euler: {
      // h(ω, γ) of critical_step_mode rises then falls in ω for fixed γ (overdamped branch
      // 2/(γ/2 + √(γ²/4 − ω²)) increasing up to ω = γ/2, then γ/ω² decreasing) and rises then
      // falls in γ for fixed ω (γ/ω² increasing up to γ = 2ω, then the overdamped branch
      // decreasing): quasi-concave in each variable, so its minimum over the rectangle is at a
      // corner.
      double h = kInf;
      for (double w : {w_lo, s.omega_max}) {
        for (double g : {s.gamma_lo, s.gamma_hi}) {
          h = std::min(h, critical_step_mode(integrator, w, g));
        }
      }
      return h;
    }
    case Integrator::symplectic_euler:
      // 4/(γ + √(γ² + 4ω²)) decreases in both γ and ω: the corner (ω_max, γ_hi).
      return critical_step_mode(integrator, s.omega_max, s.gamma_hi);
    case Integrator::verlet:
      return std::numeric_limits<double>::quiet_NaN();
    case Integrator::implicit_euler:
      return kInf;
  }
  return 0.0;
}

double predicted_critical_step(Integrator integrator, const Spectrum& s) {
  double h = critical_step_mode(integrator, s.omega_max, s.gamma_max);
  if (s.has_lowest) h = std::min(h, critical_step_mode(integrator, s.omega_min, s.gamma_min));
  return h;
}

}  // namespace vessel::msm
