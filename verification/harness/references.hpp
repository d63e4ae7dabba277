#pragma once
/// A scene's references: its meshes, the linear P2 reference at each ν (fine level and the one
/// below for the Richardson/GCI uncertainty), the modal reference, the FEM transients beside
/// dynamic models and the finite-strain reference; solved before the models, several at a time
/// when asked (solve_all_references). Untimed: the references' cost is not a model's.
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "fem_reference/convergence.hpp"
#include "fem_reference/elasticity.hpp"
#include "fem_reference/hyperelastic.hpp"
#include "msm/form/form.hpp"
#include "verification/harness/options.hpp"
#include "verification/harness/outcome.hpp"
#include "verification/scene.hpp"

namespace vessel {

/// Barycentric tolerance for evaluating the reference at model nodes: a node on the exact curved
/// wall lies outside the reference's straight-sided tets by up to the chord's sagitta ℓ²/(8r),
/// a few per cent of a tet's height at the levels used; the FE polynomial is extended there.
constexpr double kOutsideTolerance = 0.25;

/// Reference displacement at unit load and its Richardson uncertainty at a model's points.
struct ReferenceAtPoints {
  std::vector<Vec3> u;  ///< fine level, unit load
  fem::FieldUncertainty uncertainty;  ///< unit load; zero if there is no coarser level
  bool has_uncertainty = false;
};

/// The linear reference of one (scene, ν): the fine level and the one below, the FEM transient's
/// solver, and the finite-strain reference solved on demand.
struct ReferenceSolvers {
  std::unique_ptr<fem::ElasticitySolver> fine;
  std::unique_ptr<fem::ElasticitySolver> coarse;
  fem::GciOrder gci;  ///< the order reference_at's Richardson uses (with `coarse`)
  const TetMesh* fine_mesh = nullptr;
  fem::ElasticityProblem fine_problem;  ///< what `fine` solves: the solution cache's key
  fem::SolutionCache* cache = nullptr;  ///< nullptr: solve and run transients afresh
  /// The FEM transient's discretisation (scene's [transient] reference_level): `fine` itself,
  /// or a solver of its own on another level (never solved statically: transient() needs no
  /// solve).
  std::unique_ptr<fem::ElasticitySolver> transient_solver;
  const TetMesh* transient_mesh = nullptr;
  fem::ElasticityProblem transient_problem;
  int transient_level = 0;  ///< the transient's mesh level
  /// FEM transients already run, by (probe point, simulated time, α): |u(t)| at unit load, m.
  mutable std::map<std::tuple<double, double, double, double, double>,
                   std::pair<std::vector<double>, std::vector<double>>>
      transients;
  /// The finite-strain reference (scene's `reference`), one solve per load magnitude on the fine
  /// mesh with the fine problem (unit load × load factor = magnitude); not cached on disk.
  mutable std::map<double, std::unique_ptr<fem::HyperelasticSolver>> finite;
};

/// The reference (unit load) and its Richardson uncertainty at a model's points.
ReferenceAtPoints reference_at(const ReferenceSolvers& ref, const std::vector<Vec3>& points);

/// Whether the finite-strain reference judges a case at load `magnitude`: always, never, or
/// (auto) where the linear reference's largest strain there exceeds the linear regime's 5 %.
bool finite_strain_judges(const Scene& s, double linear_strain_unit, double magnitude);

/// What judges a model at load `magnitude`: the linear reference at `points` (`linear_here`) with
/// its largest strain per unit load, or, where finite_strain_judges says so, the finite-strain
/// displacement divided by the magnitude (the models' outcomes scale the reference by it), with
/// no Richardson uncertainty (no coarser finite-strain level) and strain 0 (the linear-validity
/// flag does not apply).
struct JudgingReference {
  ReferenceAtPoints at_points;
  double strain_unit = 0.0;
  bool finite_strain = false;
};
JudgingReference judging_reference(const ReferenceSolvers& ref, const Scene& s,
                                   const ReferenceAtPoints& linear_here,
                                   const std::vector<Vec3>& points, double linear_strain_unit,
                                   double magnitude);

/// The finite-strain reference at `magnitude` (solved on first use). std::runtime_error naming
/// the largest load reached when load stepping found no equilibrium at the magnitude.
const fem::HyperelasticSolver& finite_reference(const ReferenceSolvers& ref, double magnitude);

/// The FEM transient's damping beside a dynamic model: the model's point damping c (force −c v
/// per node, seed 000 eq. 3.3) becomes mass-proportional damping α = c / m̄ with m̄ the model's
/// mean nodal mass: exact for uniform masses, an average otherwise.
double transient_mass_damping(const ModelSpec& spec, const msm::Problem& problem);

/// The FEM transient next to a dynamic model's history `h` (its time_s and model_mm filled): the
/// reference's |u| at `probe` interpolated to the model's sample times, and the largest
/// difference. The transient runs once per probe, time and damping, then is reused.
void add_reference_history(History& h, const ReferenceSolvers& ref, const Vec3& probe,
                           const ModelSpec& spec, const msm::Problem& problem, double magnitude);

/// A scene's meshes and its reference at each ν: what its models are compared against, solved
/// before the models (in parallel across scenes with HarnessOptions::jobs > 1). Not movable: the
/// solvers point at the meshes.
struct SceneReferences {
  /// The scene as run: a vessel from a file has its contact and QoI points moved onto the
  /// reference mesh's wall (resolve_file_vessel).
  Scene scene;
  std::map<int, TetMesh> model_meshes;
  TetMesh fine_mesh;
  std::unique_ptr<TetMesh> coarse_mesh;
  std::unique_ptr<TetMesh> coarsest_mesh;  ///< reference_level − 2: the GCI's observed order
  /// Meshes read for the modal reference or the FEM transient alone, by level.
  std::map<int, std::unique_ptr<TetMesh>> other_meshes;
  const TetMesh* modal_reference_mesh = nullptr;  ///< nullptr: the scene asks for no modes
  int modal_level = 0;
  const TetMesh* transient_mesh = nullptr;  ///< the FEM transient's (scene's [transient])
  int transient_level = 0;
  struct AtNu {
    ReferenceSolvers ref;
    ReferenceInfo info;
    std::optional<ModalOutcome> modes;
    double seconds = 0.0;
  };
  std::vector<AtNu> at_nu;  ///< one per scene ν, in the scene's order
  /// A vessel from a lumen file: its ends with their groups (lumen_file_ends).
  std::vector<std::pair<std::string, LumenEnd>> lumen_ends;
  /// The slivers of every mesh above, by level (find_slivers).
  std::map<int, SliverReport> mesh_slivers;

  SceneReferences() = default;
  SceneReferences(const SceneReferences&) = delete;
  SceneReferences& operator=(const SceneReferences&) = delete;
};

/// The scene's meshes (generated or read from the mesh cache; gmsh is not thread-safe, so this
/// runs on one thread). Logs a lumen's ends and a warning for each mesh with slivers.
std::unique_ptr<SceneReferences> scene_meshes(const Scene& scene, const HarnessOptions& o,
                                              std::ostream& log);

/// One static linear solve of a scene's reference: its mesh, level and problem (unit load), the
/// solution cache's key.
struct ReferenceSolve {
  const TetMesh* mesh = nullptr;
  int level = 0;
  fem::ElasticityProblem problem;
};

/// The static solves of the scene's reference at its k-th ν, as solve_reference_at makes them:
/// the fine level, then the one below (Richardson) and the one below that (the GCI's observed
/// order) where the scene has them. What a distributed reference job solves into the cache.
std::vector<ReferenceSolve> reference_solves(const SceneReferences& r, std::size_t k);

/// The scene's P2 reference at its k-th ν (unit load), on the fine level and the one below.
void solve_reference_at(const Scene& s, SceneReferences& r, std::size_t k, const HarnessOptions& o);

/// The modal reference at the scene's k-th ν (nothing if the scene asks for no modes).
void solve_modal_reference_at(const Scene& s, SceneReferences& r, std::size_t k);

/// Progress labels of the reference solves, and a failed modal reference's line.
std::string reference_label(const Scene& s, double nu);
std::string modal_label(const Scene& s, const SceneReferences& r, double nu);
void log_modal_failure(std::ostream& log, const SceneReferences::AtNu& a);

/// Every scene's references, `o.jobs` solves at a time, the cores shared among the solves running
/// (parallel_solves). Scenes whose fine problems have the same matrix (mesh, material, supports:
/// the solution cache's key without the loads) are solved in one task, one after the other, so
/// that the later ones read the first's solution cache entry (the same loads) or reuse its kept
/// CHOLMOD factor (other loads: contact_straight's and gravity_sag's). Then the dynamic models'
/// FEM transients (run_all_transients).
void solve_all_references(std::vector<std::unique_ptr<SceneReferences>>& refs,
                          const HarnessOptions& o, std::ostream& log);

}  // namespace vessel
