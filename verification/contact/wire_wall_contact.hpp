#pragma once
/// A rod (any msm::Form, with its own equality constraints or none) inside a linear elastic wall,
/// the contact between the wire's surface and the wall's inner surface found by the solve.
///
/// The wire's surface is a capsule: the tube of radius r_w around its centreline polyline, closed
/// by hemispheres at its ends (the rounded tip). The contact slaves are wall nodes, the wall
/// condensed on all three displacement components of each (every_component), so a node's
/// position is P_j = X_j + u_j with u_j = Σ_l W_jl n_l λ_l its whole displacement; n_j is the
/// unit direction a contact force pushes node j (out of the lumen, fixed: the wall is linear).
/// Node j's gap is its signed distance to the capsule,
///   g_j = σ_j |P_j − c_j(x)| − r_w,
/// c_j the centreline point nearest P_j (on a segment, or an end node: the tip's hemisphere); the
/// side σ_j starts at +1 (every node outside the wire at the start) and is followed from step to
/// step, σ_j = sign((P_j − c_j)·ν_j,last), so it turns −1 once the centreline has been carried past
/// the node, which then counts as inside (an unsigned distance would find it outside, on the
/// wire's far side). The wall pushes the wire with −λ_j n_j at c_j (split between the segment's
/// nodes as c_j is), the wire pushes the wall with +λ_j n_j at node j, so the forces are equal
/// and opposite by construction. Frictionless and
/// one-sided, g ≥ 0, λ ≥ 0, λ·g = 0, to first order in the angle between n_j and the capsule's
/// normal ν_j = σ_j (P_j − c_j)/|P_j − c_j| (zero where the surfaces touch tangentially).
///
/// Equilibrium: ∇E(x) + J_c(x)ᵀμ + Σ_k λ_k B_k(x)ᵀ n_k = 0 on the free dofs, c(x) = 0, and
/// Signorini's conditions on every candidate. Solved by sequential linearisation: each step
/// linearises the rod's rows and the gaps about (x, μ, λ), condenses the rod onto the
/// candidates' gaps and solves that Signorini problem exactly (solve_signorini), so which
/// candidates touch is decided over all of them at once at every step; each step is cut so no
/// centreline or wall node moves by more than max_move · r_w.
#include <Eigen/Dense>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "msm/form/equality_constraints.hpp"
#include "msm/form/form.hpp"
#include "msm/rods/rod.hpp"
#include "verification/contact/condensed_wall.hpp"

namespace vessel::contact {

/// The wire: its Form, constraints (or nullptr), held dofs and the centreline's material nodes
/// first_node..last_node (positions are the first 3 × num_nodes dofs of x, ghost nodes included;
/// the frames' dofs follow).
struct ContactWire {
  const msm::Form* form = nullptr;
  const msm::EqualityConstraints* constraints = nullptr;
  std::vector<char> fixed;
  int num_nodes = 0;
  int first_node = 0;
  int last_node = 0;
  double radius = 0.0;  ///< r_w, m
  /// Maps each Newton iterate back onto part of the constraints (CORDE's unit quaternions); may
  /// be empty.
  std::function<void(Eigen::VectorXd&)> project;
};

/// A rod model as the contact's wire: its energy, its own constraints and projection, its clamps,
/// its centreline's material nodes, and the radius r_w (m) of its surface. The rod must outlive
/// the result.
ContactWire contact_wire(const msm::rods::Rod& rod, double radius);

struct WireWallOptions {
  double tolerance = 1e-10;      ///< on ‖rod residual‖ (free dofs) relative to force_scale
  double force_scale = 1e-3;     ///< N
  double gap_tolerance = 1e-13;  ///< m: |g| of a pressed candidate; −g beyond it penetrates
  double constraint_tolerance = 1e-14;  ///< on max |c_k|
  /// A step is cut so that no centreline node and no contact node moves by more than
  /// max_move × r_w (the gaps are linearised about a surface of curvature 1/r_w).
  double max_move = 0.5;
  /// k (N/m): 0 for Signorini's conditions; above 0, the penalty law λ_j = k max(0, −g_j).
  double penalty_stiffness = 0.0;
  int max_newton = 200;  ///< linearised steps (each a Signorini solve)
};

struct WireWallSolution {
  Eigen::VectorXd x;                ///< the wire's dofs
  Eigen::VectorXd force;            ///< λ per contact node, N (zero where not in contact)
  std::vector<Vec3> direction;      ///< n per contact node (the direction its force pushes it)
  std::vector<Vec3> normal;         ///< ν per contact node: the capsule's normal towards it
  Eigen::VectorXd gap;              ///< g per contact node at the solution, m
  Eigen::VectorXd rod_multipliers;  ///< μ of the wire's own constraints
  std::vector<int> active;          ///< candidates in contact
  int active_set_changes = 0;       ///< steps whose contact set differed from the last step's
  int newton_iterations = 0;        ///< linearised steps (each a Signorini solve)
  double residual = 0.0;            ///< ‖rod residual‖ on free dofs at the end, N
  double seconds = 0.0;
  /// Σ_j λ_j n_j: the wire's total force on the wall, N.
  [[nodiscard]] Vec3 total_force_on_wall() const;
  /// λ_j n_j stacked per component (3 per contact node, N): the CondensedWall's forces, so
  /// wall.displacement(wall_loads()) is the wall's displacement field.
  [[nodiscard]] Eigen::VectorXd wall_loads() const;
};

/// Equilibrium of the wire inside the wall from `start` (e.g. a rigid-wall solution), its forces
/// starting at zero. `wall`: condensed on every_component of the contact nodes; `directions`:
/// per contact node, n_j (into_wall_directions). `initial_active` (candidate indices) only seeds
/// the count of contact-set changes: the first step's Signorini solve chooses the contacts over all
/// candidates. Throws std::runtime_error naming the contact set's size and the residuals without
/// convergence in options.max_newton steps; std::invalid_argument for a wire without a form, a
/// non-positive radius, nodes outside x, a wall not condensed on every component or directions of
/// the wrong count.
WireWallSolution solve_wire_wall_contact(const ContactWire& wire, const CondensedWall& wall,
                                         const std::vector<Vec3>& directions, const TetMesh& mesh,
                                         const Eigen::VectorXd& start,
                                         const std::vector<int>& initial_active,
                                         const WireWallOptions& options = {});

/// Growing the candidates: after each solve, the surface group's nodes that share a triangle
/// with a pressed candidate, and those the displaced wall brings within `margin` of the wire's
/// surface, join; the wall is condensed again and the contact re-solved from the last
/// equilibrium, until nothing joins.
struct BandGrowth {
  std::string surface_group = "inner_wall";
  double margin = 0.0;  ///< m
  int max_rounds = 8;
  /// m: where a solve on the band stops with the wire through the wall beyond it (the potential's
  /// WireThroughWall on a triangle not all of whose nodes are in the band), the surface nodes
  /// this near the crossing join.
  double crossing_reach = 0.5e-3;
};

/// The surface nodes (`surface`, its `triangles`) that join a band of candidates: the neighbours
/// outside it of a pressed node (mesh indices) on its edge, and the nodes outside it that the
/// wall displaced by `displacement` (per mesh node, m) brings within `margin` of the wire's
/// surface at x. Ascending.
std::vector<int> joining_the_band(const TetMesh& mesh, const std::vector<Triangle>& triangles,
                                  const std::vector<int>& surface, const std::vector<int>& band,
                                  const std::vector<int>& pressed, const ContactWire& wire,
                                  const Eigen::VectorXd& x, const std::vector<Vec3>& displacement,
                                  double margin);

struct GrownContact {
  WireWallSolution solution;  ///< indices into `nodes`; steps, changes, seconds over all rounds
  std::vector<int> nodes;     ///< the final candidates' mesh nodes
  std::unique_ptr<CondensedWall> wall;  ///< condensed on every component of `nodes`
  int rounds = 0;                       ///< growths
  /// The pressed candidates as mesh nodes, with their forces λ (N), in the active set's order.
  void pressed(std::vector<int>& mesh_nodes, std::vector<double>& forces) const;
};

/// solve_wire_wall_contact on candidates `nodes` (the wall condensed on every component,
/// directions from into_wall_directions on growth.surface_group), the band grown as BandGrowth says
/// until no pressed candidate lies on its edge and no other surface node comes within the margin.
/// `system` as CondensedWall's. std::runtime_error after growth.max_rounds growths that still add
/// nodes.
GrownContact solve_wire_wall_contact_growing(
    const ContactWire& wire, const fem::FreeDisplacementSystem& system, const TetMesh& mesh,
    std::vector<int> nodes, const Eigen::VectorXd& start, const std::vector<int>& initial_active,
    const WireWallOptions& options, const BandGrowth& growth = {});

/// A point's gap to the wire's capsule at x: its distance to the centreline polyline
/// first_node..last_node less r_w, m (negative inside the wire). For checking wall points that
/// are not candidates (a band too narrow lets the wire pass through them unseen).
double capsule_gap(const ContactWire& wire, const Eigen::VectorXd& x, const Vec3& point);

/// The force the clamp exerts on the wire (N): on each held node's position the balance of the
/// rod's internal force −∇E, the wall's −λ_k n_k share and the constraint force −J_cᵀμ, summed
/// over the held nodes: R = Σ_held (∇E + Σ_k λ_k B_kᵀ n_k + J_cᵀμ).
Vec3 clamp_reaction(const ContactWire& wire, const CondensedWall& wall, const TetMesh& mesh,
                    const WireWallSolution& solution);

/// Per candidate, the unit direction that points out of the lumen: the negated mean of the
/// outward normals of `surface_group`'s triangles at the node, area-weighted. InputError unless
/// every candidate is a node of the group's triangles.
std::vector<Vec3> into_wall_directions(const TetMesh& mesh, const std::vector<int>& nodes,
                                       const std::string& surface_group);

}  // namespace vessel::contact
