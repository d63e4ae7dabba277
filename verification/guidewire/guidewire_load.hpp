#pragma once
/// The guidewire as the vessel's load: a Discrete Elastic Rod (msm/rods/der_rod.hpp), seed 002's
/// CORDE rod (msm/rods/corde_rod.hpp) with spec.model = WireModel::corde, the XPBD rod
/// (msm/rods/xpbd_rod.hpp, its steady state) with xpbd, or the user's program with external;
/// clamped at the inlet, inserted its length in steps, against the parametric vessel's lumen as a
/// rigid, frictionless, one-sided wall (msm/rods/rigid_wall.hpp: the centreline keeps a − r_wire from the
/// vessel's centreline). Its contact force and the wall point under its contact node become the
/// scene's contact patch load (`solve_guidewire_load` in verification/scene_problems.hpp, on the run path; parsing a scene only
/// checks the wire with `check_guidewire`).
///
/// Compliant coupling (`GuidewireSolver::coupled_force`): a linear wall of compliance C (its
/// displacement along the contact normal per unit force of the patch load) gives way by C·F under
/// the wire's force F. The wire is solved against the lumen grown by that give (the whole lumen's
/// offset, which equals a local give while the wire touches at one node), and F is found by a
/// secant on h(F) = F − F_wire(C·F). Limits: the wall is linear (its compliance measured once, at
/// the rigid wire's force), its give is normal to it at the rigid contact point, and the patch
/// stays where the rigid wire put it (the contact node slides along a frictionless wall by a
/// fraction of the give).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "meshes/vessel_geometry.hpp"
#include "msm/rods/rigid_wall.hpp"
#include "msm/rods/rod_layout.hpp"
#include "verification/guidewire/guidewire_spec.hpp"

namespace vessel {

class GuidewireSolver {
 public:
  /// InputError (naming `key_prefix`'s keys) for a vessel that is not parametric, a clamp outside
  /// the lumen or a spec out of range.
  GuidewireSolver(const VesselParams& vessel, const GuidewireSpec& spec,
                  const std::string& key_prefix = "load.");
  ~GuidewireSolver();
  GuidewireSolver(const GuidewireSolver&) = delete;
  GuidewireSolver& operator=(const GuidewireSolver&) = delete;

  /// The wire inserted in steps (each from the last shape) to the spec's insertion against the
  /// rigid lumen. Throws InputError naming `insertion` if it touches at more than one node.
  GuidewireSolution solve_rigid();
  /// The inserted wire against the lumen grown by `give` (m) along its normal, from the last
  /// solution (solve_rigid first).
  GuidewireSolution solve_with_give(double give);
  /// The wire inserted to `insertion` (m) against the rigid lumen from the last solution: one
  /// update of a simulator advancing the wire (solve_rigid first).
  GuidewireSolution solve_at_insertion(double insertion);
  /// model xpbd: one XPBD step of length h (s) of the last solution's rod, the update a
  /// simulator pays per frame (std::logic_error for another model or before a solve).
  GuidewireSolution step(double h);
  /// The wire's compliance at the contact, −dδ/dF by a central difference of solve_with_give
  /// (m/N), computed once per solve_rigid; restores the rigid state.
  double compliance();
  /// The force F (N) with F = F_wire(C·F): the wire against a wall of compliance C (m/N), by a
  /// secant to |h| ≤ 1e-12 F_rigid. Leaves the coupled solution in `last()`.
  double coupled_force(double wall_compliance);
  [[nodiscard]] const GuidewireSolution& last() const { return last_; }
  [[nodiscard]] const GuidewireSolution& rigid() const { return rigid_; }
  /// The last solve's whole rod state (positions, ghost nodes and frames' dofs, as the rod of
  /// guidewire_rod_spec at the solved length numbers them); empty for the external model.
  [[nodiscard]] const Eigen::VectorXd& rod_state() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  GuidewireSolution rigid_, last_;
  double compliance_ = 0.0;  ///< 0: not computed since the last solve_rigid
};

/// The rod of the spec at `length` (m): uniform, clamped at the spec's clamp point along its
/// clamp direction (the rod every GuidewireSolver solve builds).
msm::rods::RodSpec guidewire_rod_spec(const GuidewireSpec& spec, double length);

/// The spec with E (and G in proportion) scaled so its solid section has bending stiffness EI
/// (N·m²). InputError unless EI is positive and finite.
GuidewireSpec with_stiffness(GuidewireSpec spec, double EI);

/// The continuum wire (fem_reference/rod_theory) against the rigid lumen: its contact force and
/// the centreline's contact point.
struct WireReference {
  std::string what;     ///< which continuum solution, with its dimensionless numbers
  double force = 0.0;   ///< N
  Vec3 contact_point = Vec3::Zero();  ///< m
};

/// The continuum wire of `spec` in `vessel`; nullopt (and `why`) when its clamp is not in a pose
/// with one: on the straight tube's axis at the inlet, tilted into the tube (Kirchhoff shooting
/// at the wire's length: rod_theory::straight_tube_contact_distance), or tangential on the arch's
/// centreline at the inlet with the insertion that reaches the apex within 1e-3 (the quarter-wave
/// elastica: rod_theory::arch_apex_contact).
std::optional<WireReference> continuum_wire(const VesselParams& vessel, const GuidewireSpec& spec,
                                            std::string& why);

/// The inlet's clamp pose of the spec's tilt form: the inlet's centreline point and tangent,
/// turned by `tilt` towards `towards` (its part normal to the tangent). InputError naming
/// `load.tilt_towards` if that part is zero.
void set_tilted_clamp(const VesselParams& vessel, double tilt, const Vec3& towards,
                      GuidewireSpec& spec);

/// The checks that need no solve: InputError (naming `key_prefix`'s keys) for a vessel that is
/// not parametric, a wire wider than the lumen or a clamp outside it. Parsing a scene calls it;
/// the GuidewireSolver's constructor too.
void check_guidewire(const VesselParams& vessel, const GuidewireSpec& spec,
                     const std::string& key_prefix = "load.");

/// The parametric vessel's lumen for a centreline kept within `offset` (m) of the vessel's (the
/// inner wall itself at offset = inner radius): its gap is + inside, − beyond, ∇g of unit length.
std::unique_ptr<msm::rods::RigidLumen> rigid_lumen(const VesselParams& vessel, double offset);

/// The inner wall a wire clamped as `spec` says may bear on, as points on it at least `spacing`
/// (m) apart: under the two shapes that bracket a wire's on a deformable wall, its rigid-lumen
/// shape `rigid_state` (the wall infinitely stiff; the rod's `layout`) and the straight wire
/// along the clamp (the wire infinitely stiff), wherever they come within `near_wall` (m) of the
/// wall or beyond it; each point the radial projection onto the lumen's wall of a point sampled
/// `spacing` apart along a shape. A stiff wire straightens as a soft wall gives and bears along
/// its body, far from its rigid-lumen contact: a mesh refined along this band holds it.
std::vector<Vec3> bearing_band(const VesselParams& vessel, const GuidewireSpec& spec,
                               const msm::rods::RodLayout& layout,
                               const Eigen::VectorXd& rigid_state, double near_wall,
                               double spacing);
/// m: how near the wall the bracketing shapes count (bearing_band's near_wall), and the radius of
/// the ball the contact solves refine at each band point (the points half a ball apart).
inline constexpr double kBearingBandNearWall = 1.5e-3;
inline constexpr double kBearingBandBallRadius = 0.5e-3;

/// What solve_guidewire_load would run for `spec`, one line (for `vesselverify scene`, which
/// runs nothing).
std::string describe_guidewire_solve(const GuidewireSpec& spec);

}  // namespace vessel
