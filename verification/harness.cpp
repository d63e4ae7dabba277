#include "verification/harness.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <optional>
#include <sstream>
#include <thread>
#include <tuple>

#include "fem_reference/cholmod_solve.hpp"
#include "fem_reference/convergence.hpp"
#include "fem_reference/elasticity.hpp"
#include "fem_reference/hyperelastic.hpp"
#include "fem_reference/solution_cache.hpp"
#include "meshes/atomic_file.hpp"
#include "meshes/errors.hpp"
#include "meshes/mesh_cache.hpp"
#include "meshes/vtu_io.hpp"
#include "msm/model/build_network.hpp"
#include "msm/model/model_factory.hpp"
#include "msm/model/network_file.hpp"
#include "msm/model/quadratic_form.hpp"
#include "msm/model/roi.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/solvers/static_solver.hpp"
#include "msm/solvers/updates.hpp"
#include "reports/representative_load.hpp"
#include "verification/external_model.hpp"
#include "verification/memory.hpp"
#include "verification/modal.hpp"
#include "verification/outcome_cache.hpp"
#include "verification/parallel.hpp"
#include "verification/progress.hpp"
#include "verification/scene_problems.hpp"
#include "verification/timing.hpp"

namespace vessel {

namespace {

/// The order Richardson/GCI assumes without three reference levels (fem::gci_order). Contact: 1.
/// The patch's traction jumps at the disc's edge and the QoI lies under it, so the field is not
/// smooth there and no element's formal order holds at the point; P1's observed order there is
/// 1.0–1.2 (issue 17), and the lower order gives the larger (conservative) estimate. Distributed
/// loads (pressure, gravity): 2, what straight-sided tets cap the order at on the curved walls
/// (the reference's own Lamé verification).
constexpr double kAssumedReferenceOrderContact = 1.0;
constexpr double kAssumedReferenceOrderDistributed = 2.0;
constexpr int kHistorySamples = 200;  ///< points kept of a dynamic model's QoI history

/// Barycentric tolerance for evaluating the reference at model nodes: a node on the exact curved
/// wall lies outside the reference's straight-sided tets by up to the chord's sagitta ℓ²/(8r),
/// a few per cent of a tet's height at the levels used; the FE polynomial is extended there.
constexpr double kOutsideTolerance = 0.25;

std::vector<Vec3> scaled(const std::vector<Vec3>& u, double factor) {
  std::vector<Vec3> out(u.size());
  for (std::size_t i = 0; i < u.size(); ++i) out[i] = factor * u[i];
  return out;
}

std::size_t free_unknowns(const msm::Problem& p) {
  return static_cast<std::size_t>(std::count(p.fixed.begin(), p.fixed.end(), 0));
}

/// The model nodes on the wall line through the QoI point: within a third of the level's cell size
/// of the QoI's angle around the centreline, at the radius nearest the QoI's; sorted by arc length.
std::vector<std::size_t> wall_line(const VesselParams& v, int level,
                                   const std::vector<Vec3>& nodes, const Vec3& qoi) {
  const CentrelineCoordinates q = centreline_coordinates(v, qoi);
  const double cell = v.wall_thickness / static_cast<double>(1 << level);
  std::vector<std::size_t> on_line;
  std::vector<CentrelineCoordinates> c(nodes.size());
  double nearest_radius = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    c[i] = centreline_coordinates(v, nodes[i]);
    const double dtheta = std::remainder(c[i].theta - q.theta, 2.0 * std::numbers::pi);
    if (std::abs(dtheta) * q.rho > cell / 3.0) continue;
    on_line.push_back(i);
    nearest_radius = std::min(nearest_radius, std::abs(c[i].rho - q.rho));
  }
  std::erase_if(on_line, [&](std::size_t i) {
    return std::abs(c[i].rho - q.rho) > nearest_radius + 0.1 * cell;
  });
  std::sort(on_line.begin(), on_line.end(), [&](std::size_t a, std::size_t b) { return c[a].s < c[b].s; });
  return on_line;
}

WallProfile wall_profile(const VesselParams& v, const std::vector<Vec3>& nodes,
                         const std::vector<std::size_t>& line, const std::vector<Vec3>& u_model,
                         const std::vector<Vec3>& u_ref) {
  WallProfile p;
  for (const std::size_t i : line) {
    const CentrelineCoordinates c = centreline_coordinates(v, nodes[i]);
    p.s_mm.push_back(c.s * 1e3);
    p.model_mm.push_back(u_model[i].dot(c.e_rho) * 1e3);
    p.reference_mm.push_back(u_ref[i].dot(c.e_rho) * 1e3);
  }
  return p;
}

/// Reference displacement at unit load and its Richardson uncertainty at a model's points.
struct ReferenceAtPoints {
  std::vector<Vec3> u;  ///< fine level, unit load
  fem::FieldUncertainty uncertainty;  ///< unit load; zero if there is no coarser level
  bool has_uncertainty = false;
};

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

int transient_reference_level(const Scene& s) {
  return s.transient.reference_level >= 0 ? s.transient.reference_level : s.reference_level;
}

bool has_dynamic_models(const Scene& s) {
  return std::any_of(s.models.begin(), s.models.end(), [](const ModelSpec& m) {
    return m.kind != ModelKind::fem && m.solver.is_dynamic();
  });
}

/// Whether the finite-strain reference judges a case at load `magnitude`: always, never, or
/// (auto) where the linear reference's largest strain there exceeds the linear regime's 5 %.
bool finite_strain_judges(const Scene& s, double linear_strain_unit, double magnitude) {
  switch (s.reference) {
    case ReferenceChoice::linear:
      return false;
    case ReferenceChoice::finite_strain:
      return magnitude != 0.0;
    case ReferenceChoice::automatic:
      return linear_strain_unit * magnitude > kLinearRegimeStrain;
  }
  return false;
}

/// The finite-strain reference at `magnitude` (solved on first use). std::runtime_error naming
/// the largest load reached when load stepping found no equilibrium at the magnitude.
const fem::HyperelasticSolver& finite_reference(const ReferenceSolvers& ref, double magnitude) {
  auto& slot = ref.finite[magnitude];
  if (!slot) {
    fem::HyperelasticOptions o;
    o.target_load_factor = magnitude;
    o.initial_step = o.max_step = magnitude;  // load factor = magnitude in the scene's unit
    o.min_step = 1e-4 * magnitude;
    auto solver = std::make_unique<fem::HyperelasticSolver>(*ref.fine_mesh, ref.fine_problem, o);
    solver->solve();
    slot = std::move(solver);
  }
  const fem::HyperelasticResult& r = slot->result();
  if (!r.completed) {
    std::ostringstream m;
    m << "finite-strain reference: no equilibrium at load " << magnitude
      << "; the largest load reached is " << r.load_factor << " (" << r.stop_reason << ")";
    throw std::runtime_error(m.str());
  }
  return *slot;
}

/// Newmark steps of the FEM transient: average acceleration is unconditionally stable, and 400
/// steps over the run resolve the low modes that a contact step excites.
constexpr int kTransientSteps = 400;

/// Guards every ReferenceSolvers::transients map: the parallel pass runs a scene's transients
/// side by side.
std::mutex transients_mutex;

/// The FEM transient at `probe` for a step unit load over `duration` (cached): times and |u|.
/// Thread-safe: two calls for the same transient may both run it, and the first stored is kept.
const std::pair<std::vector<double>, std::vector<double>>& transient_at(
    const ReferenceSolvers& ref, const Vec3& probe, double duration, double alpha) {
  const auto key = std::make_tuple(probe.x(), probe.y(), probe.z(), duration, alpha);
  {
    const std::lock_guard lock(transients_mutex);
    const auto it = ref.transients.find(key);
    if (it != ref.transients.end()) return it->second;
  }
  fem::TransientOptions t;
  t.dt = duration / kTransientSteps;
  t.steps = kTransientSteps;
  t.mass_damping = alpha;
  t.probe_points = {probe};
  t.outside_tolerance = kOutsideTolerance;
  const bool own = ref.transient_solver != nullptr;
  const fem::ElasticitySolver& solver = own ? *ref.transient_solver : *ref.fine;
  const TetMesh& mesh = own ? *ref.transient_mesh : *ref.fine_mesh;
  const fem::ElasticityProblem& problem = own ? ref.transient_problem : ref.fine_problem;
  const fem::TransientResult r =
      ref.cache ? ref.cache->transient(solver, mesh, problem, t) : solver.transient(t);
  std::vector<double> u(r.time.size());
  for (std::size_t k = 0; k < u.size(); ++k) u[k] = r.probe_displacement[k][0].norm();
  const std::lock_guard lock(transients_mutex);
  return ref.transients.emplace(key, std::make_pair(r.time, u)).first->second;
}

/// Linear interpolation of (t, v) at time x (clamped to the ends).
double interpolate(const std::vector<double>& t, const std::vector<double>& v, double x) {
  if (x <= t.front()) return v.front();
  if (x >= t.back()) return v.back();
  const auto hi = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), x) - t.begin());
  const double w = (x - t[hi - 1]) / (t[hi] - t[hi - 1]);
  return (1.0 - w) * v[hi - 1] + w * v[hi];
}

/// A reference solve on `mesh`, from the solution cache when it has it. The references are
/// untimed, so a CHOLMOD factor is kept for another load on the same vessel (contact_straight's
/// and gravity_sag's level-1 references share one).
const fem::ElasticityResult& solve_reference(std::unique_ptr<fem::ElasticitySolver>& solver,
                                             const TetMesh& mesh, fem::ElasticityProblem problem,
                                             fem::SolutionCache* cache) {
  problem.options.keep_factor = true;
  solver = std::make_unique<fem::ElasticitySolver>(mesh, problem);
  return fem::solve_with(cache, *solver, mesh, problem);
}

ReferenceAtPoints reference_at(const ReferenceSolvers& ref, const std::vector<Vec3>& points) {
  ReferenceAtPoints r;
  r.u = ref.fine->displacement_at(points, kOutsideTolerance);
  if (ref.coarse) {
    r.uncertainty = fem::richardson_field(ref.coarse->displacement_at(points, kOutsideTolerance),
                                          r.u, ref.gci.order);
    r.has_uncertainty = true;
  }
  return r;
}

/// Where a model's results are read: the QoI node and the wall line.
struct ReadOut {
  std::size_t qoi = 0;
  std::vector<std::size_t> wall_line;
};

ReadOut read_out(const Scene& s, int level, const std::vector<Vec3>& nodes, const Vec3& qoi) {
  // A vessel from a file has no centreline to run a wall line along: no wall profile.
  if (!s.vessel.parametric()) return {nearest_node(nodes, qoi), {}};
  return {nearest_node(nodes, qoi), wall_line(s.vessel, level, nodes, qoi)};
}

void finish_outcome(ModelOutcome& out, const Scene& s, const std::vector<Vec3>& nodes,
                    const std::vector<Vec3>& u_model, const ReferenceAtPoints& ref,
                    double magnitude, const ReadOut& at, double ref_max_strain_unit,
                    const Vec3& qoi_point, const std::vector<Vec3>& loads, long steps, double dt) {
  const std::vector<Vec3> u_ref = scaled(ref.u, magnitude);
  const std::size_t qoi = at.qoi;
  out.quantities =
      quantity_errors(s.budget, nodes, u_model, u_ref, qoi, qoi_point, loads, out.history);
  if (s.budget.stated) {
    out.budget_error = budget_quantity_error(out.quantities, s.budget.quantity);
    std::tie(out.update_seconds, out.steps_per_update) =
        time_per_update(out.solve_seconds, steps, dt, s.budget.update_period());
  }
  out.wall_profile = wall_profile(s.vessel, nodes, at.wall_line, u_model, u_ref);
  out.error = compare_displacements(u_model, u_ref);
  out.has_reference_uncertainty = ref.has_uncertainty;
  if (ref.has_uncertainty) {
    out.reference_uncertainty.max_mm = ref.uncertainty.max_error * magnitude * 1e3;
    out.reference_uncertainty.rms_mm = ref.uncertainty.rms_error * magnitude * 1e3;
    out.reference_uncertainty.relative_l2 = ref.uncertainty.relative_l2;
  }
  out.qoi_displacement_mm = u_model[qoi].norm() * 1e3;
  out.qoi_reference_mm = u_ref[qoi].norm() * 1e3;
  out.beyond_linear_regime = ref_max_strain_unit * magnitude > kLinearRegimeStrain;
  out.ok = true;
}

/// Fields are written at one load per model: the budget's (when the run includes it), else the
/// largest within the linear regime, else the smallest.
bool wants_fields(const HarnessOptions& o, const Scene& s, double magnitude,
                  double ref_max_strain_unit) {
  if (o.fields_dir.empty()) return false;
  if (o.fields_every_load) return true;
  Scene without_budget_load = s;
  const auto& m = s.load.magnitudes;
  if (std::find(m.begin(), m.end(), s.budget.magnitude) == m.end()) {
    without_budget_load.budget.magnitude = 0.0;
  }
  return magnitude == budget_magnitude(without_budget_load, ref_max_strain_unit);
}

/// Where write_model_fields writes an outcome's fields, relative to the fields directory.
std::filesystem::path fields_file(const Scene& s, const ModelOutcome& out) {
  std::ostringstream name;
  name << file_stem(out.model) << "_nu" << out.poisson_ratio << "_L" << out.level << "_load"
       << out.magnitude << ".vtu";
  return std::filesystem::path(s.name) / name.str();
}

/// One model's displacement fields at one load for ParaView: points at the model's rest nodes
/// (m), vectors in m so that "Warp By Vector" at scale 1 shows the deformed state, and |error| in
/// mm as the reports use.
void write_model_fields(const HarnessOptions& o, const Scene& s, const ModelOutcome& out,
                        const std::vector<Vec3>& nodes, const VtuCells& cells,
                        const std::vector<Vec3>& u_model, const std::vector<Vec3>& u_ref) {
  VtuField model{"displacement_model_m", 3, {}};
  VtuField reference{"displacement_reference_m", 3, {}};
  VtuField error{"error_m", 3, {}};
  VtuField error_mm{"error_magnitude_mm", 1, {}};
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const Vec3 e = u_model[i] - u_ref[i];
    for (int c = 0; c < 3; ++c) {
      model.values.push_back(u_model[i][c]);
      reference.values.push_back(u_ref[i][c]);
      error.values.push_back(e[c]);
    }
    error_mm.values.push_back(e.norm() * 1e3);
  }
  const std::filesystem::path path = o.fields_dir / fields_file(s, out);
  std::filesystem::create_directories(path.parent_path());
  write_vtu(path, nodes, cells, {model, reference, error, error_mm});
}

/// A mass-spring network's cells: its tets (volume), triangles (surface), else its springs.
VtuCells network_cells(const msm::SpringNetwork& n) {
  if (!n.tets.empty()) return tet_cells(n.tets);
  VtuCells cells;
  if (!n.triangles.empty()) {
    cells = {5, 3, {}};
    for (const auto& t : n.triangles) {
      for (const int v : t) cells.connectivity.push_back(static_cast<std::size_t>(v));
    }
  } else {
    cells = {3, 2, {}};
    for (const auto& sp : n.springs) {
      cells.connectivity.push_back(static_cast<std::size_t>(sp.a));
      cells.connectivity.push_back(static_cast<std::size_t>(sp.b));
    }
  }
  return cells;
}

/// Linear FEM timed as a simulator runs it, by the procedure that times the mass-spring models
/// (timed_updates with the "linear" updater, msm/solvers/updates.hpp): its system on the free DoFs
/// as a Form (msm::QuadraticForm), factorised once at set-up (with, for a load on few DoFs such as
/// a contact patch, the responses to them: Cotin et al. 1999's precomputation, as for the springs'
/// linear models), then each update of the load ramp.
struct FemUpdates {
  double setup_seconds = 0.0;   ///< assembly of K and f, factorisation and responses, s
  double update_seconds = 0.0;  ///< median update, s
};
FemUpdates timed_fem_updates(const fem::ElasticitySolver& solver, int updates, int repeats) {
  Stopwatch assembly;
  fem::FreeDisplacementSystem sys = solver.free_displacement_system();
  const auto n = sys.f.size();
  const msm::QuadraticForm form(std::move(sys.K), Eigen::VectorXd::Zero(n));
  msm::Problem p;
  p.form = &form;
  p.rest = Eigen::VectorXd::Zero(n);  // the state is the displacement on the free DoFs
  p.external_force = std::move(sys.f);
  p.mass = Eigen::VectorXd::Ones(n);  // unused by a static answer
  p.fixed.assign(static_cast<std::size_t>(n), 0);
  const double assembly_seconds = assembly.seconds();
  const UpdateSequence seq = timed_updates(p, msm::parse_solver("linear"), updates, repeats);
  return {assembly_seconds + seq.setup_seconds, seq.update_seconds};
}

/// A FEM model: always the displacement formulation of its degree, so that P1's locking near
/// ν = 0.5 shows; at ν = 0.5, where that element cannot be used, it is recorded as failed.
void run_fem_model(const Scene& s, const ModelSpec& spec, double nu, const TetMesh& mesh,
                   const ReferenceSolvers& ref, const fem::ElasticityResult& fine,
                   const HarnessOptions& o, ModelOutcome base, SceneResult& result) {
  try {
    const MemoryProbe memory;
    Stopwatch setup;
    fem::ElasticityProblem problem = fem_problem(s, mesh, nu, spec.degree);
    problem.options.formulation = fem::Formulation::displacement;
    fem::ElasticitySolver solver(mesh, problem);
    const double construction = setup.seconds();
    const int updates = std::max(1, o.ramp_updates);
    const FemUpdates timed = timed_fem_updates(solver, updates, std::max(1, o.repeats));
    base.setup_seconds = construction + timed.setup_seconds;
    base.solve_seconds = timed.update_seconds;
    base.updates = updates;
    const fem::ElasticityResult r = solver.solve();  // the answer: the reference code's own solve
    base.memory_mib = memory.added_mib();
    base.detail = r.element + ", " + fem::to_string(r.solver);
    base.nodes = mesh.nodes.size();
    base.unknowns = r.n_dofs;
    // Natural frequencies (scene's [modes]): after the timed solves, outside their measurements.
    if (s.modes.count > 0) result.model_modes.push_back(fem_model_modes(solver, base, s.modes.count));
    const ReferenceAtPoints ref_here = reference_at(ref, mesh.nodes);
    const ReadOut at = read_out(s, base.level, mesh.nodes, result.qoi_point);
    std::vector<Vec3> unit_loads;  // the indentation's weights: contact loads only
    if (s.load.kind == LoadKind::contact) unit_loads = surface_nodal_loads(s, mesh, 1.0);
    for (const double mag : s.load.magnitudes) {
      ModelOutcome out = base;
      out.magnitude = mag;
      out.max_strain = r.max_abs_principal_strain * mag;
      const std::vector<Vec3> u = scaled(r.nodal_displacement, mag);
      finish_outcome(out, s, mesh.nodes, u, ref_here, mag, at, fine.max_abs_principal_strain,
                     result.qoi_point, scaled(unit_loads, mag), 0, 0.0);
      if (wants_fields(o, s, mag, fine.max_abs_principal_strain)) {
        write_model_fields(o, s, out, mesh.nodes, tet_cells(mesh.tets), u,
                           scaled(ref_here.u, mag));
      }
      result.outcomes.push_back(out);
    }
  } catch (const std::exception& e) {
    for (const double mag : s.load.magnitudes) {
      ModelOutcome out = base;
      out.magnitude = mag;
      out.failure = e.what();
      result.outcomes.push_back(out);
    }
    if (o.log) *o.log << "      FAILED: " << e.what() << "\n";
  }
}

/// The FEM transient's damping beside a dynamic model: the model's point damping c (force −c v
/// per node, seed 000 eq. 3.3) becomes mass-proportional damping α = c / m̄ with m̄ the model's
/// mean nodal mass: exact for uniform masses, an average otherwise.
double transient_mass_damping(const ModelSpec& spec, const msm::Problem& problem) {
  const double mean_mass = problem.mass.sum() / static_cast<double>(problem.mass.size());
  return spec.damping > 0.0 ? spec.damping / mean_mass : 0.0;
}

/// The FEM transient next to a dynamic model's history (transient_at: run once per probe, time
/// and damping).
void add_reference_history(History& h, const ReferenceSolvers& ref, const Vec3& probe,
                           const ModelSpec& spec, const msm::Problem& problem, double magnitude) {
  h.steps = spec.solver.steps;
  h.simulated_s = spec.solver.dt * static_cast<double>(spec.solver.steps);
  h.mass_damping = transient_mass_damping(spec, problem);
  h.reference_level = ref.transient_level;
  const auto& [t, u] = transient_at(ref, probe, h.simulated_s, h.mass_damping);
  h.reference_mm.clear();
  h.max_error_mm = 0.0;
  for (std::size_t k = 0; k < h.time_s.size(); ++k) {
    h.reference_mm.push_back(interpolate(t, u, h.time_s[k]) * magnitude * 1e3);
    h.max_error_mm = std::max(h.max_error_mm, std::abs(h.model_mm[k] - h.reference_mm[k]));
  }
}

/// What is solved for one load: the whole network, or its region of interest (the nodes beyond R
/// held and their unknowns removed: verification/roi).
struct SolvedSystem {
  const msm::Problem* problem = nullptr;
  const msm::MassSpringModel* model = nullptr;
  const msm::SpringNetwork* network = nullptr;
  Eigen::Index qoi = -1;  ///< the QoI node in the solved problem (−1 if the region holds it)
  std::unique_ptr<msm::RoiNetwork> roi;
  std::unique_ptr<msm::MassSpringModel> roi_model;
  std::unique_ptr<msm::Problem> roi_problem;

  /// Positions of the whole network from the solved ones (held nodes at rest).
  [[nodiscard]] Eigen::VectorXd to_full(const Eigen::VectorXd& x, const msm::Problem& full) const {
    if (!roi) return x;
    Eigen::VectorXd x_full = full.rest;
    for (std::size_t k = 0; k < roi->full_index.size(); ++k) {
      x_full.segment<3>(3 * static_cast<Eigen::Index>(roi->full_index[k])) =
          x.segment<3>(3 * static_cast<Eigen::Index>(k));
    }
    return x_full;
  }
};

SolvedSystem solved_system(const msm::Problem& full, const msm::MassSpringModel& model,
                           const msm::BuiltNetwork& built, const ModelSpec& spec,
                           const Vec3& qoi_point, std::size_t qoi) {
  const msm::SpringNetwork& network = built.network;
  SolvedSystem sys{&full, &model, &network, static_cast<Eigen::Index>(qoi), {}, {}, {}};
  if (spec.roi_radius <= 0.0) return sys;
  const std::vector<char> held = msm::held_nodes(full, qoi_point, spec.roi_radius);
  sys.roi = std::make_unique<msm::RoiNetwork>(
      msm::restrict_network(network, held, built.bending_rigidity.has_value()));
  sys.roi_model =
      msm::make_model(sys.roi->network, built.volume_kappa, spec.damping, built.bending_rigidity,
                      built.edge_pairs);
  sys.roi_problem =
      std::make_unique<msm::Problem>(msm::restrict_problem(full, *sys.roi, held, *sys.roi_model));
  sys.problem = sys.roi_problem.get();
  sys.model = sys.roi_model.get();
  sys.network = &sys.roi->network;
  const auto& index = sys.roi->full_index;
  const auto it = std::find(index.begin(), index.end(), static_cast<int>(qoi));
  sys.qoi = it == index.end() ? -1 : it - index.begin();
  return sys;
}

/// Solves `repeats` times (median time into out.solve_seconds, a solver's own set-up such as
/// implicit-euler-rest's factorisation added to out.setup_seconds); a dynamic solver's QoI
/// history (kHistorySamples samples) goes into out.history. Returns the solved positions.
Eigen::VectorXd timed_solve(const SolvedSystem& sys, const ModelSpec& spec, const Vec3& qoi_rest,
                            int repeats, ModelOutcome& out) {
  std::vector<double> times, setups;
  Eigen::VectorXd x;
  for (int k = 0; k < std::max(1, repeats); ++k) {
    msm::StepObserver on_step;
    if (spec.solver.is_dynamic()) {
      out.history = {};
      out.history.time_s.push_back(0.0);  // at rest
      out.history.model_mm.push_back(0.0);
      const long every = std::max(1L, spec.solver.steps / kHistorySamples);
      on_step = [&](int step, const Eigen::VectorXd& xs) {
        if (step % every != 0 && step != spec.solver.steps) return;
        out.history.time_s.push_back(step * spec.solver.dt);
        out.history.model_mm.push_back(
            sys.qoi < 0 ? 0.0 : (xs.segment<3>(3 * sys.qoi) - qoi_rest).norm() * 1e3);
      };
    }
    Stopwatch solve;
    msm::SolveResult r = msm::solve(*sys.problem, spec.solver, sys.network, on_step);
    const double wall = solve.seconds();
    // SolveResult::seconds excludes a solver's own set-up (implicit-euler-rest): count it there.
    const auto* dyn = std::get_if<msm::DynamicResult>(&r.detail);
    const double setup = dyn ? dyn->setup_seconds : 0.0;
    times.push_back(wall - setup);
    setups.push_back(setup);
    x = std::move(r.x);
  }
  out.solve_seconds = median(times);
  out.setup_seconds += median(setups);
  return x;
}

/// A flat per-dof vector (x0, y0, z0, x1, ...) as one Vec3 per node.
std::vector<Vec3> per_node(const Eigen::VectorXd& v) {
  std::vector<Vec3> out(static_cast<std::size_t>(v.size() / 3));
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = v.segment<3>(3 * static_cast<Eigen::Index>(i));
  }
  return out;
}

/// Node displacements x − rest, m.
std::vector<Vec3> displacements(const Eigen::VectorXd& x, const std::vector<Vec3>& nodes) {
  std::vector<Vec3> u = per_node(x);
  for (std::size_t i = 0; i < u.size(); ++i) u[i] -= nodes[i];
  return u;
}

/// A mass-spring model's description in results: topology, rules, solver, region.
std::string msm_detail(const std::string& topology, const ModelSpec& spec) {
  std::ostringstream d;
  if (spec.kind == ModelKind::network) {  // its springs and masses are the file's own
    d << topology << ", " << msm::to_string(spec.solver);
  } else if (spec.edge_pairs) {  // no springs, so no stiffness rule
    d << topology << ", " << msm::to_string(spec.mass) << " masses, "
      << msm::to_string(spec.solver);
  } else {
    d << topology << ", " << msm::to_string(spec.stiffness) << " stiffness, "
      << msm::to_string(spec.mass) << " masses, " << msm::to_string(spec.solver);
  }
  if (spec.roi_radius > 0.0) d << ", region of interest R = " << spec.roi_radius * 1e3 << " mm";
  if (!spec.calibration.empty()) d << ", calibrated (" << spec.calibration.filename().string() << ")";
  return d.str();
}

/// One load of a mass-spring model: build its problem, solve (timed), compare.
void run_msm_load(const Scene& s, const ModelSpec& spec, const msm::BuiltNetwork& built,
                  const msm::MassSpringModel& model, const TetMesh& mesh, const ReferenceSolvers& ref,
                  const ReferenceAtPoints& ref_here, const ReadOut& at, double ref_strain_unit,
                  const Vec3& qoi_point, const HarnessOptions& o, ModelOutcome& out) {
  const std::vector<Vec3>& nodes = built.network.nodes;
  const double mag = out.magnitude;
  const msm::Problem full = msm_problem(s, model, built, mesh, mag);
  const SolvedSystem sys = solved_system(full, model, built, spec, qoi_point, at.qoi);
  out.unknowns = free_unknowns(*sys.problem);
  const MemoryProbe solve_memory;
  Eigen::VectorXd x_solved;
  if (msm::supports_updates(spec.solver)) {
    UpdateSequence seq = timed_updates(*sys.problem, spec.solver, o.ramp_updates, o.repeats);
    out.setup_seconds += seq.setup_seconds;
    out.solve_seconds = seq.update_seconds;
    out.updates = seq.updates;
    out.iterations_per_update = seq.iterations_per_update;
    out.factorisations_per_update = seq.factorisations_per_update;
    x_solved = std::move(seq.x);
  } else {
    x_solved = timed_solve(sys, spec, nodes[at.qoi], o.repeats, out);
  }
  out.memory_mib = std::max(out.memory_mib, solve_memory.added_mib());
  // The FEM transient beside the history (computed once per scene and ν, then cached) costs the
  // reference's time and memory, not the model's: outside the measurements above.
  if (!out.history.time_s.empty()) {
    add_reference_history(out.history, ref, nodes[at.qoi], spec, *sys.problem, mag);
  }
  out.max_strain = sys.model->max_strain(x_solved);
  const std::vector<Vec3> u = displacements(sys.to_full(x_solved, full), nodes);
  std::vector<Vec3> loads;
  if (s.load.kind == LoadKind::contact) loads = per_node(full.external_force);
  finish_outcome(out, s, nodes, u, ref_here, mag, at, ref_strain_unit, qoi_point, loads,
                 spec.solver.steps, spec.solver.dt);
  if (wants_fields(o, s, mag, ref_strain_unit)) {
    write_model_fields(o, s, out, nodes, network_cells(built.network), u, scaled(ref_here.u, mag));
  }
}

/// Why a model with a ν-limited term cannot run at this ν (empty: it can): the hybrid model
/// refuses ν outside [1/4, 1/2) (κ = λ − μ negative or infinite), the homogenised one ν = 1/2 and
/// ν below its mesh's floor (found when its network is built, which is then kept in built_or),
/// the edge-pair model ν = 1/2 (λ infinite).
std::string refusal_at(const Scene& s, const ModelSpec& spec, double nu, const TetMesh& mesh,
                       const VesselParams& vessel, std::optional<msm::BuiltNetwork>& built_or) {
  try {
    if (spec.volume_term && (nu < 0.25 || nu >= 0.5)) {
      if (spec.volume_moduli == msm::VolumeModuli::golec || nu >= 0.5) {
        (void)msm::hybrid_moduli(s.youngs_modulus, nu);
      } else {
        built_or.emplace(scene_network(s, spec, mesh, vessel, nu));
      }
    }
    if (spec.edge_pairs && nu >= 0.5) (void)msm::lame_parameters(s.youngs_modulus, nu);
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

/// A mass-spring model at every load magnitude.
void run_msm_model(const Scene& s, const ModelSpec& spec, double nu, const TetMesh& mesh,
                   const ReferenceSolvers& ref, const fem::ElasticityResult& fine,
                   const HarnessOptions& o, Progress& progress, ModelOutcome base,
                   SceneResult& result) {
  // A ν the model refuses is recorded as failed, as P1 is at ν = 0.5, not fatal to the run.
  const MemoryProbe setup_memory;
  Stopwatch setup;  // the homogenised rule's fit is part of the set-up
  std::optional<msm::BuiltNetwork> built_or;
  VesselParams vessel = s.vessel;
  vessel.level = base.level;
  const std::string why = refusal_at(s, spec, nu, mesh, vessel, built_or);
  if (!why.empty()) {
    for (const double mag : s.load.magnitudes) {
      ModelOutcome out = base;
      out.magnitude = mag;
      out.failure = why;
      result.outcomes.push_back(out);
    }
    return;
  }
  if (!built_or) built_or.emplace(scene_network(s, spec, mesh, vessel, nu));
  const msm::BuiltNetwork& built = *built_or;
  if (spec.kind == ModelKind::network) {
    // The reference is read at the network's rest positions: every node must lie in its mesh
    // (within the evaluation's own tolerance), else the run stops naming them.
    msm::require_nodes_inside(built.network.nodes, *ref.fine_mesh, kOutsideTolerance,
                              s.source.string() + ": model " + spec.name + ": " + built.file);
  }
  const auto model_ptr = msm::make_model(built, spec.damping);
  const msm::MassSpringModel& model = *model_ptr;
  base.setup_seconds = setup.seconds();
  base.memory_mib = setup_memory.added_mib();
  base.detail = msm_detail(built.topology, spec);
  base.roi_radius = spec.roi_radius;
  base.nodes = built.network.nodes.size();
  if (s.modes.count > 0) {
    // Natural frequencies (scene's [modes]) of the whole model with the scene's supports (a
    // region of interest is a solve-time restriction, not another vessel), outside the timings.
    const msm::Problem at_rest = msm_problem(s, model, built, mesh, 0.0);
    result.model_modes.push_back(msm_model_modes(at_rest, base, s.modes.count));
  }
  const ReferenceAtPoints ref_here = reference_at(ref, built.network.nodes);
  const ReadOut at = read_out(s, base.level, built.network.nodes, result.qoi_point);
  for (const double mag : s.load.magnitudes) {
    progress.begin(spec.name + " at " + std::to_string(mag) + " (" + to_string(s.load.kind) + ")");
    ModelOutcome out = base;
    out.magnitude = mag;
    try {
      if (finite_strain_judges(s, fine.max_abs_principal_strain, mag)) {
        // The finite-strain displacement divided by the magnitude: finish_outcome scales the
        // reference by it. No coarser finite-strain level: no Richardson uncertainty; the
        // linear-validity flag does not apply (strain 0 passed).
        out.reference = "finite-strain";
        ReferenceAtPoints finite_here;
        finite_here.u = scaled(
            finite_reference(ref, mag).displacement_at(built.network.nodes, kOutsideTolerance),
            1.0 / mag);
        run_msm_load(s, spec, built, model, mesh, ref, finite_here, at, 0.0, result.qoi_point, o,
                     out);
      } else {
        run_msm_load(s, spec, built, model, mesh, ref, ref_here, at,
                     fine.max_abs_principal_strain, result.qoi_point, o, out);
      }
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      out.ok = false;
      out.failure = e.what();
      if (o.log) *o.log << "      FAILED: " << e.what() << "\n";
    }
    result.outcomes.push_back(out);
    progress.end();
  }
}

/// The largest |Δl|/l over the edges of the exchange cells under displacements u: the strain an
/// outside model's answer implies, since its own elements are not known.
double largest_edge_strain(const std::vector<Vec3>& nodes, const VtuCells& cells,
                           const std::vector<Vec3>& u) {
  const auto per = static_cast<std::size_t>(cells.points_per_cell);
  double worst = 0.0;
  for (std::size_t c = 0; c + per <= cells.connectivity.size(); c += per) {
    for (std::size_t i = 0; i < per; ++i) {
      for (std::size_t j = i + 1; j < per; ++j) {
        const std::size_t a = cells.connectivity[c + i], b = cells.connectivity[c + j];
        const double rest = (nodes[b] - nodes[a]).norm();
        const double now = (nodes[b] + u[b] - nodes[a] - u[a]).norm();
        if (rest > 0.0) worst = std::max(worst, std::abs(now - rest) / rest);
      }
    }
  }
  return worst;
}

/// A dynamic outside model's QoI history (its history.csv) beside the FEM transient, sampled to
/// at most kHistorySamples + 1 points.
History outside_history(const ExternalAnswer& a, const ReferenceSolvers& ref, const Vec3& probe,
                        const ModelSpec& spec, const msm::Problem& problem, double magnitude) {
  History h;
  const std::size_t n = a.history_time_s.size();
  const std::size_t every = std::max<std::size_t>(1, n / kHistorySamples);
  for (std::size_t k = 0; k < n; ++k) {
    if (k % every != 0 && k + 1 != n) continue;
    h.time_s.push_back(a.history_time_s[k]);
    h.model_mm.push_back(a.history_u[k].norm() * 1e3);
  }
  ModelSpec as_run = spec;  // add_reference_history reads the run's dt and steps from the solver
  as_run.solver.dt = spec.external.dt;
  as_run.solver.steps = spec.external.steps;
  as_run.damping = 0.0;
  add_reference_history(h, ref, probe, as_run, problem, magnitude);
  return h;
}

/// A model outside the suite (kinds external and displacements; verification/external_model.hpp)
/// at every load: the case written to its exchange folder and its command run (external), or the
/// answer read from the folder the export named (displacements); then compared as any model. A
/// case whose command fails, times out or answers badly is recorded as failed with the reason,
/// and the run goes on.
void run_outside_model(const Scene& s, const ModelSpec& spec, double nu, const TetMesh& mesh,
                       const ReferenceSolvers& ref, const fem::ElasticityResult& fine,
                       const HarnessOptions& o, Progress& progress, ModelOutcome base,
                       SceneResult& result) {
  const ExchangeNetwork network = exchange_network(s, spec, mesh, base.level, nu);
  const std::vector<Vec3>& nodes = network.built.network.nodes;
  const bool external = spec.kind == ModelKind::external;
  std::filesystem::path root = spec.external.directory;
  if (external) {
    const std::filesystem::path exchange =
        o.exchange_dir.empty() ? std::filesystem::temp_directory_path() /
                                     ("vesselverify-exchange-" + std::to_string(getpid()))
                               : o.exchange_dir;
    root = exchange / file_stem(s.name) / file_stem(spec.name);
  }
  std::ostringstream detail;
  if (external) {
    detail << "external:";
    for (const auto& a : spec.external.command) detail << " " << a;
  } else {
    detail << "displacements from " << spec.external.directory.string();
  }
  detail << "; " << network.description;
  if (spec.external.steps > 0) {
    detail << "; dynamic, " << spec.external.steps << " steps of " << spec.external.dt << " s";
  }
  base.detail = detail.str();
  base.nodes = nodes.size();
  const ReferenceAtPoints ref_here = reference_at(ref, nodes);
  const ReadOut at = read_out(s, base.level, nodes, result.qoi_point);
  for (const double mag : s.load.magnitudes) {
    progress.begin(spec.name + " at " + std::to_string(mag) + " (" + to_string(s.load.kind) + ", " +
                   to_string(spec.kind) + ")");
    ModelOutcome out = base;
    out.magnitude = mag;
    try {
      const ExchangeProblem p =
          exchange_problem(network, s, spec, mesh, base.level, nu, mag, result.qoi_point);
      out.unknowns = free_unknowns(p.problem);
      ExternalAnswer answer;
      if (external) {
        const std::filesystem::path dir = write_exchange_case(root, p);
        ProcessResult process;
        answer = run_external_case(spec.external, dir, nodes.size(), &process);
        out.solve_seconds = process.wall_seconds;
        out.timing_source = "process";
      } else {
        answer = read_external_answer(root / p.id, nodes.size());
        out.timing_source = "none";
      }
      if (answer.solve_seconds) {
        out.solve_seconds = *answer.solve_seconds;
        out.setup_seconds = answer.setup_seconds.value_or(0.0);
        out.timing_source = "simulator";
      }
      if (!answer.history_time_s.empty() && spec.external.steps > 0) {
        out.history = outside_history(answer, ref, nodes[at.qoi], spec, p.problem, mag);
      }
      out.max_strain = largest_edge_strain(nodes, network.cells, answer.u);
      std::vector<Vec3> loads;
      if (s.load.kind == LoadKind::contact) loads = p.loads;
      finish_outcome(out, s, nodes, answer.u, ref_here, mag, at, fine.max_abs_principal_strain,
                     result.qoi_point, loads, spec.external.steps, spec.external.dt);
      if (wants_fields(o, s, mag, fine.max_abs_principal_strain)) {
        write_model_fields(o, s, out, nodes, network.cells, answer.u, scaled(ref_here.u, mag));
      }
    } catch (const ExternalModelError& e) {
      out.ok = false;
      out.failure = e.what();
      if (o.log) *o.log << "      FAILED: " << e.what() << "\n";
    }
    result.outcomes.push_back(out);
    progress.end();
  }
}

}  // namespace

QuantityErrors quantity_errors(const Budget& budget, const std::vector<Vec3>& nodes,
                               const std::vector<Vec3>& u_model, const std::vector<Vec3>& u_ref,
                               std::size_t qoi, const Vec3& qoi_point,
                               const std::vector<Vec3>& loads, const History& history) {
  QuantityErrors q;
  q.contact_point_mm = (u_model[qoi] - u_ref[qoi]).norm() * 1e3;
  if (!history.time_s.empty())
    q.contact_point_mm = std::max(q.contact_point_mm, history.max_error_mm);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    q.field_mm = std::max(q.field_mm, (u_model[i] - u_ref[i]).norm() * 1e3);
  }
  if (budget.quantity == BudgetQuantity::patch && budget.radius > 0.0) {
    double worst = 0.0;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      if ((nodes[i] - qoi_point).norm() <= budget.radius) {
        worst = std::max(worst, (u_model[i] - u_ref[i]).norm());
      }
    }
    q.patch_mm = worst * 1e3;
  }
  if (!loads.empty()) {
    // Work-conjugate indentation: the total contact force F does work F·d on the wall.
    Vec3 total = Vec3::Zero();
    double work_model = 0.0;
    double work_ref = 0.0;
    for (std::size_t i = 0; i < loads.size(); ++i) {
      total += loads[i];
      work_model += loads[i].dot(u_model[i]);
      work_ref += loads[i].dot(u_ref[i]);
    }
    const double force = total.norm();
    if (force > 0.0) {
      const double d_model = work_model / force;
      const double d_ref = work_ref / force;
      q.indentation_mm = d_model * 1e3;
      q.indentation_reference_mm = d_ref * 1e3;
      q.reaction_mN = d_model > 0.0 ? force * std::abs(d_ref - d_model) / d_model * 1e3
                                    : std::numeric_limits<double>::infinity();
    }
  }
  return q;
}

double budget_magnitude(const Scene& s, double max_abs_strain_unit) {
  return representative_load(s.load.magnitudes, max_abs_strain_unit,
                             s.budget.magnitude > 0.0 ? std::optional(s.budget.magnitude)
                                                      : std::nullopt);
}

double budget_quantity_error(const QuantityErrors& q, BudgetQuantity quantity) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  switch (quantity) {
    case BudgetQuantity::contact_point:
      return q.contact_point_mm;
    case BudgetQuantity::field:
      return q.field_mm;
    case BudgetQuantity::patch:
      return q.patch_mm.value_or(nan);
    case BudgetQuantity::reaction:
      return q.reaction_mN.value_or(nan);
  }
  return nan;
}

UpdateSequence timed_updates(const msm::Problem& problem, const msm::SolverSpec& solver,
                             int updates, int repeats) {
  if (!msm::supports_updates(solver)) {
    throw InputError("solver " + msm::to_string(solver) +
                     ": the harness times prepared updates of static and linear solvers only");
  }
  if (updates < 1) {
    throw InputError("updates: expected a load ramp of >= 1 updates, got " +
                     std::to_string(updates));
  }
  UpdateSequence seq;
  seq.updates = updates;
  std::vector<double> setups, times;
  for (int rep = 0; rep < std::max(1, repeats); ++rep) {
    const std::unique_ptr<msm::Updater> up = msm::prepare_updates(problem, solver);
    setups.push_back(up->setup_seconds());
    int iterations = 0, factorisations = 0;
    for (int k = 1; k <= updates; ++k) {
      const Eigen::VectorXd f =
          problem.external_force * (static_cast<double>(k) / static_cast<double>(updates));
      const msm::UpdateResult r = up->update(f);
      times.push_back(r.seconds);
      iterations += r.iterations;
      factorisations += r.factorisations;
    }
    seq.iterations_per_update = static_cast<double>(iterations) / updates;
    seq.factorisations_per_update = static_cast<double>(factorisations) / updates;
    seq.x = up->state();
  }
  seq.setup_seconds = median(setups);
  seq.update_seconds = median(times);
  return seq;
}

std::vector<double> frequency_ratios(const ModalOutcome& model, const ModalOutcome& reference) {
  std::vector<double> r;
  if (!model.ok || !reference.ok) return r;
  const std::size_t n = std::min(model.frequencies_hz.size(), reference.frequencies_hz.size());
  for (std::size_t k = 0; k < n; ++k) {
    const double f = reference.frequencies_hz[k];
    r.push_back(f > 0.0 ? model.frequencies_hz[k] / f : 0.0);
  }
  return r;
}

std::pair<double, long> time_per_update(double solve_seconds, long steps, double dt,
                                        double period) {
  if (period <= 0.0) return {0.0, 0};
  if (steps <= 0 || dt <= 0.0) return {solve_seconds, 0};
  // One update advances the simulation by the period: ⌈period/dt⌉ steps (a relative 1e-9 keeps
  // 1 ms / 1e-5 s at 100 steps despite round-off), at least one.
  const long per_update = std::max(1L, static_cast<long>(std::ceil(period / dt * (1.0 - 1e-9))));
  return {solve_seconds / static_cast<double>(steps) * static_cast<double>(per_update), per_update};
}

Scene quick_variant(Scene s) {
  s.model_levels = {0};
  s.vessel.level = 0;
  const double mixed_threshold = fem::SolverOptions{}.mixed_threshold;
  const bool mixed = std::any_of(s.poisson_ratios.begin(), s.poisson_ratios.end(),
                                 [&](double nu) { return nu >= mixed_threshold; });
  s.reference_level = std::min(s.reference_level, mixed ? 0 : 1);
  if (s.load.magnitudes.size() > 2) {
    s.load.magnitudes = {s.load.magnitudes.front(), s.load.magnitudes.back()};
  }
  return s;
}

namespace {

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

  SceneReferences() = default;
  SceneReferences(const SceneReferences&) = delete;
  SceneReferences& operator=(const SceneReferences&) = delete;
};

/// The scene's mesh at `level`: one of those already read, else read once into other_meshes.
const TetMesh& mesh_at_level(SceneReferences& r, int level, const HarnessOptions& o) {
  if (level == r.scene.reference_level) return r.fine_mesh;
  if (r.coarse_mesh && level == r.scene.reference_level - 1) return *r.coarse_mesh;
  if (r.coarsest_mesh && level == r.scene.reference_level - 2) return *r.coarsest_mesh;
  if (r.model_meshes.count(level)) return r.model_meshes.at(level);
  auto& slot = r.other_meshes[level];
  if (!slot) slot = std::make_unique<TetMesh>(scene_mesh(r.scene, level, o.cache_dir));
  return *slot;
}

/// The scene's meshes (generated or read from the mesh cache; gmsh is not thread-safe, so this
/// runs on one thread).
std::unique_ptr<SceneReferences> scene_meshes(const Scene& scene, const HarnessOptions& o,
                                              std::ostream& log) {
  auto r = std::make_unique<SceneReferences>();
  r->fine_mesh = scene_mesh(scene, scene.reference_level, o.cache_dir);
  r->scene = resolve_file_vessel(scene, r->fine_mesh);
  const Scene& s = r->scene;
  if (!s.vessel.parametric()) {
    const Vec3 p = s.load.contact.point * 1e3;
    log << "  " << (s.load.kind == LoadKind::contact ? "contact" : "QoI") << " point on "
        << s.load.contact.surface_group << ": (" << p.x() << ", " << p.y() << ", " << p.z()
        << ") mm\n";
  }
  for (const int level : s.model_levels) {
    r->model_meshes.emplace(level, scene_mesh(s, level, o.cache_dir));
  }
  if (s.reference_level > 0) {
    r->coarse_mesh = std::make_unique<TetMesh>(scene_mesh(s, s.reference_level - 1, o.cache_dir));
  }
  if (s.reference_level > 1) {
    r->coarsest_mesh =
        std::make_unique<TetMesh>(scene_mesh(s, s.reference_level - 2, o.cache_dir));
  }
  // The modal reference's and the FEM transient's meshes (scene's [modes], [transient]).
  r->modal_level = modal_reference_level(s);
  if (s.modes.count > 0) r->modal_reference_mesh = &mesh_at_level(*r, r->modal_level, o);
  r->transient_level = transient_reference_level(s);
  r->transient_mesh = &mesh_at_level(*r, r->transient_level, o);
  r->at_nu.resize(s.poisson_ratios.size());
  return r;
}

std::string reference_label(const Scene& s, double nu) {
  return "reference P2 (level " + std::to_string(s.reference_level) + ", ν = " +
         std::to_string(nu) + ")";
}

std::string modal_label(const Scene& s, const SceneReferences& r, double nu) {
  return "modal reference P2 (level " + std::to_string(r.modal_level) + ", ν = " +
         std::to_string(nu) + ", " + std::to_string(s.modes.count) + " modes)";
}

/// The GCI order of the scene's reference (fem::gci_order): observed from the QoI point's
/// displacement along the fine level's direction there on three levels when the coarsest exists
/// (solved here), else the assumed order of the scene's load.
fem::GciOrder reference_gci_order(const Scene& s, const SceneReferences& r,
                                  const ReferenceSolvers& ref, double nu) {
  const double assumed = s.load.kind == LoadKind::contact ? kAssumedReferenceOrderContact
                                                          : kAssumedReferenceOrderDistributed;
  if (!r.coarsest_mesh) return fem::gci_order(std::nullopt, assumed);
  std::unique_ptr<fem::ElasticitySolver> coarsest;
  solve_reference(coarsest, *r.coarsest_mesh, fem_problem(s, *r.coarsest_mesh, nu, 2), ref.cache);
  const Vec3 q = qoi_point(s);
  const Vec3 fine = ref.fine->displacement_at({q}, kOutsideTolerance)[0];
  const Vec3 dir = fine.norm() > 0.0 ? Vec3(fine.normalized()) : Vec3(1.0, 0.0, 0.0);
  const double medium = ref.coarse->displacement_at({q}, kOutsideTolerance)[0].dot(dir);
  const double coarse = coarsest->displacement_at({q}, kOutsideTolerance)[0].dot(dir);
  return fem::gci_order(std::vector<double>{coarse, medium, fine.dot(dir)}, assumed);
}

/// The scene's P2 reference at its k-th ν (unit load), on the fine level and the one below.
void solve_reference_at(const Scene& s, SceneReferences& r, std::size_t k,
                        const HarnessOptions& o) {
  Stopwatch clock;
  const double nu = s.poisson_ratios[k];
  SceneReferences::AtNu& a = r.at_nu[k];
  ReferenceSolvers& ref = a.ref;
  ref.cache = o.solution_cache;
  ref.fine_mesh = &r.fine_mesh;
  ref.fine_problem = fem_problem(s, r.fine_mesh, nu, 2);
  const fem::ElasticityResult& fine =
      solve_reference(ref.fine, r.fine_mesh, ref.fine_problem, ref.cache);
  ref.transient_level = r.transient_level;
  if (r.transient_mesh != &r.fine_mesh && has_dynamic_models(s)) {
    ref.transient_mesh = r.transient_mesh;
    ref.transient_problem = fem_problem(s, *r.transient_mesh, nu, 2);
    ref.transient_solver =
        std::make_unique<fem::ElasticitySolver>(*r.transient_mesh, ref.transient_problem);
  }
  if (r.coarse_mesh) {
    solve_reference(ref.coarse, *r.coarse_mesh, fem_problem(s, *r.coarse_mesh, nu, 2), ref.cache);
    ref.gci = reference_gci_order(s, r, ref, nu);
    a.info.gci_order = ref.gci.order;
    a.info.gci_order_source = ref.gci.source;
    a.info.gci_safety_factor = ref.gci.safety_factor;
    a.info.gci_note = ref.gci.note;
  }
  a.info.poisson_ratio = nu;
  a.info.element = fine.element;
  a.info.level = s.reference_level;
  a.info.dofs = fine.n_dofs + fine.n_pressure_dofs;
  a.info.solve_seconds = fine.timings.assembly + fine.timings.solve;
  a.info.max_abs_strain_unit = fine.max_abs_principal_strain;
  a.info.budget_magnitude = budget_magnitude(s, fine.max_abs_principal_strain);
  a.seconds = clock.seconds();
}

void solve_modal_reference_at(const Scene& s, SceneReferences& r, std::size_t k) {
  if (!r.modal_reference_mesh) return;
  Stopwatch clock;
  r.at_nu[k].modes = reference_modes(s, s.poisson_ratios[k], *r.modal_reference_mesh, r.modal_level);
  r.at_nu[k].seconds += clock.seconds();
}

/// A FEM transient a dynamic model will be compared with: its probe node, simulated time and
/// mass damping, as add_reference_history asks for them.
struct TransientRequest {
  Vec3 probe;
  double duration = 0.0;
  double alpha = 0.0;
  auto operator<=>(const TransientRequest& o) const {
    return std::tie(probe.x(), probe.y(), probe.z(), duration, alpha) <=>
           std::tie(o.probe.x(), o.probe.y(), o.probe.z(), o.duration, o.alpha);
  }
  bool operator==(const TransientRequest& o) const { return (*this <=> o) == 0; }
};

/// The distinct FEM transients of the scene's dynamic models at its k-th ν, so that the parallel
/// pass runs them and the models' pass finds them in ReferenceSolvers::transients. Models on a
/// region of interest or with an automatic time step are left to the models' pass.
std::vector<TransientRequest> transient_requests(const Scene& s, const SceneReferences& r,
                                                 std::size_t k) {
  const double nu = s.poisson_ratios[k];
  const Vec3 qoi = qoi_point(s);
  std::vector<TransientRequest> out;
  for (const auto& [level, mesh] : r.model_meshes) {
    for (const ModelSpec& spec : s.models) {
      if (spec.kind == ModelKind::fem || !spec.solver.is_dynamic() || spec.roi_radius > 0.0 ||
          spec.solver.dt <= 0.0 ||
          (spec.volume_term &&
           (nu >= 0.5 || (nu < 0.25 && spec.volume_moduli == msm::VolumeModuli::golec))) ||
          (spec.edge_pairs && nu >= 0.5)) {
        continue;
      }
      VesselParams vessel = s.vessel;
      vessel.level = level;
      std::optional<msm::BuiltNetwork> built_or;
      try {
        built_or.emplace(scene_network(s, spec, mesh, vessel, nu));
      } catch (const InputError&) {
        if (!spec.volume_term) throw;
        continue;  // the homogenised rule below its mesh's floor: the models' pass records it
      }
      const msm::BuiltNetwork& built = *built_or;
      const auto model = msm::make_model(built, spec.damping);
      const msm::Problem at_rest = msm_problem(s, *model, built, mesh, 0.0);
      const TransientRequest q{built.network.nodes[nearest_node(built.network.nodes, qoi)],
                               spec.solver.dt * static_cast<double>(spec.solver.steps),
                               transient_mass_damping(spec, at_rest)};
      if (std::find(out.begin(), out.end(), q) == out.end()) out.push_back(q);
    }
  }
  return out;
}

void log_modal_failure(std::ostream& log, const SceneReferences::AtNu& a) {
  if (a.modes && !a.modes->ok) log << "      modal reference FAILED: " << a.modes->failure << "\n";
}

std::size_t model_cases(const Scene& s, const HarnessOptions& o) {
  const std::size_t loads = o.budget_load_only ? 1 : s.load.magnitudes.size();
  std::size_t cases = 0;
  for (const auto& m : s.models) cases += m.kind == ModelKind::fem ? 1 : loads;
  return s.poisson_ratios.size() * s.model_levels.size() * cases;
}

/// A FEM or mass-spring model at one ν and level: `run` (run_fem_model or run_msm_model into the
/// SceneResult it is given), or, with an outcome cache, the outcomes, natural frequencies and VTU
/// fields a run of the same model, scene, ν, level, loads, mesh, executable and machine stored.
/// Each outcome says whether its timings were measured now or read from the cache.
void run_through_cache(const Scene& s, const ModelSpec& spec, double nu, int level,
                       const TetMesh& mesh, const HarnessOptions& o, double ref_strain_unit,
                       Progress& progress, const std::string& fem_label, SceneResult& result,
                       const std::function<void(SceneResult&)>& run) {
  const auto measure = [&] {
    SceneResult part;
    part.scene = s;
    part.qoi_point = result.qoi_point;
    run(part);
    ModelRun measured{std::move(part.outcomes), std::move(part.model_modes), {}};
    for (const ModelOutcome& out : measured.outcomes) {
      if (!out.ok || !wants_fields(o, s, out.magnitude, ref_strain_unit)) continue;
      const std::filesystem::path file = fields_file(s, out);
      std::ifstream in(o.fields_dir / file, std::ios::binary);
      if (in) {
        measured.field_files.emplace_back(
            file.string(), std::string(std::istreambuf_iterator<char>(in), {}));
      }
    }
    return measured;
  };
  const auto keep = [&](ModelRun run_result, const TimingProvenance& timing) {
    for (ModelOutcome& out : run_result.outcomes) {
      out.timing = timing;
      result.outcomes.push_back(std::move(out));
    }
    for (ModalOutcome& m : run_result.modes) result.model_modes.push_back(std::move(m));
  };
  if (!o.outcome_cache || !o.outcome_cache->enabled()) {
    keep(measure(), {false, utc_now()});
    return;
  }
  bool measured_now = false;
  TimingProvenance timing;
  const std::string stored = o.outcome_cache->get(
      model_run_key(s, spec, nu, level, s.load.magnitudes, mesh, o),
      [&] {
        measured_now = true;
        return serialise(measure());
      },
      timing);
  ModelRun cached = deserialise_model_run(stored);
  if (!measured_now) {  // the progress lines and the fields a measurement would have written
    if (spec.kind == ModelKind::fem) {
      progress.begin(fem_label + ", from the outcome cache");
      progress.end();
    } else {
      for (const ModelOutcome& out : cached.outcomes) {
        std::ostringstream what;
        what << spec.name << " at " << out.magnitude << " (" << to_string(s.load.kind)
             << "), from the outcome cache";
        progress.begin(what.str());
        progress.end();
      }
    }
    for (const auto& [file, bytes] : cached.field_files) {
      const std::filesystem::path path = o.fields_dir / file;
      std::filesystem::create_directories(path.parent_path());
      write_file_atomically(path, [&](std::ostream& out) { out << bytes; }, true);
    }
  }
  keep(std::move(cached), timing);
}

/// The scene's models against its references (solved). `progress` counts one case per model,
/// level, ν and load; `solve_here` solves each ν's reference as the models reach it (serial runs).
SceneResult run_models(SceneReferences& r, const HarnessOptions& o, Progress& progress,
                       bool solve_here, std::ostream& log) {
  const Scene& s = r.scene;
  SceneResult result;
  result.scene = s;
  result.qoi_point = qoi_point(s);
  for (std::size_t k = 0; k < s.poisson_ratios.size(); ++k) {
    const double nu = s.poisson_ratios[k];
    SceneReferences::AtNu& a = r.at_nu[k];
    if (solve_here) {
      progress.begin(reference_label(s, nu));
      solve_reference_at(s, r, k, o);
      fem::release_kept_factors();  // the timed models below run without gigabytes held
      progress.end();
      if (r.modal_reference_mesh) {
        progress.begin(modal_label(s, r, nu));
        solve_modal_reference_at(s, r, k);
        log_modal_failure(log, a);
        progress.end();
      }
    }
    result.references.push_back(a.info);
    if (a.modes) result.reference_modes.push_back(*a.modes);
    const fem::ElasticityResult& fine = a.ref.fine->result();
    Scene at_nu = s;  // the scene's loads for this ν (only the budget's, if asked)
    if (o.budget_load_only) at_nu.load.magnitudes = {a.info.budget_magnitude};

    for (const auto& [level, mesh] : r.model_meshes) {
      for (const auto& spec : s.models) {
        ModelOutcome base;
        base.model = spec.name;
        base.kind = to_string(spec.kind);
        base.poisson_ratio = nu;
        base.level = level;
        if (spec.kind == ModelKind::external || spec.kind == ModelKind::displacements) {
          run_outside_model(at_nu, spec, nu, mesh, a.ref, fine, o, progress, base, result);
          continue;
        }
        const std::string fem_label = spec.name + " (FEM P" + std::to_string(spec.degree) +
                                      ", level " + std::to_string(level) + ")";
        run_through_cache(at_nu, spec, nu, level, mesh, o, fine.max_abs_principal_strain, progress,
                          fem_label, result, [&](SceneResult& part) {
                            if (spec.kind == ModelKind::fem) {
                              progress.begin(fem_label);
                              run_fem_model(at_nu, spec, nu, mesh, a.ref, fine, o, base, part);
                              progress.end();
                            } else {
                              run_msm_model(at_nu, spec, nu, mesh, a.ref, fine, o, progress, base,
                                            part);
                            }
                          });
      }
    }
  }
  return result;
}

/// The parallel pass's log: one line per finished task, numbered, with the pass's elapsed time.
class PassLog {
 public:
  PassLog(std::ostream& log, std::size_t total) : log_(log), total_(total) {}
  /// `after`: more lines (each ending in a newline) kept with this one.
  void done(const std::string& what, double seconds, const std::string& after = "") {
    const std::lock_guard lock(mutex_);
    std::ostringstream line;  // its own precision: the caller's stream keeps its settings
    line << "  [" << ++finished_ << "/" << total_ << "] " << what << " in " << std::setprecision(3)
         << seconds << " s (elapsed " << clock_.seconds() << " s)\n"
         << after;
    log_ << line.str();
  }

 private:
  std::ostream& log_;
  std::size_t total_, finished_ = 0;
  std::mutex mutex_;
  Stopwatch clock_;
};

/// The dynamic models' FEM transients of every (scene, ν) case, each its own task, `jobs` at a
/// time (after the references they are run on).
void run_all_transients(std::vector<std::unique_ptr<SceneReferences>>& refs,
                        const std::vector<std::pair<std::size_t, std::size_t>>& cases, int jobs,
                        std::ostream& log) {
  struct Transient {
    std::size_t scene, nu;
    TransientRequest request;
  };
  std::vector<Transient> transients;
  for (const auto& [i, k] : cases) {
    for (const TransientRequest& q : transient_requests(refs[i]->scene, *refs[i], k)) {
      transients.push_back({i, k, q});
    }
  }
  if (transients.empty()) return;
  log << "FEM transients of the dynamic models: " << transients.size() << ", " << jobs
      << " at a time\n";
  PassLog pass(log, transients.size());
  std::mutex seconds_mutex;
  parallel_solves(transients.size(), jobs, [&](std::size_t t) {
    const Transient& x = transients[t];
    SceneReferences& r = *refs[x.scene];
    Stopwatch watch;
    (void)transient_at(r.at_nu[x.nu].ref, x.request.probe, x.request.duration, x.request.alpha);
    const double seconds = watch.seconds();
    {
      const std::lock_guard lock(seconds_mutex);
      r.at_nu[x.nu].seconds += seconds;  // the scene's time includes its references'
    }
    std::ostringstream what;
    what << r.scene.name << ": FEM transient (ν = " << r.scene.poisson_ratios[x.nu] << ", "
         << x.request.duration << " s, α = " << x.request.alpha << " 1/s)";
    pass.done(what.str(), seconds);
  });
}

/// Every scene's references, `o.jobs` solves at a time, the cores shared among the solves running
/// (parallel_solves). Scenes whose fine problems have the same matrix (mesh, material, supports:
/// the solution cache's key without the loads) are solved in one task, one after the other, so
/// that the later ones read the first's solution cache entry (the same loads) or reuse its kept
/// CHOLMOD factor (other loads: contact_straight's and gravity_sag's). Then the dynamic models'
/// FEM transients (run_all_transients).
void solve_all_references(std::vector<std::unique_ptr<SceneReferences>>& refs,
                          const HarnessOptions& o, std::ostream& log) {
  std::vector<std::pair<std::size_t, std::size_t>> cases;  // (scene, ν index)
  for (std::size_t i = 0; i < refs.size(); ++i) {
    for (std::size_t k = 0; k < refs[i]->scene.poisson_ratios.size(); ++k) cases.emplace_back(i, k);
  }
  std::map<std::string, std::vector<std::size_t>> by_key;  // cases sharing a fine matrix
  std::vector<std::vector<std::size_t>> tasks;
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const auto [i, k] = cases[c];
    fem::ElasticityProblem unloaded = fem_problem(refs[i]->scene, refs[i]->fine_mesh,
                                                  refs[i]->scene.poisson_ratios[k], 2);
    unloaded.pressures.clear();
    unloaded.patches.clear();
    unloaded.gravity = Vec3::Zero();
    unloaded.body_force = nullptr;
    for (fem::DirichletCondition& d : unloaded.dirichlet) d.value = nullptr;  // rhs only
    const std::optional<std::string> key = fem::solution_cache_key(refs[i]->fine_mesh, unloaded);
    if (key) {
      by_key[*key].push_back(c);
    } else {
      tasks.push_back({c});
    }
  }
  for (auto& [key, group] : by_key) tasks.push_back(std::move(group));
  // Largest first (by the fine meshes' tets, the solves' cost), so that no large solve starts
  // last beside an idle core; ties in the scenes' order.
  const auto cost = [&](const std::vector<std::size_t>& task) {
    std::size_t tets = 0;
    for (const std::size_t c : task) tets += refs[cases[c].first]->fine_mesh.tets.size();
    return tets;
  };
  std::sort(tasks.begin(), tasks.end(), [&](const auto& a, const auto& b) {
    const std::size_t ca = cost(a), cb = cost(b);
    return ca != cb ? ca > cb : a < b;
  });

  const int jobs = std::max(1, o.jobs);
  log << "FEM references: " << cases.size() << " (scene, ν) cases of " << refs.size()
      << " scene(s), " << jobs << " at a time; the timed models follow one at a time\n";
  PassLog pass(log, cases.size());
  parallel_solves(tasks.size(), jobs, [&](std::size_t t) {
    for (const std::size_t c : tasks[t]) {
      const auto [i, k] = cases[c];
      const Scene& s = refs[i]->scene;
      solve_reference_at(s, *refs[i], k, o);
      solve_modal_reference_at(s, *refs[i], k);
      std::ostringstream failure;
      log_modal_failure(failure, refs[i]->at_nu[k]);
      pass.done(s.name + ": " + reference_label(s, s.poisson_ratios[k]) +
                    (refs[i]->modal_reference_mesh ? ", its modes" : ""),
                refs[i]->at_nu[k].seconds, failure.str());
    }
  });
  run_all_transients(refs, cases, jobs, log);
}

void log_scene_header(std::ostream& log, const Scene& s, std::size_t i, std::size_t n) {
  log << "== scene " << i + 1 << "/" << n << ": " << s.name << " ==\n";
  log << "scene " << s.name << ": " << describe(s.vessel) << "\n";
}

}  // namespace

SceneResult run_scene(const Scene& s, const HarnessOptions& o) {
  std::ostream null_stream(nullptr);
  std::ostream& log = o.log ? *o.log : null_stream;
  Stopwatch total;
  log << "scene " << s.name << ": " << describe(s.vessel) << "\n";
  const std::unique_ptr<SceneReferences> refs = scene_meshes(s, o, log);
  const std::size_t reference_steps = s.poisson_ratios.size() * (s.modes.count > 0 ? 2 : 1);
  Progress progress(log, reference_steps + model_cases(s, o));
  SceneResult result = run_models(*refs, o, progress, true, log);
  result.seconds = total.seconds();
  return result;
}

std::vector<SceneResult> run_scenes(const std::vector<Scene>& scenes, const HarnessOptions& o) {
  std::ostream null_stream(nullptr);
  std::ostream& log = o.log ? *o.log : null_stream;
  std::vector<SceneResult> results;
  if (o.jobs <= 1) {
    for (std::size_t i = 0; i < scenes.size(); ++i) {
      log << "== scene " << i + 1 << "/" << scenes.size() << ": " << scenes[i].name << " ==\n";
      results.push_back(run_scene(scenes[i], o));
    }
    return results;
  }
  // The references first, in parallel (untimed), then each scene's models alone: their set-up
  // and update times are measurements and must not share the cores.
  std::vector<std::unique_ptr<SceneReferences>> refs;
  for (const Scene& s : scenes) refs.push_back(scene_meshes(s, o, log));
  solve_all_references(refs, o, log);
  fem::release_kept_factors();  // gigabytes at the reference levels; the models pass needs none
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    Stopwatch clock;
    log_scene_header(log, scenes[i], i, scenes.size());
    Progress progress(log, model_cases(scenes[i], o));
    results.push_back(run_models(*refs[i], o, progress, false, log));
    double solved = 0.0;
    for (const auto& a : refs[i]->at_nu) solved += a.seconds;
    results.back().seconds = clock.seconds() + solved;
    refs[i].reset();  // its solvers and meshes are no longer needed
  }
  return results;
}

}  // namespace vessel
