#pragma once
/// Position-based dynamics constraints of seed 002 (Cheng et al., Sci China Inf Sci 2018) with
/// XPBD compliance (Macklin, Müller & Chentanez 2016) so that stiffness is in physical units and
/// independent of the iteration count.
#include <array>
#include <functional>
#include <vector>

#include "msm/form/form.hpp"
#include "msm/topology/springs.hpp"

namespace vessel::msm {

enum class ConstraintType {
  stretch,   ///< seed 002: C_len = |p_i − p_j| − |p_i⁰ − p_j⁰|
  dihedral,  ///< seed 002: C_dih = acos(n1·n2/(|n1||n2|)) − φ0', n1 = (p_j−p_i)×(p_k−p_i),
             ///< n2 = (p_j−p_i)×(p_n−p_i)
  angle,     ///< seed 002: C_angle = acos((p_i1−p_j1)·f_ext/(|p_i1−p_j1||f_ext|)) − φ0
};

struct Constraint {
  ConstraintType type = ConstraintType::stretch;
  std::array<int, 4> nodes{};  ///< stretch/angle: 2 used (i, j); dihedral: (i, j, k, n)
  double rest = 0.0;           ///< rest length (m) or rest angle (rad)
  /// XPBD compliance α: 1/k for stretch (m/N), 1/k_θ for the angles (1/(N·m)). 0: rigid (PBD).
  double compliance = 0.0;
  Vec3 direction = Vec3::Zero();  ///< angle constraint: the external force f_ext (any length)
};

/// C and its gradient with respect to the constraint's nodes (2 or 4 of them).
struct ConstraintValue {
  double C = 0.0;
  int count = 0;
  std::array<Vec3, 4> grad{};
  bool valid = true;  ///< false where the gradient is undefined (degenerate geometry)
};

ConstraintValue evaluate(const Constraint& c, const VectorXd& x);

/// The seed's closed-form PBD corrections (eq. 2 with equal masses), for tests and reference.
/// Stretching: Δp_i = −(|p_i − p_j| − l0)/2 · (p_i − p_j)/|p_i − p_j|, Δp_j = −Δp_i.
Vec3 seed002_stretch_correction(const Vec3& pi, const Vec3& pj, double rest_length);
/// Simplified angle: with a = |p_i1 − p_j1||f|, b = (p_i1 − p_j1)·f,
/// Δp_i1 = (acos(b/a) − φ0)/(2√(a² − b²)) · (|p_i1 − p_j1|² f − b (p_i1 − p_j1)), Δp_j1 = −Δp_i1.
/// (The seed prints "cos" in C_angle and "α cos" here; its Δp is that of acos, used throughout.)
Vec3 seed002_angle_correction(const Vec3& pi, const Vec3& pj, const Vec3& f, double rest_angle);

struct PbdConstraintOptions {
  bool stretch = true;
  bool dihedral = true;             ///< bending by the dihedral angle (one per interior edge)
  bool angle = false;               ///< the seed's simplified angle constraint instead/in addition
  double bending_compliance = 0.0;  ///< 1/(N·m)
  double angle_compliance = 0.0;    ///< 1/(N·m)
};

/// Constraints of a surface network: a stretch constraint per structural spring with compliance
/// 1/k (k from its stiffness rule), a dihedral constraint per interior triangle edge, and an angle
/// constraint per structural spring at each node carrying an external force (`loads`, N per node).
std::vector<Constraint> build_pbd_constraints(const SpringNetwork& net,
                                              const std::vector<Vec3>& loads,
                                              const PbdConstraintOptions& options);

struct PbdOptions {
  double dt = 1e-3;  ///< s
  int steps = 100;
  int iterations = 10;            ///< Gauss–Seidel sweeps per step
  double velocity_damping = 0.0;  ///< fraction of the velocity removed per step, [0, 1)
  /// Divergence when the kinetic energy exceeds blowup_factor × ‖f_ext‖·(model diagonal), an
  /// upper bound of what the loads can supply over the model's size, or × the kinetic energy
  /// after the first step (which releases any initially violated constraint).
  double blowup_factor = 1e3;
  /// Called after every step with (step, x); may be empty.
  std::function<void(int, const VectorXd&)> on_step;
};

struct PbdResult {
  VectorXd x;
  VectorXd v;
  int steps = 0;
  double seconds = 0.0;
  double max_violation = 0.0;  ///< max |C| of the stretch constraints at the end, m
};

/// XPBD time stepping (Macklin et al. 2016): predict x* = x + h v + h² M⁻¹ f_ext, then per
/// iteration and constraint Δλ = (−C − α̃λ)/(Σ w|∇C|² + α̃), α̃ = α/h², Δx = w ∇C Δλ; v = Δx/h.
/// Fixed dofs (problem.fixed) have zero inverse mass. Throws InputError for dt ≤ 0, iterations
/// < 1, damping outside [0, 1); DivergenceError on a non-finite value or a kinetic-energy blow-up.
PbdResult run_pbd(const Problem& problem, const std::vector<Constraint>& constraints,
                  const PbdOptions& options, const VectorXd& x0 = VectorXd());

}  // namespace vessel::msm
