#pragma once
/// Every vessel model in the same wire–wall contact problem: a guidewire scene's wire (Discrete
/// Elastic Rods at the scene's segments, clamped as the scene clamps it, at a chosen EI) in the
/// straight tube or the arch against each model's wall (model_walls.hpp), the contact between the
/// wire's capsule and the inner wall found by the solve (the wire and the wall as one potential,
/// solve_wire_wall_potential_growing; or the active set, solve_wire_wall_contact_growing), on one
/// tet mesh refined around the rigid wire's contact: every model and the reference (FEM P2 on the
/// same mesh) are solved on the same mesh, the same candidates' growth and the same contact law,
/// so their contact forces compare.
#include <ostream>
#include <optional>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "verification/contact_models/model_walls.hpp"
#include "verification/scene.hpp"

namespace vessel::contact {

struct ContactModelsOptions {
  /// EI (N·m²) of each run: the scene wire's E (and G) scaled, its section kept. Empty: the
  /// scene's own wire.
  std::vector<double> bending_stiffness;
  double fine_size = 0.08e-3;   ///< m: the mesh's element size near the rigid contact
  double fine_radius = 1.0e-3;  ///< m: the refined patch's radius around the rigid contact
  /// m: the element size along the band the wire may bear on (bearing_band: a stiff wire bears
  /// along its body, far from its rigid contact, where coarser walls let it through; 0: not
  /// refined there)
  double bearing_band_size = 0.16e-3;
  double band_radius = 0.5e-3;  ///< m: the first candidates, inner-wall nodes this near it
  int reference_degree = 2;     ///< the reference wall: FEM of this degree (deal.II)
  int max_newton = 400;         ///< per contact solve (each growth round)
  double max_move = 0.5;        ///< WireWallOptions::max_move
  /// false: every wall linearised at rest (see active_set for how its contact is solved).
  /// true: every model at its own equilibrium (its own nonlinear energy,
  /// FormWall) and the reference at finite strain (the neo-Hookean FEM), each with the wire as one
  /// potential (wire_wall_potential.hpp); every inner-wall node a candidate.
  bool own_equilibrium = false;
  /// At own equilibrium, each EI after the first is solved from the wall's equilibrium at the EI
  /// before, through EI rungs a factor √10 apart (the same mesh; from rest only if a rung fails):
  /// a stiffer wire dents a soft wall by millimetres, which Newton from the wall at rest may not
  /// reach. false: every EI from rest.
  bool from_softer_wire = true;
  /// At own equilibrium with a P2 reference: its equilibrium is first solved on P1 (the same mesh,
  /// from P1's own equilibrium at the EI before where there is one), and P2 from there (P1's
  /// wire, P1's field at P2's nodes); P2 as without it only if that fails. A P1 factorisation
  /// takes ~0.3 s against P2's 10–13 s on the contact meshes. It pays in the arch (EI 4e-7: P2
  /// from P1's state converges in 46 steps, from rest it had not in 50) and not on the straight
  /// tube's stiffer wires (EI 4e-6: 1.5e-3 N after 25 steps, where P2 alone converges through
  /// its rung in 55), so it is asked for.
  bool p2_from_p1 = false;
  /// For walls linearised at rest. false: each wall with the wire as one potential on the wall
  /// condensed on a band of candidates grown from the first (condensed_wall_potential.hpp): an
  /// energy line search, a wire through the wall refused. true: the active set on the condensed
  /// wall (wire_wall_contact.hpp), the second formulation, which loses contacts the potential
  /// holds (the arch's buckled wire, whose force hardly changes with its shape; most walls at
  /// EI 4e-6 on the straight tube's band-refined mesh).
  bool active_set = false;
  /// Threads of the reference wall's sparse factorisations and solves (CHOLMOD's BLAS,
  /// set_solver_threads). The models' walls are solved on one thread whatever this is, so their
  /// times are comparable with each other and with a run's.
  int reference_threads = 1;
  /// One line per wall and EI as it is solved, and an own-equilibrium solve's progress (per
  /// round and per 25 Newton steps), if set
  std::ostream* log = nullptr;
};

/// ModelContact::linearisation of a wall solved at its own equilibrium.
inline constexpr const char* kOwnEquilibrium = "own equilibrium";

/// One wall's contact with the wire.
struct ModelContact {
  std::string name;
  std::string detail;
  std::string linearisation;  ///< to_string(WallLinearisation), or kOwnEquilibrium
  /// The wall's energy is quadratic: linearised at rest, or a linear FEM model (whose own
  /// equilibrium is its linearisation) under own_equilibrium.
  bool linear_wall = false;
  std::string failure;                ///< empty when solved
  /// |Σλn|: the net force the wire puts on the wall, N (a zone whose normals fan out round the
  /// wire presses harder node by node than its sum, Σλ, says).
  double force = 0.0;
  Vec3 force_on_wall = Vec3::Zero();  ///< Σλn, N
  int pressed = 0;
  int candidates = 0;            ///< after growth
  int rounds = 0;                ///< growths
  Vec3 centroid = Vec3::Zero();  ///< force-weighted mean rest position of the pressed nodes, m
  double axial_extent = 0.0;     ///< span of the pressed nodes along the vessel's centreline, m
  double circumferential_extent = 0.0;  ///< their span around it, as arc length at the lumen, m
  double dent = 0.0;                    ///< the largest displacement of a pressed node, m
  /// The wall's largest principal strain: small strain from the P1 gradient of the vertex
  /// displacements (linearised walls), the wall's own measure at its own equilibrium.
  double strain = 0.0;
  /// At its own nonlinear equilibrium, the tets the wall carries that are inverted there
  /// (WallPotential::inverted_tets; 0 for the finite-strain FEM, whose energy forbids it);
  /// nothing for a linearised wall or a wall without tets.
  std::optional<std::size_t> inverted_tets;
  Vec3 tip = Vec3::Zero();              ///< the wire's tip, m
  /// own_imbalance at the dent: the share of the contact load the model's own (nonlinear) energy
  /// does not balance there (0 for deal.II's FEM).
  double own_imbalance = 0.0;
  int steps = 0;  ///< Newton steps over every round (and every EI rung from the softer wire)
  /// solved from the wall's equilibrium under the softer wire of the EI before (own_equilibrium)
  bool from_softer_wire = false;
  double setup_seconds = 0.0;  ///< the model's stiffness and its condensation (every round), s
  double solve_seconds = 0.0;  ///< the contact solves, s
};

/// All walls at one EI.
struct ContactModelsRun {
  double bending_stiffness = 0.0;        ///< N·m²
  double rigid_force = 0.0;              ///< the same wire against the rigid lumen, N
  Vec3 rigid_wall_point = Vec3::Zero();  ///< the wall under the wire's contact node, m
  ModelContact reference;                ///< FEM P(reference_degree)
  std::vector<ModelContact> models;
};

struct ContactModels {
  std::size_t mesh_nodes = 0, mesh_tets = 0;
  double nu = 0.0;
  std::vector<ContactModelsRun> runs;  ///< one per EI
};

/// The solved models of `run` whose wall has inverted tets at its own equilibrium, each as "name
/// (count)", comma-separated; empty if none. Such a wall has folded: its force is not an elastic
/// wall's.
std::string folded_walls(const ContactModelsRun& run);

/// The solved linear walls of `run` (ModelContact::linear_wall; the reference's included) whose
/// dent exceeds the wall's thickness `wall_thickness` (m), each as "name (dent in mm)",
/// comma-separated; empty if none. A linear wall dented through its thickness is far beyond its
/// validity.
std::string linear_walls_dented_through(const ContactModelsRun& run, double wall_thickness);

/// Whether the model has a wall the wire can press: not a network, an external program, given
/// displacements or a surface model on the outer wall.
bool has_contact_wall(const ModelSpec& model);

/// Whether two models press the wire with the same wall: they differ at most in what the
/// contact solve does not read (their names, solvers, damping and regions of interest), as
/// recommend's candidates of one model under several solvers and radii do. The contact solve
/// solves such a wall once.
bool same_contact_wall(const ModelSpec& a, const ModelSpec& b);

/// The scene's models and the model kinds the suite runs that the scene lacks, one each: the
/// spring networks (seed001, van-gelder), the hybrid volume model, the edge pairs, corotational P1,
/// XPBD FEM, the surface models (seed 000 on the mid-surface and on the inner wall, Discrete Shells
/// on the mid-surface) and FEM P1. Models without a contact wall (has_contact_wall) are left out.
std::vector<ModelSpec> contact_model_kinds(const Scene& scene);

/// The scene's wire (a guidewire load in the straight tube or the arch) against every wall of
/// `models` and the reference's, at each EI, at the scene's first ν. InputError naming the scene's
/// file for a scene without a guidewire or a vessel that is neither. A model whose contact solve
/// fails is recorded with its reason (ModelContact::failure) and the others go on.
ContactModels solve_contact_models(const Scene& scene, const std::vector<ModelSpec>& models,
                                   const ContactModelsOptions& options);

}  // namespace vessel::contact
