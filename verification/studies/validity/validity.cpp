#include "verification/studies/validity/validity.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "fem_reference/elasticity.hpp"
#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/content_hash.hpp"
#include "meshes/self_contact.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/solvers/updates.hpp"
#include "msm/terms/edge_pair_term.hpp"
#include "verification/harness/budget.hpp"
#include "verification/harness/external_model.hpp"
#include "verification/harness/metrics.hpp"
#include "verification/harness/model_readout.hpp"
#include "verification/harness/model_runs.hpp"
#include "verification/harness/options.hpp"
#include "verification/harness/timed_updates.hpp"
#include "verification/harness/timing.hpp"
#include "verification/harness/parallel.hpp"
#include "verification/scene_problems.hpp"

namespace vessel {

namespace {

using nlohmann::json;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

const char* load_unit(LoadKind k) {
  return k == LoadKind::contact ? "N" : (k == LoadKind::pressure ? "Pa" : "g");
}

/// What the continuation gave at one checkpoint, at the points the study reads.
struct Sample {
  double load = 0.0;
  int load_steps = 0, rejected_steps = 0, newton_iterations = 0;
  double seconds = 0.0;
  Vec3 qoi = Vec3::Zero();
  std::vector<Vec3> mesh_nodes;                ///< at the reference mesh's nodes
  std::vector<std::vector<Vec3>> model_nodes;  ///< per model, at its nodes' rest positions
};

struct Continuation {
  std::string element;
  std::size_t dofs = 0;
  bool completed = false;
  double largest_load = 0.0;
  std::string stop_reason;
  bool self_contact = false;
  int load_steps = 0, rejected_steps = 0, newton_iterations = 0;
  double seconds = 0.0;
  std::vector<Sample> samples;
};

json points_json(const std::vector<Vec3>& v) {
  json a = json::array();
  for (const Vec3& p : v) {
    a.push_back(p.x());
    a.push_back(p.y());
    a.push_back(p.z());
  }
  return a;
}

std::vector<Vec3> points_from(const json& a) {
  const auto flat = a.get<std::vector<double>>();
  if (flat.size() % 3 != 0) throw std::runtime_error("point array not a multiple of 3");
  std::vector<Vec3> v(flat.size() / 3);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = {flat[3 * i], flat[3 * i + 1], flat[3 * i + 2]};
  return v;
}

std::string serialise(const Continuation& c) {
  json j{{"element", c.element},
         {"dofs", c.dofs},
         {"completed", c.completed},
         {"largest_load", c.largest_load},
         {"stop_reason", c.stop_reason},
         {"self_contact", c.self_contact},
         {"load_steps", c.load_steps},
         {"rejected_steps", c.rejected_steps},
         {"newton_iterations", c.newton_iterations},
         {"seconds", c.seconds}};
  json samples = json::array();
  for (const Sample& s : c.samples) {
    json models = json::array();
    for (const auto& m : s.model_nodes) models.push_back(points_json(m));
    samples.push_back({{"load", s.load},
                       {"load_steps", s.load_steps},
                       {"rejected_steps", s.rejected_steps},
                       {"newton_iterations", s.newton_iterations},
                       {"seconds", s.seconds},
                       {"qoi", points_json({s.qoi})},
                       {"mesh_nodes", points_json(s.mesh_nodes)},
                       {"model_nodes", models}});
  }
  j["samples"] = samples;
  return j.dump();
}

/// Throws on a payload it cannot read (the cache then recomputes it).
Continuation deserialise(std::string_view text, std::size_t mesh_nodes,
                         const std::vector<std::size_t>& model_nodes) {
  const json j = json::parse(text);
  Continuation c;
  c.element = j.at("element").get<std::string>();
  c.dofs = j.at("dofs").get<std::size_t>();
  c.completed = j.at("completed").get<bool>();
  c.largest_load = j.at("largest_load").get<double>();
  c.stop_reason = j.at("stop_reason").get<std::string>();
  c.self_contact = j.at("self_contact").get<bool>();
  c.load_steps = j.at("load_steps").get<int>();
  c.rejected_steps = j.at("rejected_steps").get<int>();
  c.newton_iterations = j.at("newton_iterations").get<int>();
  c.seconds = j.at("seconds").get<double>();
  for (const json& s : j.at("samples")) {
    Sample x;
    x.load = s.at("load").get<double>();
    x.load_steps = s.at("load_steps").get<int>();
    x.rejected_steps = s.at("rejected_steps").get<int>();
    x.newton_iterations = s.at("newton_iterations").get<int>();
    x.seconds = s.at("seconds").get<double>();
    const auto q = points_from(s.at("qoi"));
    if (q.size() != 1) throw std::runtime_error("qoi: expected one point");
    x.qoi = q[0];
    x.mesh_nodes = points_from(s.at("mesh_nodes"));
    if (x.mesh_nodes.size() != mesh_nodes) throw std::runtime_error("mesh node count differs");
    const json& models = s.at("model_nodes");
    if (models.size() != model_nodes.size()) throw std::runtime_error("model count differs");
    for (std::size_t m = 0; m < models.size(); ++m) {
      x.model_nodes.push_back(points_from(models[m]));
      if (x.model_nodes.back().size() != model_nodes[m])
        throw std::runtime_error("model node count differs");
    }
    c.samples.push_back(std::move(x));
  }
  return c;
}

/// Whether the study judges a model of this kind on the mesh's own nodes: linear P1 FEM,
/// corotational P1, XPBD FEM.
bool on_mesh_kind(const ModelSpec& m) {
  return (m.kind == ModelKind::fem && m.degree == 1) || m.kind == ModelKind::corotational_fem ||
         m.kind == ModelKind::xpbd_fem;
}

/// The models the study runs: named ones, else (default) the seed models and the P1 tet models
/// (linear, corotational, XPBD), else (full) every whole-vessel static or linear mass-spring model
/// and the P1 tet models of the scene.
std::vector<const ModelSpec*> chosen_models(const Scene& s, const ValidityOptions& o) {
  auto eligible = [](const ModelSpec& m) {
    return ((m.kind == ModelKind::surface_msm || m.kind == ModelKind::volume_msm) &&
            m.roi_radius <= 0.0 && msm::supports_updates(m.solver)) ||
           on_mesh_kind(m);
  };
  std::vector<const ModelSpec*> out;
  if (!o.models.empty()) {
    for (const std::string& name : o.models) {
      const auto it = std::find_if(s.models.begin(), s.models.end(),
                                   [&](const ModelSpec& m) { return m.name == name; });
      if (it == s.models.end() || !eligible(*it)) {
        throw InputError("--models " + name + ": " + s.source.string() +
                         " has no whole-vessel static mass-spring model, P1 fem, corotational_fem "
                         "or xpbd_fem model of that name");
      }
      out.push_back(&*it);
    }
    return out;
  }
  for (const ModelSpec& m : s.models) {
    if (!eligible(m)) continue;
    // The default runs the seed models, linear P1 (what the errors are read against) and the P1
    // models simulators pick instead of springs.
    const bool seed = on_mesh_kind(m) ||
                      (!m.volume_term && !m.edge_pairs && m.bending == msm::Bending::none &&
                       m.calibration.empty() &&
                       (m.stiffness == msm::StiffnessRule::seed000 ||
                        m.stiffness == msm::StiffnessRule::seed001));
    if (o.full || seed) out.push_back(&m);
  }
  return out;
}

void log_line(const ValidityOptions& o, const std::string& text) {
  if (o.log) *o.log << (text + "\n") << std::flush;  // one write: scenes may run on threads
}

int reference_level_of(const Scene& s, const ValidityOptions& o) {
  return o.reference_level >= 0 ? o.reference_level : (o.full ? s.reference_level : 0);
}

}  // namespace

ThresholdCrossing threshold_crossing(const std::vector<double>& loads,
                                     const std::vector<double>& d, double threshold) {
  if (loads.empty() || loads.size() != d.size()) {
    throw std::invalid_argument("threshold_crossing: expected as many differences as loads, > 0");
  }
  for (std::size_t k = 0; k < loads.size(); ++k) {
    if (!(loads[k] > 0.0) || (k > 0 && !(loads[k] > loads[k - 1]))) {
      throw std::invalid_argument("threshold_crossing: loads must be > 0 and ascending");
    }
  }
  ThresholdCrossing c;
  c.threshold = threshold;
  if (d[0] >= threshold) {
    c.status = "below_ladder";
    c.load = loads[0];
    c.lower = c.upper = loads[0];
    return c;
  }
  for (std::size_t k = 1; k < loads.size(); ++k) {
    if (d[k] < threshold) continue;
    c.status = "interpolated";
    c.lower = loads[k - 1];
    c.upper = loads[k];
    if (d[k - 1] > 0.0) {
      // ln F linear in ln d between the bracketing loads.
      const double w = std::log(threshold / d[k - 1]) / std::log(d[k] / d[k - 1]);
      c.load = std::exp(std::log(loads[k - 1]) + w * std::log(loads[k] / loads[k - 1]));
    } else {  // no log at d = 0: linear in F
      c.load = loads[k - 1] + (threshold - d[k - 1]) / (d[k] - d[k - 1]) * (loads[k] - loads[k - 1]);
    }
    return c;
  }
  c.status = "not_reached";
  c.lower = c.upper = loads.back();
  return c;
}

std::vector<double> default_ladder(const Scene& scene, bool full, bool quick) {
  if (scene.load.kind == LoadKind::contact) {
    if (quick && !full) return {1e-4, 1e-3, 1e-2};
    // Seed 000's range, 0.01 to 140 mN, denser where the references part (0.1–10 mN).
    if (full) {
      return {1e-5, 1e-4, 2e-4, 3e-4, 5e-4, 7e-4, 1e-3, 1.5e-3, 2e-3, 3e-3, 5e-3, 7e-3,
              1e-2, 1.5e-2, 2e-2, 3e-2, 5e-2, 7e-2, 0.1, 0.14};
    }
    // Up to 70 mN, below where the tubes' continuations stop at P2 level 0 (89–93 mN: the wall
    // passing through itself under the straight tube's patch, Newton on the arch). Finding that
    // largest load is most of the study's cost (halving the increment down to min_step after
    // each failure), so it is left to --full, whose ladder goes on to 140 mN.
    return {1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 5e-2, 7e-2};
  }
  // Other loads: fractions of the scene's largest magnitude (gravity: up to 1 g).
  const double top = *std::max_element(scene.load.magnitudes.begin(), scene.load.magnitudes.end());
  if (full) return {0.01 * top, 0.1 * top, 0.25 * top, 0.5 * top, 0.75 * top, top};
  if (quick) return {top};
  return {0.5 * top, top};
}

namespace {

/// The scene's study settings: names, levels, ν and the sorted ladder. InputError for a dynamic
/// scene or an empty or non-positive ladder.
ValidityScene scene_settings(const Scene& s, const ValidityOptions& o) {
  const bool dynamic = std::any_of(s.models.begin(), s.models.end(),
                                   [](const ModelSpec& m) { return m.solver.is_dynamic(); });
  if (dynamic) {
    throw InputError(s.source.string() +
                     ": validity compares static answers; this scene's models are dynamic");
  }
  ValidityScene out;
  out.scene = s.name;
  out.source = s.source.string();
  out.load_kind = to_string(s.load.kind);
  out.load_unit = load_unit(s.load.kind);
  out.poisson_ratio = s.poisson_ratios.front();
  out.reference_level = reference_level_of(s, o);
  out.degree = o.degree;
  out.model_level = s.model_levels.front();
  out.ladder = o.ladder.empty() ? default_ladder(s, o.full, o.quick) : o.ladder;
  std::sort(out.ladder.begin(), out.ladder.end());
  out.ladder.erase(std::unique(out.ladder.begin(), out.ladder.end()), out.ladder.end());
  if (out.ladder.empty() || !(out.ladder.front() > 0.0)) {
    throw InputError("validity: the load ladder must hold loads > 0");
  }
  return out;
}

/// The models the study judges, built on their level's mesh: mass-spring networks, and the P1
/// tet models on the mesh's own nodes (those: an empty BuiltNetwork; linear P1 also no Form, its
/// answer the unit load's displacement scaled).
struct StudyModels {
  std::vector<const ModelSpec*> specs;
  TetMesh mesh;
  std::vector<msm::BuiltNetwork> built;
  std::vector<std::unique_ptr<msm::Form>> forms;
  std::vector<std::size_t> node_counts;
  std::vector<std::vector<Vec3>> unit_displacement;  ///< linear P1 at unit load, m per unit
  std::vector<std::optional<FemUpdates>> fem_timing;  ///< linear P1, when the study times updates

  [[nodiscard]] bool on_mesh(std::size_t m) const { return on_mesh_kind(*specs[m]); }
  [[nodiscard]] bool linear_fem(std::size_t m) const { return specs[m]->kind == ModelKind::fem; }
  [[nodiscard]] const std::vector<Vec3>& nodes(std::size_t m) const {
    return on_mesh(m) ? mesh.nodes : built[m].network.nodes;
  }
  [[nodiscard]] VtuCells cells(std::size_t m) const {
    return on_mesh(m) ? tet_cells(mesh.tets) : network_cells(built[m].network);
  }
  [[nodiscard]] msm::Problem problem(const Scene& s, std::size_t m, double load) const {
    if (on_mesh(m)) {
      return tet_mesh_problem(s, static_cast<const msm::TetTerm&>(*forms[m]), mesh, load);
    }
    return msm_problem(s, static_cast<const msm::MassSpringModel&>(*forms[m]), built[m], mesh,
                       load);
  }
};

StudyModels build_models(const Scene& s, const ValidityOptions& o, ValidityScene& out) {
  StudyModels m;
  m.specs = chosen_models(s, o);
  m.mesh = scene_mesh(s, out.model_level, o.mesh_cache_dir);
  VesselParams vessel = s.vessel;
  vessel.level = out.model_level;
  for (const ModelSpec* spec : m.specs) {
    std::string detail;
    m.unit_displacement.emplace_back();
    m.fem_timing.emplace_back();
    if (spec->kind == ModelKind::fem) {
      // Linear P1 in the displacement formulation, as the harness runs it (fem_model_run.cpp).
      m.built.emplace_back();
      m.forms.emplace_back();
      fem::ElasticityProblem problem = fem_problem(s, m.mesh, out.poisson_ratio, 1);
      problem.options.formulation = fem::Formulation::displacement;
      const Stopwatch construction;
      fem::ElasticitySolver solver(m.mesh, problem);
      const double construction_seconds = construction.seconds();
      const fem::ElasticityResult& r = fem::solve_with(o.cache, solver, m.mesh, problem);
      m.unit_displacement.back() = r.nodal_displacement;
      if (o.time_updates) {
        FemUpdates t = timed_fem_updates(solver, kRampUpdates, 1);
        t.setup_seconds += construction_seconds;
        m.fem_timing.back() = t;
      }
      m.node_counts.push_back(m.mesh.nodes.size());
      detail = "linear P1 FEM (displacement formulation), the unit load's answer scaled";
    } else if (on_mesh_kind(*spec)) {
      m.built.emplace_back();
      m.forms.push_back(tet_fem_term(*spec, m.mesh, s.youngs_modulus, out.poisson_ratio));
      m.node_counts.push_back(m.mesh.nodes.size());
      detail = tet_fem_detail(*spec);
    } else {
      m.built.push_back(scene_network(s, *spec, m.mesh, vessel, out.poisson_ratio));
      m.forms.push_back(msm::make_model(m.built.back(), spec->damping));
      m.node_counts.push_back(m.built.back().network.nodes.size());
      detail = m.built.back().topology + ", " + msm::to_string(spec->stiffness) + " stiffness, " +
               msm::to_string(spec->solver);
    }
    out.models.push_back({spec->name, detail, out.model_level, m.node_counts.back()});
  }
  return m;
}

/// The finite-strain continuation through the ladder (unit load × load factor = magnitude, as
/// the harness's finite-strain reference), sampled at each checkpoint at the QoI, the mesh's
/// nodes and the models' nodes; from the cache when it holds it (`from_cache` says which).
Continuation finite_continuation(const Scene& s, const ValidityOptions& o, const TetMesh& ref_mesh,
                                 const fem::ElasticityProblem& problem,
                                 const std::vector<double>& ladder, const StudyModels& models,
                                 bool& from_cache) {
  const Vec3 qoi = qoi_point(s);
  fem::HyperelasticOptions fo = o.finite;
  fo.target_load_factor = ladder.back();
  fo.initial_step = fo.max_step = ladder.back();  // each step tries the next checkpoint
  // Where no equilibrium follows, the increment is halved down to min_step: the largest load
  // reached is found to within it. Most of the study's cost is that search (on 2 cores the
  // default ladder's hunt to 1e-4 of the top took ~10 min of the main job), so the default
  // stops at 2 % of the top (2.8 mN of 140 mN); --full keeps 1e-4.
  fo.min_step = (o.full ? 1e-4 : 2e-2) * ladder.back();
  fo.checkpoints = ladder;
  ContentHash what;
  what.text("validity samples v3").real(qoi.x()).real(qoi.y()).real(qoi.z());
  what.real(kOutsideTolerance);
  for (std::size_t m = 0; m < models.specs.size(); ++m) {
    what.integer(static_cast<std::int64_t>(models.nodes(m).size()));
    for (const Vec3& p : models.nodes(m)) what.real(p.x()).real(p.y()).real(p.z());
  }
  auto compute = [&] {
    from_cache = false;
    Continuation c;
    fem::HyperelasticSolver fs(ref_mesh, problem, fo);
    const auto take = [&](const fem::HyperelasticSolver& at, const fem::Checkpoint& cp) {
      Sample x;
      x.load = cp.load_factor;
      x.load_steps = cp.load_steps;
      x.rejected_steps = cp.rejected_steps;
      x.newton_iterations = cp.newton_iterations;
      x.seconds = cp.seconds;
      x.qoi = at.displacement_at({qoi}, kOutsideTolerance)[0];
      x.mesh_nodes = cp.nodal_displacement;
      for (std::size_t m = 0; m < models.specs.size(); ++m) {
        x.model_nodes.push_back(at.displacement_at(models.nodes(m), kOutsideTolerance));
      }
      std::ostringstream m;
      m << "  " << s.name << ": finite strain at " << cp.load_factor << " " << load_unit(s.load.kind) << ": "
        << cp.load_steps << " steps, " << cp.newton_iterations << " Newton iterations, "
        << std::setprecision(3) << cp.seconds << " s";
      log_line(o, m.str());
      c.samples.push_back(std::move(x));
      return std::string();
    };
    const fem::HyperelasticResult& r = fs.solve(take);
    c.element = r.element;
    c.dofs = r.n_dofs;
    c.completed = r.completed;
    c.largest_load = r.load_factor;
    c.stop_reason = r.stop_reason;
    c.self_contact = r.self_contact;
    c.load_steps = static_cast<int>(r.steps.size());
    c.rejected_steps = r.rejected_steps;
    c.newton_iterations = r.newton_iterations;
    c.seconds = r.timings.assembly + r.timings.solve;
    return serialise(c);
  };
  from_cache = true;
  const std::optional<std::string> key =
      o.cache ? fem::continuation_cache_key(ref_mesh, problem, fo, what.hex()) : std::nullopt;
  const std::string payload =
      key ? o.cache->payload(*key, compute,
                             [&](std::string_view text) {
                               return deserialise(text, ref_mesh.nodes.size(), models.node_counts)
                                   .seconds;
                             })
          : compute();
  return deserialise(payload, ref_mesh.nodes.size(), models.node_counts);
}

/// The updater of model m on problem p: XPBD FEM stepped to its steady state, static Newton for
/// corotational P1, the model's own solver for a spring network.
std::unique_ptr<msm::Updater> model_updater(const StudyModels& models, std::size_t m,
                                            const msm::Problem& p) {
  const ModelSpec& spec = *models.specs[m];
  if (spec.kind == ModelKind::xpbd_fem) {
    return std::make_unique<XpbdFemUpdater>(p, static_cast<const msm::TetTerm&>(*models.forms[m]),
                                            spec.tet_fem);
  }
  if (spec.kind == ModelKind::corotational_fem) {
    return msm::prepare_updates(p, msm::parse_solver("static"));
  }
  return msm::prepare_updates(p, spec.solver);
}

/// Model m timed at `load` as `vesselverify run` times it (set-up apart): linear P1 and the static
/// models over a ramp of kRampUpdates warm-started updates to the load (timed_updates), XPBD FEM
/// from rest to its steady state; with the time per update at 30 Hz and 1 kHz (time_per_update:
/// XPBD FEM pays its per-step cost × the steps one period holds).
ValidityTiming timed_update(const Scene& s, const StudyModels& models, std::size_t m, double load) {
  ValidityTiming t;
  const ModelSpec& spec = *models.specs[m];
  if (models.linear_fem(m)) {
    t.setup_seconds = models.fem_timing[m]->setup_seconds;
    t.update_seconds = models.fem_timing[m]->update_seconds;
  } else if (spec.kind == ModelKind::xpbd_fem) {
    const msm::Problem p = models.problem(s, m, load);
    XpbdFemUpdater up(p, static_cast<const msm::TetTerm&>(*models.forms[m]), spec.tet_fem);
    const msm::UpdateResult r = up.update(p.external_force);
    t.setup_seconds = up.setup_seconds();
    t.update_seconds = r.seconds;
    t.steps = r.iterations;
    t.dt = spec.tet_fem.dt;
  } else {
    const msm::Problem p = models.problem(s, m, load);
    const msm::SolverSpec solver = spec.kind == ModelKind::corotational_fem
                                       ? msm::parse_solver("static")
                                       : spec.solver;
    const UpdateSequence seq = timed_updates(p, solver, kRampUpdates, 1);
    t.setup_seconds = seq.setup_seconds;
    t.update_seconds = seq.update_seconds;
  }
  t.update_seconds_30hz = time_per_update(t.update_seconds, t.steps, t.dt, 1.0 / 30.0).first;
  t.update_seconds_1khz = time_per_update(t.update_seconds, t.steps, t.dt, 1e-3).first;
  return t;
}

/// Model m's errors against the finite-strain reference at sample x, updated from its previous
/// state along the ladder (a continuation too; a failure is recorded and restarts it from rest);
/// linear P1's answer is its unit-load answer scaled. With `fields` non-empty, its fields written
/// there; with `timed`, its update timed afresh (timed_update).
ValidityModelError model_error(const Scene& s, const StudyModels& models, std::size_t m,
                               const Sample& x, std::unique_ptr<msm::Updater>& updater,
                               const std::filesystem::path& fields, bool timed) {
  ValidityModelError e;
  e.model = models.specs[m]->name;
  try {
    const auto& nodes = models.nodes(m);
    std::vector<Vec3> um(nodes.size());
    if (models.linear_fem(m)) {
      um = scaled(models.unit_displacement[m], x.load);
      e.iterations = 1;
    } else {
      const msm::Problem p = models.problem(s, m, x.load);
      if (!updater) updater = model_updater(models, m, p);
      const msm::UpdateResult u = updater->update(p.external_force);
      e.iterations = u.iterations;
      const Eigen::VectorXd& state = updater->state();
      for (std::size_t i = 0; i < nodes.size(); ++i) {
        um[i] = state.segment<3>(3 * static_cast<Eigen::Index>(i)) - nodes[i];
      }
    }
    const ErrorStatistics st = compare_displacements(um, x.model_nodes[m]);
    e.relative_l2 = st.relative_l2;
    e.max_error_mm = st.max_mm;
    const std::size_t q = nearest_node(nodes, qoi_point(s));
    const Vec3 uref = x.model_nodes[m][q];
    e.qoi_error_mm = (um[q] - uref).norm() * 1e3;
    e.qoi_model_mm = um[q].norm() * 1e3;
    e.qoi_relative = uref.norm() > 0.0 ? (um[q] - uref).norm() / uref.norm() : 0.0;
    if (timed) e.timing = timed_update(s, models, m, x.load);
    e.ok = true;
    if (!fields.empty()) {
      write_fields_vtu(fields, nodes, models.cells(m), um, x.model_nodes[m]);
      e.fields_file = fields;
    }
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& ex) {
    e.failure = ex.what();
    updater.reset();
  }
  return e;
}

}  // namespace

ValidityScene run_validity_scene(const Scene& s, const ValidityOptions& o) {
  const auto t_scene = std::chrono::steady_clock::now();
  ValidityScene out = scene_settings(s, o);
  out.qoi_point = qoi_point(s);

  // The references: one mesh, one problem at unit load.
  const TetMesh ref_mesh = scene_mesh(s, out.reference_level, o.mesh_cache_dir);
  const fem::ElasticityProblem problem = fem_problem(s, ref_mesh, out.poisson_ratio, o.degree);
  fem::ElasticitySolver linear(ref_mesh, problem);
  const fem::ElasticityResult& lin = fem::solve_with(o.cache, linear, ref_mesh, problem);
  out.element = lin.element;
  out.dofs = lin.n_dofs;
  const Vec3 lin_qoi = linear.displacement_at({qoi_point(s)}, kOutsideTolerance)[0];
  log_line(o, "validity " + s.name + ": reference " + lin.element + " on level " +
                  std::to_string(out.reference_level) + ", " + std::to_string(lin.n_dofs) +
                  " DoFs");

  const StudyModels models = build_models(s, o, out);
  const Continuation c =
      finite_continuation(s, o, ref_mesh, problem, out.ladder, models, out.finite_from_cache);
  out.completed = c.completed;
  out.largest_load = c.largest_load;
  out.stop_reason = c.stop_reason;
  out.self_contact = c.self_contact;
  out.load_steps = c.load_steps;
  out.rejected_steps = c.rejected_steps;
  out.newton_iterations = c.newton_iterations;
  out.finite_seconds = c.seconds;
  if (!c.completed) {
    log_line(o, "  " + s.name + ": finite strain stopped at " + std::to_string(c.largest_load) + " " +
                    out.load_unit + ": " + c.stop_reason);
  }

  // The rows: references and models at each checkpoint reached.
  std::vector<std::unique_ptr<msm::Updater>> updaters(models.specs.size());
  const bool parametric =
      s.vessel.kind == VesselKind::straight || s.vessel.kind == VesselKind::arch;
  for (const Sample& x : c.samples) {
    ValidityRow row;
    row.magnitude = x.load;
    const Vec3 ul = x.load * lin_qoi;
    row.linear_qoi_mm = ul.norm() * 1e3;
    row.finite_qoi_mm = x.qoi.norm() * 1e3;
    row.qoi_difference = x.qoi.norm() > 0.0 ? (ul - x.qoi).norm() / x.qoi.norm() : 0.0;
    row.l2_difference =
        compare_displacements(scaled(lin.nodal_displacement, x.load), x.mesh_nodes).relative_l2;
    row.linear_strain = lin.max_abs_principal_strain * x.load;
    if (parametric) {
      row.wall_gap_mm =
          closest_approach(ref_mesh, x.mesh_nodes, "inner_wall", s.vessel.inner_radius) * 1e3;
    }
    row.newton_iterations = x.newton_iterations;
    row.load_steps = x.load_steps;
    row.finite_seconds = x.seconds;
    const bool largest = &x == &c.samples.back();
    for (std::size_t m = 0; m < models.specs.size(); ++m) {
      std::filesystem::path fields;
      if (largest && !o.fields_dir.empty()) {
        std::ostringstream name;
        name << file_stem(models.specs[m]->name) << "_load" << x.load << ".vtu";
        fields = o.fields_dir / file_stem(s.name) / name.str();
      }
      row.models.push_back(model_error(s, models, m, x, updaters[m], fields, o.time_updates));
    }
    out.rows.push_back(std::move(row));
  }

  std::vector<double> loads, dq, dl;
  for (const ValidityRow& r : out.rows) {
    loads.push_back(r.magnitude);
    dq.push_back(r.qoi_difference);
    dl.push_back(r.l2_difference);
  }
  if (!loads.empty()) {
    for (const double t : kValidityThresholds) {
      out.qoi_limits.push_back(threshold_crossing(loads, dq, t));
      out.l2_limits.push_back(threshold_crossing(loads, dl, t));
    }
  }
  out.seconds = seconds_since(t_scene);
  return out;
}

std::vector<ValidityScene> run_validity(const std::vector<Scene>& scenes,
                                        const ValidityOptions& o, int jobs) {
  if (o.mesh_cache_dir.empty() || o.time_updates) jobs = 1;  // timings: one scene at a time
  if (jobs > 1) {
    for (const Scene& s : scenes) {
      (void)scene_mesh(s, reference_level_of(s, o), o.mesh_cache_dir);
      (void)scene_mesh(s, s.model_levels.front(), o.mesh_cache_dir);
    }
  }
  std::vector<ValidityScene> out(scenes.size());
  parallel_for(scenes.size(), jobs, [&](std::size_t i) { out[i] = run_validity_scene(scenes[i], o); });
  return out;
}

ValidityStudy run_validity_study(const std::vector<Scene>& scenes, const ValidityOptions& options,
                                 int jobs, const std::string& command) {
  const auto t0 = std::chrono::steady_clock::now();
  ValidityStudy study;
  study.command = command;
  study.full = options.full;
  study.scenes = run_validity(scenes, options, jobs);
  study.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return study;
}

namespace {

json crossing_json(const ThresholdCrossing& c) {
  return {{"threshold", c.threshold},
          {"status", c.status},
          {"load", c.load ? json(*c.load) : json(nullptr)},
          {"lower", c.lower},
          {"upper", c.upper}};
}

}  // namespace

/// A model's errors at one load; its fields path relative to `json_dir`, validity.json's folder.
json model_error_json(const ValidityModelError& e, const std::filesystem::path& json_dir) {
  json m{{"model", e.model}, {"ok", e.ok}};
  if (!e.ok) {
    m["failure"] = e.failure;
    return m;
  }
  m.update({{"relative_l2", e.relative_l2},
            {"max_error_mm", e.max_error_mm},
            {"qoi_error_mm", e.qoi_error_mm},
            {"qoi_relative", e.qoi_relative},
            {"qoi_model_mm", e.qoi_model_mm},
            {"iterations", e.iterations}});
  if (e.timing) {
    const ValidityTiming& t = *e.timing;
    m["timing"] = {{"setup_seconds", t.setup_seconds},
                   {"update_seconds", t.update_seconds},
                   {"steps", t.steps},
                   {"dt", t.dt},
                   {"update_seconds_30hz", t.update_seconds_30hz},
                   {"update_seconds_1khz", t.update_seconds_1khz}};
  }
  if (!e.fields_file.empty()) {
    m["fields"] = std::filesystem::absolute(e.fields_file)
                      .lexically_relative(std::filesystem::absolute(json_dir))
                      .generic_string();
  }
  return m;
}

void write_validity_json(const ValidityStudy& study, const std::filesystem::path& path) {
  json scenes = json::array();
  for (const ValidityScene& v : study.scenes) {
    json rows = json::array();
    for (const ValidityRow& r : v.rows) {
      json models = json::array();
      for (const ValidityModelError& e : r.models) {
        models.push_back(model_error_json(e, path.parent_path()));
      }
      rows.push_back({{"magnitude", r.magnitude},
                      {"linear_qoi_mm", r.linear_qoi_mm},
                      {"finite_qoi_mm", r.finite_qoi_mm},
                      {"qoi_difference", r.qoi_difference},
                      {"l2_difference", r.l2_difference},
                      {"linear_strain", r.linear_strain},
                      {"wall_gap_mm", r.wall_gap_mm ? json(*r.wall_gap_mm) : json(nullptr)},
                      {"newton_iterations", r.newton_iterations},
                      {"load_steps", r.load_steps},
                      {"finite_seconds", r.finite_seconds},
                      {"models", models}});
    }
    json models = json::array();
    for (const ValidityModel& m : v.models) {
      models.push_back({{"name", m.name}, {"detail", m.detail}, {"level", m.level},
                        {"nodes", m.nodes}});
    }
    json qoi_limits = json::array(), l2_limits = json::array();
    for (const auto& c : v.qoi_limits) qoi_limits.push_back(crossing_json(c));
    for (const auto& c : v.l2_limits) l2_limits.push_back(crossing_json(c));
    scenes.push_back({{"scene", v.scene},
                      {"source", v.source},
                      {"load_kind", v.load_kind},
                      {"load_unit", v.load_unit},
                      {"poisson_ratio", v.poisson_ratio},
                      {"reference_level", v.reference_level},
                      {"degree", v.degree},
                      {"element", v.element},
                      {"dofs", v.dofs},
                      {"qoi_point_mm",
                       {v.qoi_point.x() * 1e3, v.qoi_point.y() * 1e3, v.qoi_point.z() * 1e3}},
                      {"model_level", v.model_level},
                      {"ladder", v.ladder},
                      {"models", models},
                      {"continuation",
                       {{"completed", v.completed},
                        {"largest_load", v.largest_load},
                        {"stop_reason", v.stop_reason},
                        {"self_contact", v.self_contact},
                        {"load_steps", v.load_steps},
                        {"rejected_steps", v.rejected_steps},
                        {"newton_iterations", v.newton_iterations},
                        {"solve_seconds", v.finite_seconds},
                        {"from_cache", v.finite_from_cache}}},
                      {"qoi_limits", qoi_limits},
                      {"l2_limits", l2_limits},
                      {"rows", rows},
                      {"seconds", v.seconds}});
  }
  const json j{{"schema", "vesselverify.validity"},
               {"schema_version", 1},
               {"command", study.command},
               {"full", study.full},
               {"total_seconds", study.total_seconds},
               {"scenes", scenes}};
  write_file_atomically(path, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

void print_validity_summary(const ValidityStudy& study, std::ostream& out) {
  for (const ValidityScene& v : study.scenes) {
    out << v.scene << " (" << v.element << " level " << v.reference_level << ", " << v.dofs
        << " DoFs, nu " << v.poisson_ratio << "):\n";
    out << "  continuation: " << v.load_steps << " load steps (" << v.rejected_steps
        << " rejected), " << v.newton_iterations << " Newton iterations, " << v.finite_seconds
        << " s" << (v.finite_from_cache ? " (read from the cache; original time)" : "") << "\n";
    if (v.completed) {
      out << "  reached the whole ladder, " << v.largest_load << " " << v.load_unit << "\n";
    } else {
      out << "  stopped at " << v.largest_load << " " << v.load_unit
          << (v.self_contact ? " (the wall would pass through itself beyond it)" : "") << ": "
          << v.stop_reason << "\n";
    }
    for (std::size_t k = 0; k < v.qoi_limits.size(); ++k) {
      const auto& c = v.qoi_limits[k];
      out << "  references part by " << c.threshold * 100 << " % at the QoI: ";
      if (c.status == "not_reached") {
        out << "not up to " << c.lower;
      } else if (c.status == "below_ladder") {
        out << "already at " << c.upper;
      } else {
        out << *c.load << " (between " << c.lower << " and " << c.upper << ")";
      }
      out << " " << v.load_unit << "\n";
    }
    for (const ValidityRow& r : v.rows) {
      out << "  " << std::setw(8) << r.magnitude << " " << v.load_unit << ": u_fs "
          << r.finite_qoi_mm << " mm, u_lin " << r.linear_qoi_mm << " mm, QoI diff "
          << r.qoi_difference << ", L2 diff " << r.l2_difference;
      for (const auto& e : r.models) {
        out << "; " << e.model << " ";
        if (e.ok) {
          out << "rel L2 " << e.relative_l2;
        } else {
          out << "failed";
        }
      }
      out << "\n";
    }
  }
}

}  // namespace vessel
