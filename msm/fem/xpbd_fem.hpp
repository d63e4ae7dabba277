#pragma once
/// XPBD FEM: the stable neo-Hookean tetrahedron as two constraints per tet (Macklin & Müller 2021,
/// "A constraint-based formulation of stable neo-Hookean materials", MIG, §4), solved by XPBD
/// (Macklin, Müller & Chentanez 2016) in Gauss–Seidel sweeps over the tets:
///   deviatoric   C_D = √tr(FᵀF),   compliance 1/(μ V₀),
///   hydrostatic  C_H = det F − α,   compliance 1/(λ V₀),  α = 1 + μ/λ,
/// so that ½C_D²/α_D + ½C_H²/α_H = V₀(½μ I_C + ½λ(J − α)²): the StableNeoHookeanTerm energy plus a
/// constant. Each constraint update: Δλ = −(C + α̃λ)/(∇C W ∇Cᵀ + α̃), x += W ∇Cᵀ Δλ, α̃ = α/h².
///
/// Multipliers are carried from step to step as XpbdRod carries them (msm/rods/xpbd_rod.hpp): a
/// step starts from the last step's λ (kept as a force λ/h² and rescaled by the step's h²), and
/// the prediction includes that force, x̃ = x + h v + h² W (f + Σ ∇Cᵀ λ/h²). A steady state (v = 0,
/// λ unchanged by the sweeps) then has C + α̃λ = 0 on every constraint and f + Σ ∇Cᵀ λ/h² = 0: the
/// static equilibrium of the energy, whatever the number of sweeps. The carried multipliers start
/// at the rest shape's own (−C(X)/α per constraint: C_D(I) = √3, so the two constraints hold the
/// rest shape by opposite forces ±μV₀ I); from zero the first sweeps collapse the tets towards
/// F = 0. The carried force acts along the step's initial gradients, explicitly: the part of the
/// stiffness it carries (most of the deviatoric one, μV₀ (I − n nᵀ) in F, n = F/‖F‖) is then
/// integrated explicitly and h must resolve it (tests/msm/test_xpbd_fem.cpp: on its test tube,
/// h = 1 ms diverges and 0.1 ms settles). With carry_multipliers = false, λ restarts from zero
/// each step (Macklin et al.'s algorithm) and the steady state depends on the sweep count.
/// Units: positions m, h s, forces N, masses kg, Lamé parameters Pa.
#include <vector>

#include "msm/fem/stable_neo_hookean.hpp"

namespace vessel::msm {

struct XpbdFemOptions {
  int iterations = 4;     ///< Gauss–Seidel sweeps per step
  double damping = 0.02;  ///< fraction of the velocity removed per step
  bool carry_multipliers = true;
};

class XpbdFem {
 public:
  /// `lame`: the stable neo-Hookean energy's own (μ, λ), λ > 0; `mass`: lumped, per dof (kg);
  /// `fixed`: per dof, held at its rest position (a node is held if any of its dofs is). Throws
  /// InputError for sizes that do not match the nodes, or a free node of zero mass.
  XpbdFem(const std::vector<Vec3>& nodes, std::vector<Tet> tets, LameParameters lame,
          const VectorXd& mass, const std::vector<char>& fixed, XpbdFemOptions options = {});

  /// One step of length h (s) under the dead loads `force` (N, per dof). DivergenceError on a
  /// non-finite position.
  void step(double h, const VectorXd& force);
  /// Steps until the largest node movement in a step is at most `relative_change` × the largest
  /// node displacement from rest (so the test means the same at 1 µN and at 100 mN), or
  /// max_steps; returns the steps taken. The test bounds the last step's movement, not the
  /// distance to the steady state: that is about the movement × 1/(1 − ρ), ρ the per-step decay
  /// of the slowest mode.
  int relax(double h, const VectorXd& force, double relative_change, int max_steps);

  [[nodiscard]] const VectorXd& state() const { return x_; }
  /// The velocity the next step starts from, m/s (per dof).
  [[nodiscard]] const VectorXd& velocity() const { return v_; }
  /// Sets it (zero on held nodes); InputError for a wrong size.
  void set_velocity(const VectorXd& v);
  /// The energy the constraints carry, as a Form (for a Newton solve of the same energy).
  [[nodiscard]] const StableNeoHookeanTerm& energy_model() const { return energy_; }

 private:
  /// Constraint c (0: deviatoric, 1: hydrostatic) of tet k at x_: C and ∇C (12 entries).
  double evaluate(std::size_t k, int c, Vec12& grad) const;

  StableNeoHookeanTerm energy_;
  XpbdFemOptions options_;
  VectorXd rest_, x_, v_, inverse_mass_;
  std::vector<std::array<double, 2>> compliance_;    ///< per tet: α_D, α_H (1/(Pa·m³))
  std::vector<std::array<double, 2>> lambda_;        ///< the step's multipliers (scaled by h²)
  std::vector<std::array<double, 2>> force_lambda_;  ///< carried multipliers as forces (λ/h²)
  int steps_taken_ = 0;
};

}  // namespace vessel::msm
