#pragma once
/// Seed 002's guidewire (Cheng et al. 2018), the CORDE rod of Spillmann & Teschner (SCA 2007):
/// centreline points P_i and one quaternion q_j per edge (its material frame d1, d2, d3). Energy:
///   bending and torsion  Σ_i (l̄_i/2) Σ_k K_k (Ω_i,k − Ω⁰_i,k)²,  Ω_i = (2/l̄_i) Im(q̄_{i−1} q_i)
///                        (the discrete Darboux vector, in q_{i−1}'s frame; K = (EI, EI, GJ)),
///   alignment penalty    Σ_j (κ/2) l_j |(P_{j+1} − P_j)/l_j − d3(q_j)|²,
/// constraints (Lagrange multipliers, EqualityConstraints):
///   inextensibility      C_j = |P_{j+1} − P_j|² − |P⁰_{j+1} − P⁰_j|² = 0 (Cheng et al.),
///   unit quaternions     |q_j|² − 1 = 0.
/// The penalty acts as a shear stiffness: under a tip force F it adds F·L/κ to the deflection, and
/// the frame follows the edge as 1/κ. A clamp's ghost edge carries the clamp's quaternion, half a
/// segment from the first edge's midpoint.
#include <Eigen/Geometry>
#include <functional>
#include <vector>

#include "msm/rods/constrained_newton.hpp"
#include "msm/rods/rod.hpp"

namespace vessel::msm::rods {

/// The discrete Darboux vector of two neighbouring frames q_a, q_b at a vertex of Voronoi length
/// l̄, with φ and n the angle and axis of q̄_a q_b:
///  - `quaternion`: (2/l̄) Im(q̄_a q_b) = (2 sin(φ/2)/l̄) n, the paper's (Spillmann & Teschner 2007);
///  - `rotation_vector`: (φ/l̄) n, the turning angle (a closed circle is exact; at coarse N it
///    bends less softly than 2 sin(φ/2): 1.9e-3 against 3.1e-3 L at α = 10, N = 16). Not the
///    paper's formula: name it so where it is used.
enum class DarbouxMeasure { quaternion, rotation_vector };

class CordeRod : public Rod, public EqualityConstraints {
 public:
  /// `alignment`: κ, N. Default (≤ 0): the section's shear stiffness 0.9·G·A (Timoshenko's
  /// coefficient of a solid circle), which makes CORDE a shearable Cosserat rod.
  /// `inextensible` false: the unit quaternions are the only constraints (the XPBD rod's energy,
  /// whose stretch is the alignment penalty's).
  CordeRod(RodLayout layout, double alignment = 0.0, bool inextensible = true,
           DarbouxMeasure measure = DarbouxMeasure::quaternion);

  [[nodiscard]] int num_dofs() const override;
  [[nodiscard]] double energy(const VectorXd& x) const override;
  void gradient(const VectorXd& x, VectorXd& g) const override;
  void hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const override;

  [[nodiscard]] int num_constraints() const override;
  void evaluate(const VectorXd& x, VectorXd& c) const override;
  void jacobian(const VectorXd& x, SparseMatrix& J) const override;
  void weighted_hessian(const VectorXd& x, const VectorXd& lambda, SparseMatrix& H) const override;

  [[nodiscard]] double alignment() const { return kappa_; }
  [[nodiscard]] bool inextensible() const { return inextensible_; }
  [[nodiscard]] DarbouxMeasure darboux_measure() const { return measure_; }
  /// Index of edge j's quaternion (w, x, y, z) in x.
  [[nodiscard]] int quaternion_dof(int edge) const { return 3 * num_nodes() + 4 * edge; }
  [[nodiscard]] VectorXd rest_state() const override;
  /// Scales every quaternion of x to unit length.
  void normalise_quaternions(VectorXd& x) const;
  /// Rod's hooks: its constraints are itself; a state is projected by normalise_quaternions.
  [[nodiscard]] const EqualityConstraints* constraints() const override { return this; }
  void project(VectorXd& x) const override { normalise_quaternions(x); }
  /// The ghost nodes, the clamp nodes and the ghost edges' quaternions.
  [[nodiscard]] std::vector<char> clamp_fixed() const override;
  /// ρA per half segment on the nodes; 4ρI l on each quaternion component (rotary inertia).
  [[nodiscard]] VectorXd lumped_mass() const override;
  /// The clamps' quaternion: d1 = the layout's normal, d3 = the rest tangent.
  [[nodiscard]] Eigen::Quaterniond clamp_frame() const { return frame0_; }

 private:
  double kappa_;
  bool inextensible_ = true;
  DarbouxMeasure measure_ = DarbouxMeasure::quaternion;
  Eigen::Quaterniond frame0_;
};

}  // namespace vessel::msm::rods
