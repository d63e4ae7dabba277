#pragma once
/// A vessel model's wall as the contact's wall: the model's stiffness at its rest state, its
/// supports held, on its free dofs, with the tet mesh's nodes mapped to its rows, so that
/// CondensedWall and solve_wire_wall_contact take it as they take the FEM reference's.
///
/// The stiffness is the Hessian of the model's energy at rest. For the linear models (FEM P1 and
/// P2 by deal.II, the edge-pair StVK tetrahedron and the corotational P1 at rest, whose Hessian
/// there is linear P1's) that is the model's own equilibrium operator; for the spring networks,
/// the hybrid volume term, the Discrete Shells hinges and XPBD's stable neo-Hookean energy it is
/// their small-dent linearisation (their own equilibrium is nonlinear in the dent).
///
/// Surface models: a surface model's nodes are the inner wall's mesh nodes (surface = "inner"),
/// or those nodes moved radially to the mid-surface a + t/2 (surface = "mid"; msm::wall_surface);
/// either way each maps to its inner-wall source node. The contact acts on the inner wall: a mid-
/// surface node's contact point is its inner-wall source node, carried with the mid-surface node's
/// displacement (the shell's normal fibre translated, its turn and thinning neglected), which on a
/// tube is the contact of the mid-surface with the wire's radius grown by t/2. The thickness enters
/// the stiffness (springs ∝ E·t, hinges ∝ E·t³) and this offset. Outer-wall surface models have no
/// node on the inner wall: InputError.
#include <memory>
#include <string>
#include <vector>

#include "fem_reference/elasticity.hpp"
#include "meshes/tet_mesh.hpp"
#include "msm/form/form.hpp"
#include "verification/scene.hpp"

namespace vessel::contact {

/// The free displacement system of a Form linearised at `rest` (its positions, m): K = ∂²E/∂x² at
/// rest (N/m) on the dofs not `fixed`, f = 0; node_rows maps tet-mesh node mesh_node[i] to the rows
/// of the Form's node i (−1 for held dofs and for mesh nodes no Form node maps to). `mesh_node`:
/// per Form node its tet-mesh node, or −1 for none. std::invalid_argument for sizes that disagree,
/// a mesh node out of range or mapped twice.
fem::FreeDisplacementSystem form_wall_system(const msm::Form& form, const Eigen::VectorXd& rest,
                                             const std::vector<char>& fixed,
                                             const std::vector<int>& mesh_node,
                                             std::size_t mesh_nodes);

/// How a model's wall enters the contact.
enum class WallLinearisation {
  exact,      ///< a linear model: its own equilibrium
  small_dent  ///< a nonlinear model linearised at rest
};
std::string to_string(WallLinearisation l);  ///< "own (linear)" | "small-dent"

/// A msm model's energy as the wall carries it, to measure how far a linearised dent is from the
/// model's own equilibrium.
struct WallEnergy {
  std::shared_ptr<const void> owner;  ///< keeps the model (and its network) alive
  const msm::Form* form = nullptr;    ///< nullptr: deal.II's FEM (linear)
  Eigen::VectorXd rest;               ///< m
  std::vector<char> fixed;
  std::vector<int> mesh_node;  ///< per Form node its tet-mesh node (−1: none)
};

struct ModelWall {
  std::string name;
  std::string detail;  ///< what the model is (kind, rules)
  fem::FreeDisplacementSystem system;
  WallLinearisation linearisation = WallLinearisation::exact;
  WallEnergy energy;
  double setup_seconds = 0.0;  ///< building the model and its stiffness, s
};

/// The model's own force imbalance at a dent of its linearised wall: ‖∇E(X + u) − f‖ over its free
/// dofs relative to ‖f‖, u (m) and f (N) per tet-mesh node (each Form node takes its mesh node's).
/// 0 for deal.II's FEM (linear: the linearised dent is its equilibrium); for the nonlinear models
/// the part of the contact load their own energy does not balance at that dent.
double own_imbalance(const ModelWall& wall, const std::vector<Vec3>& u,
                     const std::vector<Vec3>& loads);

/// The wall of `spec` (kinds fem, volume_msm, surface_msm with surface inner or mid,
/// corotational_fem, xpbd_fem) on `mesh`, the scene's material at ν and its supports held.
/// `vessel`: the mesh's vessel (its radius and thickness, style unstructured for a gmsh mesh).
/// InputError for another kind, an outer-wall surface model or a ν the model refuses
/// (model_refusal).
ModelWall model_wall(const Scene& scene, const ModelSpec& spec, const TetMesh& mesh,
                     const VesselParams& vessel, double nu);

}  // namespace vessel::contact
