#pragma once
/// What every rod model of msm/rods gives the solvers that load, insert, press into a wall and
/// step it, so those are written once for DER and CORDE (and the XPBD rod's energy, a CordeRod):
/// the layout, the rest state, the clamps' held dofs, the lumped masses, the energy (a Form), the
/// model's own equality constraints and the two hooks a state change needs.
#include <algorithm>
#include <utility>
#include <vector>

#include "msm/form/equality_constraints.hpp"
#include "msm/form/form.hpp"
#include "msm/rods/rod_layout.hpp"

namespace vessel::msm::rods {

class Rod : public Form {
 public:
  explicit Rod(RodLayout layout) : layout_(std::move(layout)) {}

  [[nodiscard]] const RodLayout& layout() const { return layout_; }
  [[nodiscard]] int num_nodes() const { return layout_.num_nodes(); }
  /// The rest state: rest positions, the model's rest frame dofs.
  [[nodiscard]] virtual VectorXd rest_state() const = 0;
  /// The clamps' held dofs: the ghost nodes, the clamp nodes and the ghost edges' frame dofs.
  [[nodiscard]] virtual std::vector<char> clamp_fixed() const = 0;
  /// Lumped masses per dof (kg on positions, the frame dofs' rotary inertia).
  [[nodiscard]] virtual VectorXd lumped_mass() const = 0;
  /// The model's hard equality constraints (CORDE's inextensibility and unit quaternions), or
  /// null for a model without any (DER).
  [[nodiscard]] virtual const EqualityConstraints* constraints() const { return nullptr; }
  /// Maps a Newton iterate back onto the part of the constraint manifold that is cheap to reach
  /// (CORDE: unit quaternions); nothing for DER.
  virtual void project(VectorXd& /*x*/) const {}
  /// Readies the model for states near x before a new load or time step from x (DER: carries its
  /// reference frames to x by parallel transport); leaves the energy at x unchanged.
  virtual void prepare(const VectorXd& /*x*/) {}

 protected:
  RodLayout layout_;
};

/// EI/L² of the rod's stiffest section (N): the force scale of a rod under a moment alone, the
/// scale its solvers' residuals are measured against when no nodal load sets one.
inline double bending_force_scale(const Rod& rod) {
  double ei = 0.0;
  for (const auto& section : rod.layout().section) ei = std::max(ei, section.EI);
  const double L = rod.layout().total_length();
  return ei / (L * L);
}

}  // namespace vessel::msm::rods
