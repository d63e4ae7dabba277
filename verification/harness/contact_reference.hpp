#pragma once
/// The contact reference of a guidewire scene: the scene's wire (DER, the scene's segments) and its
/// wall (linear FEM, the scene's material and supports) solved together, the contact between the
/// wire's surface and the wall's found by the solve (verification/contact/wire_wall_contact.hpp),
/// on the wall meshed at several refinement levels around the contact zone, with the contact
/// force's Richardson extrapolate and grid convergence index (fem_reference/convergence.hpp).
///
/// The zone is found in two passes: the rigid-wall solve gives the wall point under the wire's
/// contact node; a scout solve on the coarsest level's mesh refined there gives the pressed zone;
/// every level is then meshed with refined_patch_mesh around the zone's middle (fine size
/// coarsest_size / ratio^level within the zone's reach from its middle plus a margin, graded to
/// the scene's nominal size over 2 mm). Candidates: the inner-wall nodes within `band` of the
/// rigid-wall wire's surface inside the refined ball, grown by solve_wire_wall_contact_growing.
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "fem_reference/convergence.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/tet_mesh.hpp"
#include "verification/contact/wire_wall_potential.hpp"
#include "verification/scene.hpp"

namespace vessel {

struct ContactReferenceOptions {
  ContactWall wall = ContactWall::linear;
  int levels = 3;  ///< refinement levels (three give an observed order)
  /// m: the fine size around the zone at level 0 (at 0.16 mm, near the wire's radius 0.178 mm,
  /// the capsule passes between the nodes of the shipped scenes' wall)
  double coarsest_size = 0.08e-3;
  double ratio = 1.4142135623730951;  ///< fine size ratio between levels (> 1): √2
  /// The wall's elements, P1 or P2 (P2 at 0.08 mm takes 2–3 minutes a level on this machine)
  int degree = 1;
  double margin = 0.3e-3;  ///< m: the refined ball's radius beyond the zone's half extent
  double band = 0.5e-3;    ///< m: candidates within this of the rigid-wall wire's surface
  /// the linear wall's validity: largest strain at most this (the neo-Hookean wall has no limit)
  double strain_limit = 0.1;
  /// A reference's GCI on the force (relative) at most this: levels whose GCI is larger bound the
  /// force no better than that (not yet in the asymptotic range) and are not a reference
  double gci_limit = 0.2;
  int max_steps = 300;  ///< linearised contact steps per solve
  /// The neo-Hookean wall: a stiffer wire is reached by raising EI from this (N·m²) in steps of
  /// continuation_ratio, each solved from the last one's equilibrium (4e-7: the floppy wire of
  /// the shipped scenes, which Newton reaches from the rigid-lumen state on their 14.24 kPa wall)
  double continuation_from = 4e-7;
  double continuation_ratio = contact::kContinuationRatio;
  /// The neo-Hookean wall: each solve after the first starts at the target EI from the solve
  /// before's equilibrium (its wall interpolated onto the new mesh), the rungs only if that
  /// fails; false: every solve climbs the rungs from the wall at rest.
  bool from_previous_solve = true;
  /// The neo-Hookean P2 wall: each level solved from P1's equilibrium on its mesh (P1 climbing
  /// the EI rungs from the wall at rest, a P1 factorisation a fortieth of P2's time), P2's own
  /// path (from the solve before, else the rungs) where that fails.
  bool p1_start = false;
  /// Threads of the wall's factorisations (CHOLMOD's BLAS; set_solver_threads) over the solve,
  /// the process's setting restored after it
  int threads = 1;
  std::ostream* log = nullptr;  ///< one line per solve (mesh, candidates, result), if set
};

/// One level's contact solve.
struct ContactLevel {
  int level = 0;
  double fine_size = 0.0;  ///< m
  int mesh_nodes = 0;
  int candidates = 0;  ///< after growth
  bool converged = false;
  std::string failure;           ///< why not, when not converged
  int pressed = 0;               ///< wall nodes in contact
  double force = 0.0;            ///< |Σ λ_j n_j|, the wire's total force on the wall, N
  Vec3 centroid = Vec3::Zero();  ///< force-weighted mean of the pressed nodes' rest positions, m
  double extent = 0.0;           ///< largest distance between two pressed nodes, m
  Vec3 middle = Vec3::Zero();    ///< midpoint of the two pressed nodes farthest apart, m
  double reach = 0.0;            ///< largest distance of a pressed node from `middle`, m
  double dent = 0.0;             ///< largest displacement of a pressed node, m
  /// largest principal strain over the wall: small strain from the P1 gradient of the vertex
  /// displacements (linear wall), Green–Lagrange at the quadrature points (neo-Hookean wall)
  double strain = 0.0;
  bool zone_inside_patch = true;  ///< every pressed node within the refined ball
  int steps = 0;         ///< linearised steps over all growth rounds or rungs (0 if not converged)
  int rungs = 0;         ///< the neo-Hookean wall's stiffness continuation: solves to reach the EI
  /// The neo-Hookean wall's climb stopped at this softer rung's EI (N·m²), whose dent (`dent`,
  /// `strain`: that rung's) was already wider than the lumen; the level is not converged
  std::optional<double> gave_way_at;
  /// the neo-Hookean wall solved at the EI from the solve before (a coarser level's or the
  /// ungrown patch's equilibrium, interpolated onto this mesh), not from the wall at rest
  bool from_previous_solve = false;
  /// the P2 wall solved at the EI from P1's equilibrium on this mesh (ContactReferenceOptions::
  /// p1_start); `steps` and `rungs` count P1's too
  bool from_p1 = false;
  double seconds = 0.0;  ///< meshing, condensing and solving this level
};

struct ContactReference {
  std::string scene;
  double bending_stiffness = 0.0;  ///< EI, N·m²
  double wall_modulus = 0.0;       ///< Pa
  double poisson_ratio = 0.0;
  double rigid_force = 0.0;                     ///< the same discrete wire on the rigid lumen, N
  std::optional<double> continuum_rigid_force;  ///< the continuum wire's (closed form), N
  Vec3 rigid_wall_point = Vec3::Zero();         ///< m
  Vec3 patch_centre = Vec3::Zero();             ///< m: where every level is refined
  double patch_radius = 0.0;                    ///< m
  /// Balls refined along a scout wire that passed between the wall's nodes (0: none)
  int refined_along_wire = 0;
  /// Times the patch was grown to a level's zone that left it, and the levels solved again
  int patch_growths = 0;
  double strain_limit = 0.0;
  ContactWall wall = ContactWall::linear;
  int degree = 1;      ///< the wall's element degree
  ContactLevel scout;  ///< the coarsest size at the rigid wall point: where the zone is
  std::vector<ContactLevel> levels;
  /// From the three finest levels when all converged: Roache's order and GCI on the force.
  std::optional<fem::GciOrder> order;
  std::optional<fem::RichardsonEstimate> estimate;
  /// "reference", "no reference: the wall does not hold this wire (...)", "did not converge
  /// (...)", "beyond the linear wall's validity (largest strain ...)", "not a reference: the
  /// contact zone leaves the refined patch", "one level: ..." (no convergence estimate) or "not
  /// a reference: the levels' GCI ... is above ...": what the finest level's force may be used
  /// as.
  std::string verdict;
  [[nodiscard]] bool is_reference() const { return verdict == "reference"; }
};

/// The contact reference of `scene`'s guidewire at bending stiffness EI (N·m²; E and G scaled,
/// with_stiffness), against the scene's wall at its first Poisson's ratio: the scout, then
/// solve_contact_levels. InputError naming the scene's file for a scene without a guidewire load,
/// a vessel from a file, EI ≤ 0 or not finite, or options out of range. A level whose solve does
/// not converge is reported, not thrown.
ContactReference solve_contact_reference(const Scene& scene, double EI,
                                         const ContactReferenceOptions& options = {});

/// Where a scout refines after its wire's centreline (its nodes, m) crossed the inner wall: the
/// rest positions of the crossed triangle's nodes (`through`, mesh indices, if known; the wall
/// material the wire passed through, however far the wall was pushed), then for each centreline
/// node within kBearingBandNearWall of the undeformed inner wall the nearest inner-wall node (the
/// centreline lies beyond the dented wall, up to ~0.7 mm off the nodes it presses).
std::vector<Vec3> crossed_wire_refinement(const TetMesh& mesh, const std::vector<Vec3>& centreline,
                                          const Triangle* through);

/// A level's solve: its mesh refined to `fine` (m) in the balls, the patch first.
using ContactLevelSolve =
    std::function<ContactLevel(double fine, const std::vector<RefinedBall>& balls)>;

/// A level whose zone leaves the refined patch grows the patch to that zone and the levels are
/// solved again from the first, at most this many times (every level shares the patch; a zone
/// that leaves it after that makes the verdict "not a reference").
inline constexpr int kContactPatchGrowths = 2;

/// The levels of a reference whose scout is solved (`r.scout`, `r.patch_centre`,
/// `r.patch_radius`): level l at options.coarsest_size / options.ratio^l by `solve`, on `balls`.
/// A converged level whose zone leaves the patch grows the patch to it (the ball inserted first)
/// and the levels are solved again from the first, up to kContactPatchGrowths times. The first
/// converged solve, the scout's included, whose dent is wider than the lumen (2 × lumen_radius, m)
/// ends them, kept as the last level: the wall does not hold the wire and no finer level changes
/// that verdict (judge_contact_reference's first rule).
void solve_contact_levels(const ContactReferenceOptions& options, double lumen_radius,
                          std::vector<RefinedBall> balls, const ContactLevelSolve& solve,
                          ContactReference& r);

/// Sets the levels' Roache order, Richardson estimate and GCI on the force (every level
/// converged, two or more) and the verdict, in this order of precedence: a converged level or
/// scout whose dent is wider than the lumen (2 × lumen_radius, m), or one whose climb stopped at a
/// softer rung with such a dent (ContactLevel::gave_way_at: a stiffer wire presses the wall
/// further), makes it "no reference: the wall does not hold this wire"; a level that did not
/// converge, "did not converge"; the linear wall's strain beyond `options.strain_limit`; a zone
/// outside the refined patch; a single level; a GCI above `options.gci_limit`.
void judge_contact_reference(const ContactReferenceOptions& options, double lumen_radius,
                             ContactReference& reference);

/// The stiffnesses a scene's contact reference is solved at: its wire's stiffness_sweep, or its
/// wire's own EI (N·m²). InputError naming the scene's file without a guidewire load.
std::vector<double> contact_reference_stiffnesses(const Scene& scene);

/// The reference as Markdown: a line with the scene, EI, the wall, the rigid-wall forces and the
/// refined patch; a table of the levels (mm, mN, seconds); the extrapolate, order and GCI; the
/// verdict.
void print_contact_reference(const ContactReference& reference, std::ostream& out);

}  // namespace vessel
