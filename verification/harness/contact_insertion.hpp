#pragma once
/// The wire pushed into the vessel in steps, quasi-statically, against a deformable wall: at each
/// insertion length the wire and the wall are solved together as one potential
/// (verification/contact/wire_wall_potential.hpp), each step from the last step's equilibrium
/// (the wire fed through the clamp to the new length, fed_through_clamp; the wall's displacement
/// kept), so contacts appear, slide and separate as the solve finds them.
///
/// The wall is meshed once, refined to `fine_size` within `refine_radius` of every point where
/// the same wire touches the rigid lumen over the insertion (sampled every quarter of that radius,
/// so the mesh follows the range, not the steps); a wire whose centreline crosses the wall (it
/// bears outside the refined balls) is a failed step.
///
/// Per step the hub's two forces: the clamp's axial force R·t (what a clamp holding the wire
/// bears) and the push P that advances it. A wire leaving a frictionless sleeve is drawn out of
/// it by M²/(2EI) (M its bending moment at the sleeve's exit: Bigoni et al., "Eshelby-like forces
/// acting on elastic structures", J. Mech. Phys. Solids 2015), so P = R·t − M²/(2EI), and by
/// virtual work P = dΠ/dL with Π the equilibrium's stored energy (wire and wall); both are
/// reported, the second by central differences between steps.
#include <Eigen/Core>
#include <array>
#include <ostream>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "msm/rods/rod_layout.hpp"
#include "verification/harness/contact_reference.hpp"
#include "verification/scene.hpp"

namespace vessel {

struct ContactInsertionOptions {
  ContactWall wall = ContactWall::neo_hookean;
  double first = 0.0;  ///< m: the first insertion length (0: 80 % of the scene's insertion)
  double last = 0.0;   ///< m: the last (0: the scene's insertion)
  int steps = 8;       ///< steps from first to last (steps + 1 solves)
  /// m: the wall's size where the wire may bear (below the wire's diameter, so the capsule
  /// cannot pass between the nodes)
  double fine_size = 0.1e-3;
  double refine_radius = 1.0e-3;  ///< m: the refined ball around each rigid-lumen wall point
  int degree = 1;                 ///< the wall's elements
  int max_steps = 300;            ///< Newton steps per insertion step
  /// m: the 3D view's step, the converged one nearest this length (0: the last converged)
  double view_at = 0.0;
  /// The wall: empty for the reference (deal.II's FEM as `wall` says), else the name of one of
  /// the scene's models, its own wall on the same mesh (a mass-spring or tet model's own energy,
  /// so its own nonlinear equilibrium; a linear FEM model's linear wall; contact_models/
  /// model_walls.hpp says how a surface model's thickness enters)
  std::string model;
  /// Threads of the reference wall's factorisations (CHOLMOD's BLAS; set_solver_threads). A
  /// model's wall is solved on one thread whatever this is, so its per-step times are a
  /// simulator's on one core. The process's setting is restored after the insertion.
  int reference_threads = 1;
  /// A linear P1 wall (the reference's with `wall` linear, a linear FEM model's) condensed on a
  /// band of contact candidates around the first contact, grown as the contact slides and kept
  /// from step to step (condensed_wall_potential.hpp: the same equilibrium, the Newton matrix 3
  /// rows per band node); false: the whole wall, factorised at every Newton step. A P2 wall is
  /// always whole (its mid-edge nodes are contact candidates too).
  bool condense_linear_walls = true;
  std::ostream* log = nullptr;  ///< per step a line, and the contact solve's progress, if set
};

/// One pressed region: pressed nodes closer than 1 mm to each other.
struct ContactZone {
  double force = 0.0;            ///< |Σ λ_j n_j| over its nodes, N
  Vec3 centroid = Vec3::Zero();  ///< force-weighted mean of its nodes' rest positions, m
  double extent = 0.0;           ///< largest distance between two of its nodes, m
  int nodes = 0;
};

struct InsertionStep {
  double insertion = 0.0;  ///< m: the wire's length beyond the clamp
  bool converged = false;
  std::string failure;
  double force = 0.0;  ///< |Σ λ_j n_j| over every pressed node, N
  int pressed = 0;
  std::vector<ContactZone> zones;
  double clamp_axial = 0.0;   ///< R·t: the clamp's force on the wire along the clamp direction, N
  double clamp_moment = 0.0;  ///< |M|: the clamp's moment on the wire about the clamp point, N·m
  double push = 0.0;          ///< R·t − M²/(2EI), N
  /// dΠ/dL by central differences of the neighbouring steps' energies (one-sided at the ends;
  /// NaN when a neighbour failed), N
  double push_by_energy = 0.0;
  double energy = 0.0;      ///< the wire's and the wall's stored energy at equilibrium, J
  Vec3 tip = Vec3::Zero();  ///< m
  double dent = 0.0;        ///< largest wall displacement of a pressed node, m
  std::vector<Vec3> centreline;  ///< the wire's nodes, clamp to tip, m
  int newton_steps = 0;
  double seconds = 0.0;
};

/// The wall where the wire bears at one step, for a 3D view: the inner wall's triangles with a
/// node within kInsertionViewReach of a pressed node.
struct InsertionView {
  int step = -1;                              ///< index into the steps (−1: none converged)
  std::vector<int> nodes;                     ///< mesh indices of the drawn nodes
  std::vector<Vec3> rest;                     ///< their rest positions, m
  std::vector<Vec3> displacement;             ///< their displacements, m
  std::vector<double> force;                  ///< the wire's contact force on each, N
  std::vector<std::array<int, 3>> triangles;  ///< into `nodes`
};

/// m: the drawn wall's reach from the pressed nodes.
inline constexpr double kInsertionViewReach = 2e-3;

struct ContactInsertion {
  std::string scene;
  std::string model = "reference";  ///< the wall's model ("reference": the FEM wall)
  std::string model_detail;         ///< what that wall is
  double bending_stiffness = 0.0;  ///< EI, N·m²
  ContactWall wall = ContactWall::neo_hookean;
  int mesh_nodes = 0;
  int refined_balls = 0;
  double mesh_seconds = 0.0;  ///< meshing and the wall's set-up
  double wire_radius = 0.0;   ///< m
  std::vector<InsertionStep> steps;
  InsertionView view;  ///< at the converged step options.view_at chooses
};

/// The start of an insertion step: the rod's dofs x at length `from_length` (m) pushed through its
/// clamp to `layout`'s length, as a pushed wire slides along its own path: each node where the
/// centreline was at the node's new arclength from the clamp (linear between the old nodes), past
/// the old tip along the tip's last edge; the ghost node and the frames' angles unchanged. A tip
/// the wall pushes on (`tip_push`, the wall's contact force on the tip's edge, N; zero: none)
/// goes on along the wall: the part of its edge's direction against that force is removed. The
/// rod's sections scale with its length (guidewire_rod_spec), so the old nodes' arclengths are
/// the new ones times from_length / length.
Eigen::VectorXd fed_through_clamp(const Eigen::VectorXd& x, const msm::rods::RodLayout& layout,
                                  double from_length, const Vec3& tip_push = Vec3::Zero());

/// The insertion of `scene`'s guidewire at bending stiffness EI (N·m²) against the scene's wall
/// (or options.model's) at its first Poisson's ratio. InputError naming the scene's file for a
/// scene without a guidewire load, a vessel from a file, EI ≤ 0, options out of range, a first
/// insertion beyond the last, or a model the scene does not have or the contact cannot carry. A
/// step that does not converge is reported, and the next starts from the last converged one.
ContactInsertion solve_contact_insertion(const Scene& scene, double EI,
                                         const ContactInsertionOptions& options = {});

/// The walls `names` asks for, as contact_insertion_document takes them: "reference" is "" (the
/// FEM wall), "all" is "" and each of the scene's models with a wall in the contact
/// (contact::has_contact_wall) in the scene's order, another name itself; each wall once.
std::vector<std::string> insertion_walls(const Scene& scene, const std::vector<std::string>& names);

class OutcomeCache;  // verification/harness/outcome_cache.hpp

/// The insertions of `scene`'s wire at each bending stiffness in `stiffnesses` (N·m²), against each
/// wall of `models` (options.model's meaning: "" the reference, else a model's name), as the JSON
/// document `vesselverify insertion --json` writes (schema "vesselverify.insertion", version 1:
/// verification/harness/contact_insertion.schema.json; SI units), which the report reads back
/// (reports/study_files.hpp) for its tables and curves. With a `cache`, each insertion is kept
/// under the scene file's text, its EI and the options (and the code and machine, as every
/// outcome): a repeated insertion is read back, its time the original solve's, and the document
/// says when that was. InputError as solve_contact_insertion.
std::string contact_insertion_document(const Scene& scene, const std::vector<double>& stiffnesses,
                                       const ContactInsertionOptions& options,
                                       const std::string& command, OutcomeCache* cache = nullptr,
                                       const std::vector<std::string>& models = {""});

/// One insertion as the document's entry (a JSON object), as contact_insertion_document writes it.
std::string contact_insertion_entry(const ContactInsertion& insertion);

}  // namespace vessel
