#pragma once
/// The one place that builds the problems a Scene describes, for the harness, the studies and the
/// fem/msm commands alike: its meshes, the FEM reference's problem and each mass-spring model's
/// network and problem (material, supports, loads), with every default they share. The FEM and the
/// springs get the same loads (the contact patch and pressure triangles of meshes/surface_loads)
/// and the same supports (meshes/supports). SI units.
#include <filesystem>
#include <memory>
#include <string>

#include "fem_reference/elasticity.hpp"
#include "msm/model/build_network.hpp"
#include "msm/fem/tet_term.hpp"
#include "msm/form/form.hpp"
#include "verification/scene.hpp"

namespace vessel {

/// Solves the scene's wire against the rigid lumen (a Newton solve, an XPBD run to rest or the
/// user's program) and makes its load the contact patch of the wire's force at the wall point
/// under its contact node (magnitudes = {F}). Does nothing for a scene without a guidewire or
/// one already solved. InputError naming the scene file and `load.insertion` if the wire does
/// not reach the wall, or touches it at more than one node; naming the file and `load` if the
/// solve fails (the user's program among them).
void solve_guidewire_load(Scene& scene);

/// Where a contact pushes when no point is given: on the named wall (inner_wall or outer_wall,
/// radius a or b) at mid-length on the θ = 0 side: (r, 0, L/2) on the tube, the outer bend's
/// apex (0, R + r, 0) on the arch. InputError for a vessel from a file (its point must be given).
Vec3 default_contact_point(const VesselParams& vessel, const std::string& surface_group);

/// Where a scene's "contact-point displacement" (its QoI) is read: the contact point, or for
/// distributed loads the inner wall's default contact point. For a vessel from a file, the point
/// resolve_file_vessel put in load.contact.point.
Vec3 qoi_point(const Scene& scene);

/// A vessel from a file (mesh or lumen) has no parametric wall, so its points come from its mesh
/// (the scene's reference mesh, the same for every level): a contact point (also of the constant
/// loads) moves to the nearest point of its wall group (`surface`: inner_wall or outer_wall); for
/// a distributed load the QoI becomes the point of the inner wall nearest the centroid of the
/// wall's nodes, kept in load.contact.point. A parametric vessel's scene is returned unchanged.
Scene resolve_file_vessel(Scene scene, const TetMesh& mesh);

/// The node of `nodes` nearest `point` (the first of equals): where a point's displacement is read.
std::size_t nearest_node(const std::vector<Vec3>& nodes, const Vec3& point);

/// The scene's vessel mesh at `level`: generated with gmsh, cached under cache_dir (none if empty).
TetMesh scene_mesh(const Scene& scene, int level, const std::filesystem::path& cache_dir);

/// The supports of the scene's [boundary] (meshes/supports), errors naming the scene's file.
Supports scene_supports(const Scene& scene);

/// The contact patch of a contact load with force `force` (N) on `mesh`.
TractionPatch scene_contact_patch(const LoadSpec& load, const TetMesh& mesh, double force);

/// The FEM problem of the scene on `mesh` at Poisson's ratio ν with elements of `degree`: the
/// scene's material, supports, the swept load at `magnitude` and every constant load at its
/// magnitude; a load of magnitude 0 is not built. Formulation automatic at the default mixed
/// threshold (fem::SolverOptions::mixed_threshold).
/// Throws InputError (naming the scene's file) if nothing supports the body.
fem::ElasticityProblem fem_problem(const Scene& scene, const TetMesh& mesh, double nu, int degree,
                                   double magnitude = 1.0);

/// The scene's wall alone: its material at ν, its supports, elements of `degree`, no load (the
/// contact reference puts the wire's forces on it). InputError as fem_problem's.
fem::ElasticityProblem wall_problem(const Scene& scene, double nu, int degree);

/// The network options of a mass-spring model of the scene at ν.
msm::NetworkOptions network_options(const Scene& scene, const ModelSpec& model, double nu);

/// The network of a mass-spring model of the scene on `mesh` (vessel at the mesh's level) at ν,
/// with the model's calibration file applied when it names one (verification/calibration_file);
/// for a network model, its file placed on the mesh (msm::network_on_mesh). A mesh file without a
/// wall_thickness gets estimate_wall_thickness(mesh) (the surface models' shell thickness).
msm::BuiltNetwork scene_network(const Scene& scene, const ModelSpec& model, const TetMesh& mesh,
                                const VesselParams& vessel, double nu);

/// The held dofs of a network read from a file (built.file_supports): its fixed nodes in every
/// component, and the scene's supports of the groups it follows (a clamped group holds every
/// component, a roller group z, with the pins) on the nodes lying on those groups' triangles
/// (within kNodeMatchTolerance of the mesh's size). InputError naming the file if nothing is held.
std::vector<char> file_network_held_dofs(const Scene& scene, const TetMesh& mesh,
                                         const msm::BuiltNetwork& built);

/// The consistent nodal loads (N, per mesh node) of the scene's surface loads (contact patch,
/// pressure) at `magnitude` for the swept load: what the FEM integrates, lumped to the nodes.
/// Gravity is not among them: mass-spring models carry it on their own masses.
std::vector<Vec3> surface_nodal_loads(const Scene& scene, const TetMesh& mesh, double magnitude);

/// The mass-spring problem of a network built on `mesh`: surface loads as consistent nodal loads
/// (mapped to the network's nodes), gravity on the network's own masses (for the volume model
/// with consistent masses exactly the FEM's ρgV/4 per tet vertex), and the scene's supports as
/// held dofs.
msm::Problem msm_problem(const Scene& scene, const msm::Form& form, const msm::BuiltNetwork& built,
                         const TetMesh& mesh, double magnitude);

/// The problem of a P1 tet model on the scene's mesh itself (kinds corotational_fem and xpbd_fem):
/// its nodes are the mesh's, with lumped masses ρV₀/4 per tet corner (kg), the surface loads'
/// consistent nodal loads (N), gravity on those masses and the scene's supports as held dofs.
msm::Problem tet_mesh_problem(const Scene& scene, const msm::TetTerm& term, const TetMesh& mesh,
                              double magnitude);

/// The energy of a P1 tet model (kinds corotational_fem and xpbd_fem) on `mesh` with Young's
/// modulus E (Pa) and Poisson's ratio ν: corotational P1 with its consistent tangent (static
/// Newton's), or the stable neo-Hookean energy XPBD FEM's constraints carry, with the λ whose
/// small-strain limit is the material's (msm/fem/stable_neo_hookean.hpp). InputError for another
/// kind.
std::unique_ptr<msm::TetTerm> tet_fem_term(const ModelSpec& spec, const TetMesh& mesh, double E,
                                           double nu);

}  // namespace vessel
