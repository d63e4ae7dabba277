#pragma once
/// Natural frequencies of a mass-spring model at rest: the generalised eigenproblem
/// K φ = ω² M φ on the free dofs, K the model's exact Hessian at rest (springs plus every other
/// term of its Form, e.g. the hybrid model's volume term), M its lumped masses (diagonal), fixed
/// dofs (supports) removed. Solved as the standard symmetric problem A y = ω² y with
/// A = M^{-1/2} K M^{-1/2}, φ = M^{-1/2} y, by shift-invert Lanczos (Spectra's SymEigsShiftSolver)
/// about a small negative shift σ: (A − σI)⁻¹ = M^{1/2} (K − σM)⁻¹ M^{1/2}, with K − σM
/// factorised once by CHOLMOD (positive definite for σ < 0 since K is positive semi-definite at
/// rest: each spring's block there is k·d dᵀ, the volume term's κ/V₀·∇V ∇Vᵀ). The eigenvalues
/// nearest σ are then the lowest ones; zero-frequency modes (mechanisms, e.g. a membrane's
/// transverse motion, which only tension stiffens) show as ω ≈ 0 and are counted.
#include <vector>

#include "msm/form/form.hpp"

namespace vessel::msm {

struct NaturalFrequencyOptions {
  int count = 6;  ///< lowest modes wanted (≥ 1, < free dofs)
  /// σ = −relative_shift × mean(K_ii/m_i) over the free dofs, (rad/s)²: a shift below the
  /// spectrum's bottom (0) that keeps K − σM positive definite with mechanisms present, and close
  /// enough to 0 that the lowest modes converge first.
  double relative_shift = 1e-4;
  double tolerance = 1e-10;  ///< Spectra's relative tolerance on the eigenvalues
  int max_iterations = 1000;  ///< Lanczos restarts
  /// At or below this many free dofs the eigenproblem is solved densely (Eigen's
  /// SelfAdjointEigenSolver on A): cheaper than Lanczos there, and exact.
  int dense_max_dofs = 200;
};

struct NaturalFrequencies {
  std::vector<double> omega;           ///< rad/s, ascending, `count` of them
  std::vector<double> frequencies_hz;  ///< ω/(2π), Hz
  /// Mode shapes φ (num_dofs × count, zero on fixed dofs), M-orthonormal: φᵀMφ = I.
  Eigen::MatrixXd shapes;
  /// Modes among them with ω² ≤ 1e-8 × mean(K_ii/m_i): zero-frequency motions (mechanisms).
  int mechanisms = 0;
  int free_dofs = 0;
  double shift = 0.0;      ///< σ used, (rad/s)²
  int iterations = 0;      ///< Lanczos restarts (0: dense)
  double seconds = 0.0;    ///< assembly, factorisation and iteration, wall clock
};

/// The `options.count` lowest natural frequencies of `problem` at its rest positions. InputError
/// if count < 1 or count ≥ the free dofs, or a free dof has no positive mass; std::runtime_error
/// if K − σM cannot be factorised (K not positive semi-definite) or Lanczos does not converge.
NaturalFrequencies natural_frequencies(const Problem& problem,
                                       const NaturalFrequencyOptions& options = {});

}  // namespace vessel::msm
