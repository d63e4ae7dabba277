#pragma once
/// The wire and the wall as one potential: a rod (DER) and a wall (linear, or the finite-strain
/// neo-Hookean FEM wall) pressed together, frictionless, the contact found by minimising
///   Π(x, u) = E_rod(x) + W_wall(u) + Σ_j ψ(g_j),  g_j = d(P_j, centreline(x)) − r_w,
/// over the wire's free dofs x and the wall's free displacements u. P_j = X_j + u_j is wall node
/// j's position, d its distance to the nearest segment of the wire's centreline (a hemisphere
/// at the ends: the wire's surface is a capsule of radius r_w); and as many pairs of the wire's
/// tip against each face of the inner wall (its three nodes candidates), d the distance of the
/// tip's centre to the face, so a wall that wraps round the tip between its nodes still meets its
/// hemisphere (point_triangle_distance.hpp). Signorini's conditions (g ≥ 0, λ ≥ 0, λg = 0) enter
/// through the augmented Lagrangian's term for multiplier estimates λ̂,
///   ψ(g) = max(0, λ̂ − k g)²/(2k),  −ψ'(g) = max(0, λ̂ − k g)
/// (shifted by λ̂²/(2k) so it vanishes where a node is open), with the exact Hessian of the gap
/// (point_segment_distance.hpp). Three laws (ContactLaw):
/// - Alart–Curnier (the default): the multipliers are unknowns beside z, solved by one
///   semismooth Newton iteration on ∇E − Σ λ_j ∇g_j = 0 and λ_j = max(0, λ_j − k g_j)
///   (Alart & Curnier 1991, CMAME 92: 353). Its step, condensed with k, is Newton's step on Π for
///   λ̂ = λ; the model's own forces k max(0, λ̂/k − g − ∇g·dz) become the next λ (after a step of
///   the exact model, or of the PSD-projected one taken whole inside its trust region; any other
///   step holds them). The force balance then uses the multipliers, so the gap's second-order
///   error after a step (s²/2r_w for a slide s along the capsule) stays a gap error, corrected by
///   the next step, instead of a force error k times it that a penalty's iterates chase (the
///   straight tube's finite-strain levels: 5–7 Newton steps where the rounds took 19–65). Where
///   twelve full-length steps do not halve the balance's residual the solve goes on by the
///   augmented Lagrangian's rounds.
/// - augmented Lagrangian: Newton's method on Π for fixed λ̂, then λ̂ ← max(0, λ̂ − k g), until no
///   force changes by more than k × the gap tolerance (Nocedal & Wright, Numerical Optimization,
///   2nd ed., Framework 17.3);
/// - penalty: λ̂ = 0, the force k max(0, −g) (a second formulation: extrapolated in 1/k).
/// The forces act along the capsule's normal at every iterate, exactly frictionless, equal and
/// opposite by construction (d is invariant under translation).
///
/// The wall re-linearises at every Newton step, so dents of many wire radii, strains of order
/// one and a zone that slides are one solve; each step is cut so no centreline or wall node moves
/// by more than max_move · r_w (a longer step can carry a node across the wire), and accepted by
/// Armijo's condition on Π (an inverted wall element makes Π infinite) for the step's λ̂.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <memory>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "fem_reference/elasticity.hpp"
#include "fem_reference/hyperelastic.hpp"
#include "meshes/tet_mesh.hpp"
#include "msm/form/form.hpp"
#include "msm/rods/rod.hpp"

namespace vessel::contact {

/// A wall's displacement node at the middle of the mesh edge (a, b): a P2 wall's mid-edge node.
struct EdgeNode {
  int a = -1, b = -1;         ///< the edge's mesh nodes
  Vec3 rest = Vec3::Zero();   ///< its support point at rest (on a curved wall, on the curve), m
  std::array<int, 3> rows{};  ///< its x, y, z displacement rows (−1 where held)
};

/// A wall as the energy of its free displacement rows (m).
class WallPotential {
 public:
  virtual ~WallPotential() = default;
  [[nodiscard]] virtual int num_dofs() const = 0;
  /// Per mesh node, the rows of its x, y, z displacement (−1 where held).
  [[nodiscard]] virtual const std::vector<std::array<int, 3>>& node_rows() const = 0;
  /// The wall's nodes at the middles of `edges` (mesh node pairs) where its displacement is
  /// quadratic along them (P2), an edge whose middle node is wholly held left out; none for a
  /// wall linear on every edge.
  [[nodiscard]] virtual std::vector<EdgeNode> edge_nodes(
      const TetMesh& /*mesh*/, const std::vector<std::array<int, 2>>& /*edges*/) const {
    return {};
  }
  /// The energy at u (J; +∞ where an element is inverted), its gradient (N) and Hessian (N/m)
  /// when asked; with project_psd the Hessian's element blocks projected onto the positive
  /// semidefinite cone (a linear wall's already are).
  virtual double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd* gradient,
                          Eigen::SparseMatrix<double>* hessian, bool project_psd = false) const = 0;
  /// evaluate's energy and gradient with both Hessians, the exact one and the projected one (as
  /// evaluate gives each). By default two evaluations; a wall assembled from element blocks
  /// projects each block as it assembles it and gives both from one pass.
  virtual double evaluate_both(const Eigen::VectorXd& u, Eigen::VectorXd* gradient,
                               Eigen::SparseMatrix<double>& exact,
                               Eigen::SparseMatrix<double>& projected) const;
  /// The largest principal strain at u: small strain for a linear wall, Green–Lagrange for a
  /// finite-strain one.
  [[nodiscard]] virtual double largest_strain(const TetMesh& mesh,
                                              const Eigen::VectorXd& u) const = 0;
  /// Per mesh node its displacement (m) at u: zero where held, unless the wall knows its whole
  /// field (a condensed one does).
  [[nodiscard]] virtual std::vector<Vec3> nodal(const Eigen::VectorXd& u) const;
  /// The tets the wall carries that are inverted at u (non-positive volume; by default every
  /// tet of `mesh` with its nodes moved by nodal(u)); nothing for a wall without tets.
  [[nodiscard]] virtual std::optional<std::size_t> inverted_tets(const TetMesh& mesh,
                                                                 const Eigen::VectorXd& u) const;
};

/// The linear wall: ½uᵀKu − fᵀu of the FEM's free displacement system.
class LinearWall final : public WallPotential {
 public:
  explicit LinearWall(fem::FreeDisplacementSystem system) : s_(std::move(system)) {}
  [[nodiscard]] int num_dofs() const override { return static_cast<int>(s_.f.size()); }
  [[nodiscard]] const std::vector<std::array<int, 3>>& node_rows() const override {
    return s_.node_rows;
  }
  /// P2: the mid-edge nodes (mid_edge_nodes; std::logic_error if the system's row points are not
  /// filled: ElasticitySolver::set_row_points). None for a system with only the vertices' rows.
  [[nodiscard]] std::vector<EdgeNode> edge_nodes(
      const TetMesh& mesh, const std::vector<std::array<int, 2>>& edges) const override;
  double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd* gradient,
                  Eigen::SparseMatrix<double>* hessian, bool project_psd = false) const override;
  [[nodiscard]] double largest_strain(const TetMesh& mesh, const Eigen::VectorXd& u) const override;

 private:
  fem::FreeDisplacementSystem s_;
};

/// The finite-strain wall: the FEM reference's compressible neo-Hookean strain energy
/// (fem::HyperelasticSolver::free_state, displacement formulation, P1 or P2).
class NeoHookeanWall final : public WallPotential {
 public:
  NeoHookeanWall(const TetMesh& mesh, fem::ElasticityProblem problem);
  [[nodiscard]] int num_dofs() const override { return n_; }
  [[nodiscard]] const std::vector<std::array<int, 3>>& node_rows() const override {
    return dofs_.node_rows;
  }
  /// P2: the mid-edge nodes, found by their support points (mid_edge_nodes).
  [[nodiscard]] std::vector<EdgeNode> edge_nodes(
      const TetMesh& mesh, const std::vector<std::array<int, 2>>& edges) const override;
  double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd* gradient,
                  Eigen::SparseMatrix<double>* hessian, bool project_psd = false) const override;
  /// The exact and the projected Hessian from one pass over the cells.
  double evaluate_both(const Eigen::VectorXd& u, Eigen::VectorXd* gradient,
                       Eigen::SparseMatrix<double>& exact,
                       Eigen::SparseMatrix<double>& projected) const override;
  [[nodiscard]] double largest_strain(const TetMesh& mesh, const Eigen::VectorXd& u) const override;
  /// The cells with J ≤ 0 at a quadrature point (none where the energy is finite).
  [[nodiscard]] std::optional<std::size_t> inverted_tets(const TetMesh& /*mesh*/,
                                                         const Eigen::VectorXd& u) const override {
    return inverted_cells(u).size();
  }
  /// The supports' total reaction at u (N): the internal forces on the held DoFs, summed per
  /// component.
  [[nodiscard]] Vec3 support_reaction(const Eigen::VectorXd& u) const;
  [[nodiscard]] const fem::FreeDisplacementSystem& dofs() const { return dofs_; }
  /// The cells inverted at u (fem::HyperelasticSolver::inverted_cells).
  [[nodiscard]] std::vector<int> inverted_cells(const Eigen::VectorXd& u) const {
    return solver_->inverted_cells(u);
  }
  /// u with its folds smoothed out, where a field carried from another mesh inverts elements
  /// (the new mesh's elements straddle the old one's kinks under a deep dent): while a cell is
  /// inverted, the rows of the inverted cells, and one ring of neighbours more at each pass,
  /// take their neighbours' mean displacement (Laplacian smoothing; neighbours share a cell and
  /// a component), every other row kept. Nothing if cells are still inverted after
  /// `max_passes`.
  [[nodiscard]] std::optional<Eigen::VectorXd> untangled(const Eigen::VectorXd& u,
                                                         int max_passes = 6) const;
  /// The wall's displacement at u (its free rows) at points inside its mesh, m
  /// (fem::HyperelasticSolver::free_displacement_at).
  [[nodiscard]] std::vector<Vec3> displacement_at(const Eigen::VectorXd& u,
                                                  const std::vector<Vec3>& points,
                                                  double outside_tolerance) const {
    return solver_->free_displacement_at(u, points, outside_tolerance);
  }

 private:
  int degree_ = 1;  ///< read before the problem moves into the solver
  std::unique_ptr<fem::HyperelasticSolver> solver_;
  fem::FreeDisplacementSystem dofs_;
  int n_ = 0;
};

/// The nodes of `system` at the middles of `edges` (mesh node pairs): per edge the support point
/// (system.row_points) nearest its chord's midpoint, within a quarter of its length (a P2 node
/// on a curved wall sits off the chord by about h²/(8R)); an edge with none there left out.
std::vector<EdgeNode> mid_edge_nodes(const fem::FreeDisplacementSystem& system, const TetMesh& mesh,
                                     const std::vector<std::array<int, 2>>& edges);

/// The rows of `wall` (P1 or P2 on `mesh`) of the field linear in each tet with the values
/// `nodal` at the mesh's nodes: a vertex's rows take its value, a mid-edge node's the mean of its
/// edge's two (edge_nodes). A P2 wall's start from a P1 equilibrium on the same mesh.
/// std::logic_error if a row is at no vertex and no edge's middle.
Eigen::VectorXd linear_field_rows(const WallPotential& wall, const TetMesh& mesh,
                                  const std::vector<Vec3>& nodal);

/// A msm model's own energy as the wall: E(X + u) − E(X) over its free dofs with its exact
/// gradient and Hessian, so the contact solve finds the model's own (nonlinear) equilibrium.
/// `free_index` and `node_rows` as form_wall_system (contact_models/model_walls.hpp) gives them.
/// The form must outlive the wall.
class FormWall final : public WallPotential {
 public:
  FormWall(const msm::Form& form, Eigen::VectorXd rest, std::vector<int> free_index,
           std::vector<std::array<int, 3>> node_rows);
  [[nodiscard]] int num_dofs() const override { return n_; }
  [[nodiscard]] const std::vector<std::array<int, 3>>& node_rows() const override {
    return node_rows_;
  }
  double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd* gradient,
                  Eigen::SparseMatrix<double>* hessian, bool project_psd = false) const override;
  /// The P1 small strain of the tets whose four nodes the model carries (NaN if none).
  [[nodiscard]] double largest_strain(const TetMesh& mesh, const Eigen::VectorXd& u) const override;
  /// Of the tets whose four nodes the model carries, those inverted at u (nothing if none): a
  /// spring network's energy does not forbid a tet to fold.
  [[nodiscard]] std::optional<std::size_t> inverted_tets(const TetMesh& mesh,
                                                         const Eigen::VectorXd& u) const override;

 private:
  [[nodiscard]] Eigen::VectorXd positions(const Eigen::VectorXd& u) const;
  /// `mesh` with only the tets whose four nodes the model carries.
  [[nodiscard]] TetMesh carried_tets(const TetMesh& mesh) const;
  const msm::Form& form_;
  Eigen::VectorXd rest_;
  std::vector<int> free_index_;
  std::vector<std::array<int, 3>> node_rows_;
  int n_ = 0;
  double rest_energy_ = 0.0;
};

/// How Signorini's conditions are solved (the file's comment).
enum class ContactLaw { alart_curnier, augmented_lagrangian, penalty };

struct PotentialContactOptions {
  /// k (N/m). 0: penalty_factor × the wall's largest diagonal stiffness at rest on the
  /// candidates' rows.
  double penalty_stiffness = 0.0;
  double penalty_factor = 100.0;
  ContactLaw law = ContactLaw::alart_curnier;
  /// m: Alart–Curnier's stops when no multiplier's pair penetrates or, pressed, is open by more
  /// than this (|min(λ_j/k, g_j)|); the augmented Lagrangian when no force changes by more than
  /// k × this in a round (then no pressed node is open or penetrating by more than this)
  double gap_tolerance = 1e-9;
  /// on the force balance over the free dofs, relative to force_scale: ‖∇E − Σ λ_j∇g_j‖
  /// (Alart–Curnier), ‖∇Π‖ (otherwise)
  double tolerance = 1e-9;
  double force_scale = 1e-3;    ///< N
  double max_move = 0.5;        ///< × r_w: the largest node move of one Newton step
  int max_newton = 300;         ///< Newton steps per round
  /// A P2 wall's mid-edge nodes on the inner wall are candidates too, and the tip meets its faces
  /// split at them (four flat triangles each): a quadratic wall pressed at its vertices alone
  /// takes point loads where a pressure puts none of its consistent load, and its surface
  /// between them can wrap round the wire. Off: its vertices alone, as a P1 wall's.
  bool mid_edge_candidates = true;
  /// Levenberg–Marquardt: the Newton model's matrix B + μ diag(|B|), μ raised tenfold (from 1e-4)
  /// after a step the line search cut and lowered tenfold after a full one.
  bool damped_newton = false;
  /// augmented-Lagrangian rounds (also Alart–Curnier's after it falls back; the penalty's: one)
  int max_rounds = 40;
  std::ostream* log = nullptr;  ///< one line per round and per 25 Newton steps, if set
};

struct PotentialContactSolution {
  Eigen::VectorXd x;  ///< the wire's dofs
  Eigen::VectorXd u;  ///< the wall's free displacement rows, m
  /// The pressed wall nodes (mesh indices, ascending), the magnitude of the wire's force on each
  /// (N) and its unit direction: its own contact with the capsule plus its shares of the tip's
  /// contacts with its faces and half of each mid-edge node's force on its edges.
  std::vector<int> pressed;
  std::vector<double> force;
  std::vector<Vec3> direction;
  /// How many of the pressed candidates are a P2 wall's mid-edge nodes (their forces are in
  /// `force`, half on each end of the edge).
  int pressed_edge_nodes = 0;
  /// Per centreline node, the wall's contact force on it (N).
  std::vector<Vec3> force_on_wire;
  double max_penetration = 0.0;  ///< m, over every candidate
  double penalty_stiffness = 0.0;  ///< the k used, N/m
  int newton_iterations = 0;       ///< over all rounds
  int factorisations = 0;          ///< of the coupled Newton matrix, over all rounds
  int rounds = 0;                  ///< augmented-Lagrangian rounds (1 without any)
  double residual = 0.0;           ///< the force balance's residual at the end, N (tolerance)
  double seconds = 0.0;
  /// Σ λ_j n_j: the wire's total force on the wall, N.
  [[nodiscard]] Vec3 total_force_on_wall() const;
};

/// The wire's centreline crossed the wall's inner surface (describe_wall_crossing) at the solve's
/// start or after a Newton step: the capsule passed between the wall's nodes, whose gaps are open
/// again on the far side, and a solve from there would converge outside the lumen. Holds that
/// iterate's centreline nodes (m), where it crossed (m), the crossed inner-wall triangle's
/// mesh nodes and the wall's rows (m), for a caller that refines the wall or widens its
/// candidates where the wire bears, or asks whether the wall had folded there.
struct WireThroughWall : std::runtime_error {
  WireThroughWall(const std::string& what, std::vector<Vec3> at, const Vec3& where,
                  const Triangle& crossed, Eigen::VectorXd rows)
      : std::runtime_error(what),
        centreline(std::move(at)),
        point(where),
        triangle(crossed),
        wall_rows(std::move(rows)) {}
  std::vector<Vec3> centreline;
  Vec3 point;
  Triangle triangle;
  Eigen::VectorXd wall_rows;
};

/// `crossing` with, where `wall` (whose rows the crossing holds) then had inverted tets, how many
/// appended to its message: a folded wall, not only a coarse one, lets the wire through between
/// its nodes.
WireThroughWall with_inverted_tets(const WireThroughWall& crossing, const WallPotential& wall,
                                   const TetMesh& mesh);

/// Minimises Π from the wire at `start` (e.g. its rigid-lumen state) and the wall at
/// `wall_start` (its free rows, m; empty: at rest), e.g. the equilibrium of a softer wire on the
/// same wall. The contact candidates are `candidates` (mesh nodes; e.g. the whole inner wall)
/// and, on a P2 wall, the mid-edge nodes of the inner-wall faces whose three nodes are candidates
/// (options.mid_edge_candidates): each one's gap to the capsule enters Π, a mid-edge node's force
/// reported half on each end of its edge. `rod`: without equality constraints (DER); its clamps
/// are held; it is left prepared at the solution. Throws WireThroughWall where the centreline
/// crosses the wall; std::runtime_error naming the round, the residual and the penetration
/// without convergence; InputError for a rod with constraints,
/// r_w ≤ 0, a start of the wrong size or a candidate not in the mesh.
PotentialContactSolution solve_wire_wall_potential(msm::rods::Rod& rod, double radius,
                                                   const WallPotential& wall, const TetMesh& mesh,
                                                   const std::vector<int>& candidates,
                                                   const Eigen::VectorXd& start,
                                                   const PotentialContactOptions& options = {},
                                                   const Eigen::VectorXd& wall_start = {});

/// The bending stiffnesses of a continuation towards `target` (N·m², ascending, ending at
/// target): from `first` in steps of `ratio`, or the target alone when it is not above `first`.
/// A stiff wire's equilibrium on a soft wall is reached by solving each from the last.
std::vector<double> continuation_rungs(double first, double ratio, double target);

/// The ratio between rungs both contact references climb by: √10, two rungs a decade (on the
/// straight scene 4e-6 → 1.26e-5 converges in 41 Newton steps; 4e-6 → 4e-5 did not in 300,
/// measured with the wall's tangent left unprojected).
inline constexpr double kContinuationRatio = 3.1622776601683795;

/// The forces the clamp exerts on the wire at a solution, per node with a held position
/// component (N): the rod's internal force and its contact share there.
std::vector<std::pair<int, Vec3>> potential_clamp_forces(const msm::rods::Rod& rod,
                                                        const PotentialContactSolution& solution);

/// The force the clamp exerts on the wire at a solution (N): potential_clamp_forces summed.
Vec3 potential_clamp_reaction(const msm::rods::Rod& rod, const PotentialContactSolution& solution);

}  // namespace vessel::contact
