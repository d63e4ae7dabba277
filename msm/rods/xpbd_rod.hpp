#pragma once
/// An XPBD Cosserat rod: position- and orientation-based Cosserat rods (Kugelstadt & Schömer,
/// SCA 2016) with compliance (XPBD, Macklin, Müller & Chentanez 2016). The state is CORDE's
/// (centreline points, a quaternion per edge, the same dof layout); per time step the
/// constraints are projected in Gauss–Seidel sweeps:
///   stretch–shear  Γ_j = (P_{j+1} − P_j)/l_j − d3(q_j), compliance 1/(κ l_j),
///   bend–twist     Ω_i = (2/l̄_i) Im(q̄_{i−1} q_i),    compliance diag(EI, EI, GJ)⁻¹/l̄_i,
/// each as a 3-row block (Δλ = −(J W Jᵀ + α/h²)⁻¹ (C + α λ/h²), Δx = W Jᵀ Δλ), quaternions
/// renormalised after each correction; the multipliers start from zero each step (XPBD). Its
/// energy is CordeRod(layout, κ, inextensible = false)'s, but its steady state is that energy's
/// equilibrium only as the sweeps per step converge: with few sweeps it is softer, the more so
/// the longer the step (tests/rods/test_xpbd.cpp measures it). The frames carry the segment's
/// rotary inertia ρA l³/12: with the section's ρI l alone they are ~10⁷ times lighter than the
/// points and the sweeps diverge.
#include <array>
#include <vector>

#include "msm/rods/corde_rod.hpp"

namespace vessel::msm::rods {

struct XpbdOptions {
  int iterations = 4;        ///< Gauss–Seidel sweeps per step
  double damping = 0.02;     ///< velocity damping per step (fraction removed)
};

class XpbdRod {
 public:
  XpbdRod(RodLayout layout, double alignment = 0.0, XpbdOptions options = {});

  /// One step of length h under the dead loads `force` (per dof; positions only).
  void step(double h, const VectorXd& force);
  /// Steps until the largest position change in a step is ≤ tolerance·L (or max_steps);
  /// returns the number of steps taken.
  int relax(double h, const VectorXd& force, double tolerance, int max_steps);

  [[nodiscard]] const VectorXd& state() const { return x_; }
  [[nodiscard]] const CordeRod& energy_model() const { return model_; }
  [[nodiscard]] int tip_node() const { return model_.layout().tip_node; }

 private:
  [[nodiscard]] std::array<int, 10> edge_dofs(int edge) const;
  [[nodiscard]] std::array<int, 8> vertex_dofs(int vertex) const;
  void project_stretch_shear(int edge, double h);
  void project_bend_twist(int vertex, double h);

  CordeRod model_;
  XpbdOptions options_;
  VectorXd x_, v_, inverse_mass_;
  std::vector<Eigen::Vector3d> lambda_ss_, lambda_bt_;  ///< per edge, per vertex
};

}  // namespace vessel::msm::rods
