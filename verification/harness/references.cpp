#include "verification/harness/references.hpp"

#include <algorithm>
#include <iomanip>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "fem_reference/solution_cache.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "reports/representative_load.hpp"
#include "verification/harness/budget.hpp"
#include "verification/harness/modal.hpp"
#include "verification/harness/model_readout.hpp"
#include "verification/harness/parallel.hpp"
#include "verification/harness/timing.hpp"
#include "verification/model_capabilities.hpp"
#include "verification/scene_problems.hpp"

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

int transient_reference_level(const Scene& s) {
  return s.transient.reference_level >= 0 ? s.transient.reference_level : s.reference_level;
}

bool has_dynamic_models(const Scene& s) {
  return std::any_of(s.models.begin(), s.models.end(), [](const ModelSpec& m) {
    return m.kind != ModelKind::fem && m.solver.is_dynamic();
  });
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

/// The GCI order of the scene's reference (fem::gci_order): observed from the QoI point's
/// displacement along the fine level's direction there on three levels when the coarsest exists
/// (solved here), else the assumed order of the scene's load.
fem::GciOrder reference_gci_order(const Scene& s, const std::vector<ReferenceSolve>& solves,
                                  const ReferenceSolvers& ref) {
  const double assumed = s.load.kind == LoadKind::contact ? kAssumedReferenceOrderContact
                                                          : kAssumedReferenceOrderDistributed;
  if (solves.size() < 3) return fem::gci_order(std::nullopt, assumed);
  std::unique_ptr<fem::ElasticitySolver> coarsest;
  solve_reference(coarsest, *solves[2].mesh, solves[2].problem, ref.cache);
  const Vec3 q = qoi_point(s);
  const Vec3 fine = ref.fine->displacement_at({q}, kOutsideTolerance)[0];
  const Vec3 dir = fine.norm() > 0.0 ? Vec3(fine.normalized()) : Vec3(1.0, 0.0, 0.0);
  const double medium = ref.coarse->displacement_at({q}, kOutsideTolerance)[0].dot(dir);
  const double coarse = coarsest->displacement_at({q}, kOutsideTolerance)[0].dot(dir);
  return fem::gci_order(std::vector<double>{coarse, medium, fine.dot(dir)}, assumed);
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
          spec.solver.dt <= 0.0 || !model_refusal(spec, s.youngs_modulus, nu).empty()) {
        continue;
      }
      VesselParams vessel = s.vessel;
      vessel.level = level;
      std::optional<msm::BuiltNetwork> built_or;
      try {
        built_or.emplace(scene_network(s, spec, mesh, vessel, nu));
      } catch (const std::exception&) {
        continue;  // a model that cannot be built fails alone: the models' pass records it
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

}  // namespace

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

JudgingReference judging_reference(const ReferenceSolvers& ref, const Scene& s,
                                   const ReferenceAtPoints& linear_here,
                                   const std::vector<Vec3>& points, double linear_strain_unit,
                                   double magnitude) {
  if (!finite_strain_judges(s, linear_strain_unit, magnitude)) {
    return {linear_here, linear_strain_unit, false};
  }
  JudgingReference j;
  j.at_points.u = scaled(finite_reference(ref, magnitude).displacement_at(points, kOutsideTolerance),
                         1.0 / magnitude);
  j.finite_strain = true;
  return j;
}

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

double transient_mass_damping(const ModelSpec& spec, const msm::Problem& problem) {
  const double mean_mass = problem.mass.sum() / static_cast<double>(problem.mass.size());
  return spec.damping > 0.0 ? spec.damping / mean_mass : 0.0;
}

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

namespace {

/// Lists a lumen's ends in the log and finds each mesh's slivers, warning of them: a model's
/// error on such a mesh includes the mesh's.
void describe_meshes(SceneReferences& r, std::ostream& log) {
  const Scene& s = r.scene;
  if (s.vessel.kind == VesselKind::lumen) {
    r.lumen_ends = lumen_file_ends(s.vessel.file, s.vessel.file_scale, s.vessel.listed_ends);
    log << "  ends of the lumen: " << r.lumen_ends.size() << "\n";
    for (const auto& [group, end] : r.lumen_ends) {
      log << "    " << group << ": " << format_end(end) << "\n";
    }
  }
  std::map<int, const TetMesh*> meshes{{s.reference_level, &r.fine_mesh}};
  for (const auto& [level, mesh] : r.model_meshes) meshes[level] = &mesh;
  if (r.coarse_mesh) meshes[s.reference_level - 1] = r.coarse_mesh.get();
  if (r.coarsest_mesh) meshes[s.reference_level - 2] = r.coarsest_mesh.get();
  for (const auto& [level, mesh] : r.other_meshes) meshes[level] = mesh.get();
  for (const auto& [level, mesh] : meshes) {
    const SliverReport& slivers = r.mesh_slivers[level] = find_slivers(*mesh);
    if (slivers.count > 0)
      log << "  mesh level " << level << ": " << sliver_warning(slivers) << "\n";
  }
}

}  // namespace

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
  describe_meshes(*r, log);
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

std::vector<ReferenceSolve> reference_solves(const SceneReferences& r, std::size_t k) {
  const Scene& s = r.scene;
  const double nu = s.poisson_ratios[k];
  std::vector<ReferenceSolve> out;
  out.push_back({&r.fine_mesh, s.reference_level, fem_problem(s, r.fine_mesh, nu, 2)});
  const TetMesh* below[] = {r.coarse_mesh.get(), r.coarsest_mesh.get()};
  for (int i = 0; i < 2 && below[i]; ++i) {
    out.push_back({below[i], s.reference_level - 1 - i, fem_problem(s, *below[i], nu, 2)});
  }
  return out;
}

void solve_reference_at(const Scene& s, SceneReferences& r, std::size_t k,
                        const HarnessOptions& o) {
  Stopwatch clock;
  const double nu = s.poisson_ratios[k];
  SceneReferences::AtNu& a = r.at_nu[k];
  ReferenceSolvers& ref = a.ref;
  std::vector<ReferenceSolve> solves = reference_solves(r, k);
  ref.cache = o.solution_cache;
  ref.fine_mesh = &r.fine_mesh;
  ref.fine_problem = solves[0].problem;
  const fem::ElasticityResult& fine =
      solve_reference(ref.fine, r.fine_mesh, ref.fine_problem, ref.cache);
  ref.transient_level = r.transient_level;
  if (r.transient_mesh != &r.fine_mesh && has_dynamic_models(s)) {
    ref.transient_mesh = r.transient_mesh;
    ref.transient_problem = fem_problem(s, *r.transient_mesh, nu, 2);
    ref.transient_solver =
        std::make_unique<fem::ElasticitySolver>(*r.transient_mesh, ref.transient_problem);
  }
  if (solves.size() > 1) {
    solve_reference(ref.coarse, *solves[1].mesh, solves[1].problem, ref.cache);
    ref.gci = reference_gci_order(s, solves, ref);
    a.info.gci_order = ref.gci.order;
    a.info.gci_order_source = ref.gci.source;
    a.info.gci_safety_factor = ref.gci.safety_factor;
    a.info.gci_note = ref.gci.note;
  }
  a.info.poisson_ratio = nu;
  a.info.element = fine.element;
  a.info.level = s.reference_level;
  a.info.dofs = fine.n_dofs;  // Taylor–Hood: displacement and pressure, each counted once
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

void log_modal_failure(std::ostream& log, const SceneReferences::AtNu& a) {
  if (a.modes && !a.modes->ok) log << "      modal reference FAILED: " << a.modes->failure << "\n";
}

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

}  // namespace vessel
