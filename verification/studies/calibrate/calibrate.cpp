#include "verification/studies/calibrate/calibrate.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <numbers>
#include <sstream>

#include "fem_reference/elasticity.hpp"
#include "fem_reference/solution_cache.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/calibration/lbfgs.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/solvers/updates.hpp"
#include "reports/representative_load.hpp"
#include "verification/harness/options.hpp"
#include "verification/harness/outcome.hpp"
#include "verification/harness/metrics.hpp"
#include "verification/harness/timed_updates.hpp"
#include "verification/scene_problems.hpp"
#include "verification/harness/timing.hpp"

namespace vessel {

std::string to_string(CalibrationGranularity g) {
  switch (g) {
    case CalibrationGranularity::groups: return "groups";
    case CalibrationGranularity::wall_layers: return "wall_layers";
    case CalibrationGranularity::edge_types: return "edge_types";
    case CalibrationGranularity::per_section_spring: return "per_section_spring";
    case CalibrationGranularity::per_spring: return "per_spring";
  }
  return "groups";
}

CalibrationGranularity parse_calibration_granularity(const std::string& name) {
  if (name == "groups") return CalibrationGranularity::groups;
  if (name == "wall_layers" || name == "wall-layers") return CalibrationGranularity::wall_layers;
  if (name == "edge_types" || name == "edge-types") return CalibrationGranularity::edge_types;
  if (name == "per_section_spring" || name == "per-section-spring") {
    return CalibrationGranularity::per_section_spring;
  }
  if (name == "per_spring" || name == "per-spring") return CalibrationGranularity::per_spring;
  throw InputError("granularity: found \"" + name +
                   "\", expected groups, wall-layers, edge-types, per-section-spring or "
                   "per-spring");
}

std::string to_string(CaseWeights w) { return w == CaseWeights::equal ? "equal" : "p1"; }

CaseWeights parse_case_weights(const std::string& name) {
  if (name == "equal") return CaseWeights::equal;
  if (name == "p1") return CaseWeights::p1;
  throw InputError("weights: found \"" + name + "\", expected equal or p1");
}

namespace {

/// Barycentric tolerance of the reference at model nodes (the harness's: nodes on the exact
/// curved wall lie slightly outside the straight-sided reference tets).
constexpr double kOutsideTolerance = 0.25;
/// Held-out contacts on scenes without a contact load: the scenes' patch radius and a load in the
/// linear regime (the contact scenes' budget load).
constexpr double kContactRadius = 1.0e-3;
constexpr double kContactForce = 5.0e-4;
constexpr double kPressure = 10.0;  ///< Pa: pressure_lame's load

struct LoadCase {
  std::string name;
  bool training = false;
  std::string holds_out;
  LoadKind kind = LoadKind::contact;
  double magnitude = 0.0;
  Vec3 point = Vec3::Zero();
};

/// The wall point at arc length s, angle θ around the centreline and distance ρ from it
/// (the inverse of centreline_coordinates).
Vec3 wall_point(const VesselParams& v, double s, double theta, double rho) {
  if (v.kind == VesselKind::straight) {
    return {rho * std::cos(theta), rho * std::sin(theta), s};
  }
  const double phi = s / v.bend_radius;
  const Vec3 outward(std::cos(phi), std::sin(phi), 0.0);
  return v.bend_radius * outward + rho * (std::cos(theta) * outward + std::sin(theta) * Vec3::UnitZ());
}

Vec3 contact_point_of(const Scene& s) {
  if (s.load.kind == LoadKind::contact) return s.load.contact.point;
  return default_contact_point(s.vessel, std::string(group_names::inner_wall));
}

/// The scene reduced to one load case (its supports, material and vessel; no constant loads).
Scene case_scene(const Scene& s, const LoadCase& c) {
  Scene out = s;
  out.constant_loads.clear();
  LoadSpec l;
  l.kind = c.kind;
  l.magnitudes = {c.magnitude};
  if (c.kind == LoadKind::contact) {
    if (s.load.kind == LoadKind::contact) {
      l.contact = s.load.contact;
    } else {
      l.contact.radius = kContactRadius;
      l.contact.surface_group = std::string(group_names::inner_wall);
    }
    l.contact.point = c.point;
  } else if (c.kind == LoadKind::pressure) {
    l.contact.surface_group = s.load.kind == LoadKind::pressure
                                  ? s.load.contact.surface_group
                                  : std::string(group_names::inner_wall);
  } else if (s.load.kind == LoadKind::gravity) {
    l.gravity_direction = s.load.gravity_direction;
  }
  out.load = l;
  return out;
}

/// The scene's load at which it is trained: its budget load, else the middle of its magnitudes.
double training_magnitude(const Scene& s) {
  if (s.budget.magnitude > 0.0) return s.budget.magnitude;
  std::vector<double> m = s.load.magnitudes;
  std::sort(m.begin(), m.end());
  return m[m.size() / 2];
}

double default_magnitude(const Scene& s, LoadKind kind, double gravity) {
  if (s.load.kind == kind) return training_magnitude(s);
  switch (kind) {
    case LoadKind::contact: return kContactForce;
    case LoadKind::pressure: return kPressure;
    case LoadKind::gravity: return gravity;
  }
  return 1.0;
}

/// The load cases of a scene: training ones for the kinds in `train`, the rest held out.
std::vector<LoadCase> load_cases(const Scene& s, const std::vector<LoadKind>& train,
                                 bool other_vessel, double gravity) {
  std::vector<LoadCase> out;
  const auto trained = [&](LoadKind k) {
    return !other_vessel && std::find(train.begin(), train.end(), k) != train.end();
  };
  const std::string other_type = other_vessel ? "other vessel" : "other load type";
  // Contact: the scene's point, the point 90° round (training), 180° round, and 45° back a
  // quarter of the vessel along (held out).
  {
    const bool t = trained(LoadKind::contact);
    const double m = default_magnitude(s, LoadKind::contact, gravity);
    const Vec3 p0 = contact_point_of(s);
    const CentrelineCoordinates c = centreline_coordinates(s.vessel, p0);
    const double L = s.vessel.centreline_length();
    const std::string held = t ? "other contact point" : other_type;
    out.push_back({"contact θ+0°", t, t ? "training" : other_type, LoadKind::contact, m, p0});
    if (!other_vessel) {
      out.push_back({"contact θ+90°", t, t ? "training" : other_type, LoadKind::contact, m,
                     wall_point(s.vessel, c.s, c.theta + 0.5 * std::numbers::pi, c.rho)});
      out.push_back({"contact θ+180°", false, held, LoadKind::contact, m,
                     wall_point(s.vessel, c.s, c.theta + std::numbers::pi, c.rho)});
      const double s2 = std::min(c.s + 0.25 * L, 0.85 * L);
      out.push_back({"contact θ−45°, s+L/4", false, held, LoadKind::contact, m,
                     wall_point(s.vessel, s2, c.theta - 0.25 * std::numbers::pi, c.rho)});
    }
  }
  for (const LoadKind k : {LoadKind::pressure, LoadKind::gravity}) {
    const bool t = trained(k);
    out.push_back({to_string(k), t, t ? "training" : other_type, k,
                   default_magnitude(s, k, gravity), Vec3::Zero()});
  }
  return out;
}

/// The other magnitudes of the scene's own load at its point (added once the reference's strain
/// per unit load is known: only those within the linear regime).
std::vector<double> other_magnitudes(const Scene& s, double strain_unit) {
  std::vector<double> out;
  const double m0 = training_magnitude(s);
  for (const double m : s.load.magnitudes) {
    if (m != m0 && m * strain_unit <= kLinearRegimeStrain) out.push_back(m);
  }
  return out;
}

/// The FEM answers of one load shape at unit magnitude.
struct ShapeAnswer {
  std::vector<Vec3> reference_at_network;
  std::vector<Vec3> reference_at_mesh;
  std::vector<Vec3> p1;  ///< P1 on the model's mesh, at its nodes
  double p1_seconds = 0.0;
  double strain_unit = 0.0;
};

/// One vessel: its scene, the model's mesh, the reference mesh and the base network.
struct VesselContext {
  const Scene* scene = nullptr;
  int level = 0;
  VesselParams vessel;  ///< at the model's level
  TetMesh mesh;
  TetMesh reference_mesh;
  msm::BuiltNetwork base;
  std::map<std::string, ShapeAnswer> shapes;
  fem::SolutionCache* cache = nullptr;  ///< FEM solutions kept on disk (nullptr: none)
};

std::string shape_key(const LoadCase& c) {
  std::ostringstream k;
  k << to_string(c.kind);
  if (c.kind == LoadKind::contact) k << std::setprecision(17) << c.point.transpose();
  return k.str();
}

std::vector<Vec3> scaled(const std::vector<Vec3>& u, double f) {
  std::vector<Vec3> out(u.size());
  for (std::size_t i = 0; i < u.size(); ++i) out[i] = f * u[i];
  return out;
}

const ShapeAnswer& shape_answer(VesselContext& v, const LoadCase& c, double nu,
                                std::ostream& log) {
  const std::string key = shape_key(c);
  const auto it = v.shapes.find(key);
  if (it != v.shapes.end()) return it->second;
  LoadCase unit = c;
  unit.magnitude = 1.0;
  const Scene cs = case_scene(*v.scene, unit);
  log << "  FEM reference P2 (level " << v.scene->reference_level << ") and P1 (level " << v.level
      << ") for " << v.scene->name << ": " << c.name << " ..." << std::flush;
  Stopwatch clock;
  ShapeAnswer a;
  {
    const fem::ElasticityProblem p2 = fem_problem(cs, v.reference_mesh, nu, 2, 1.0);
    fem::ElasticitySolver ref(v.reference_mesh, p2);
    a.strain_unit = fem::solve_with(v.cache, ref, v.reference_mesh, p2).max_abs_principal_strain;
    a.reference_at_network = ref.displacement_at(v.base.network.nodes, kOutsideTolerance);
    a.reference_at_mesh = ref.displacement_at(v.mesh.nodes, kOutsideTolerance);
  }
  fem::ElasticityProblem p1 = fem_problem(cs, v.mesh, nu, 1, 1.0);
  p1.options.formulation = fem::Formulation::displacement;
  fem::ElasticitySolver p1_solver(v.mesh, p1);
  // From the cache, P1's time is the one measured when it was solved.
  const fem::ElasticityResult& r = fem::solve_with(v.cache, p1_solver, v.mesh, p1);
  a.p1 = r.nodal_displacement;
  a.p1_seconds = r.timings.assembly + r.timings.solve;
  const std::streamsize precision = log.precision();
  log << " " << std::fixed << std::setprecision(1) << clock.seconds() << " s\n"
      << std::defaultfloat << std::setprecision(static_cast<int>(precision));
  return v.shapes.emplace(key, std::move(a)).first->second;
}

/// A model's nodal displacements (m) for one case, solved as the harness solves it.
struct ModelAnswer {
  std::vector<Vec3> u;
  double update_seconds = 0.0;
};

ModelAnswer solve_model(const Scene& cs, const ModelSpec& spec, const msm::BuiltNetwork& built,
                        const TetMesh& mesh, double magnitude) {
  const auto model = msm::make_model(built, spec.damping);
  const msm::Problem p = msm_problem(cs, *model, built, mesh, magnitude);
  Eigen::VectorXd x;
  ModelAnswer a;
  if (msm::supports_updates(spec.solver)) {
    UpdateSequence seq = timed_updates(p, spec.solver, kRampUpdates, 1);
    x = std::move(seq.x);
    a.update_seconds = seq.update_seconds;
  } else {
    msm::SolveResult r = msm::solve(p, spec.solver, &built.network);
    x = std::move(r.x);
    a.update_seconds = r.seconds;
  }
  const auto& nodes = built.network.nodes;
  a.u.resize(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    a.u[i] = x.segment<3>(3 * static_cast<Eigen::Index>(i)) - nodes[i];
  }
  return a;
}

const ModelSpec& pick_model(const Scene& s, const std::string& name) {
  if (!name.empty()) {
    for (const ModelSpec& m : s.models) {
      if (m.name != name) continue;
      if (m.kind != ModelKind::surface_msm && m.kind != ModelKind::volume_msm) {
        throw InputError("calibrate: --model " + name + " is a " + to_string(m.kind) +
                         " model; expected a surface_msm or volume_msm model (a network file's "
                         "stiffness is the file's own; an outside model's is its own)");
      }
      return m;
    }
    std::string names;
    for (const ModelSpec& m : s.models) names += (names.empty() ? "" : ", ") + m.name;
    throw InputError("calibrate: --model " + name + ": no such model in " + s.source.string() +
                     "; expected one of " + names);
  }
  for (const ModelSpec& m : s.models) {
    if (m.volume_term) return m;
  }
  for (const ModelSpec& m : s.models) {
    if (m.kind == ModelKind::surface_msm || m.kind == ModelKind::volume_msm) return m;
  }
  throw InputError("calibrate: " + s.source.string() + " has no mass-spring model to calibrate");
}

VesselContext make_context(const Scene& s, const ModelSpec& spec, int level, int reference_level,
                           double nu, const CalibrateOptions& o) {
  const std::filesystem::path& cache = o.cache_dir;
  VesselContext v;
  v.cache = o.solution_cache;
  v.scene = &s;
  v.level = level;
  v.vessel = s.vessel;
  v.vessel.level = level;
  v.mesh = scene_mesh(s, level, cache);
  v.reference_mesh = scene_mesh(s, reference_level, cache);
  ModelSpec plain = spec;
  plain.calibration.clear();  // the base: the model's own rule
  v.base = scene_network(s, plain, v.mesh, v.vessel, nu);
  return v;
}

/// Evaluates base, calibrated and P1 on one case of a vessel.
CalibrationCaseResult evaluate_case(VesselContext& v, const LoadCase& c, const ModelSpec& spec,
                                    const msm::BuiltNetwork* calibrated, const std::string& why_not,
                                    double nu, std::ostream& log) {
  const ShapeAnswer& a = shape_answer(v, c, nu, log);
  CalibrationCaseResult r;
  r.scene = v.scene->name;
  r.name = c.name;
  r.training = c.training;
  r.holds_out = c.holds_out;
  r.kind = c.kind;
  r.magnitude = c.magnitude;
  r.point = c.point;
  r.level = v.level;
  r.max_strain_reference = a.strain_unit * c.magnitude;
  r.p1 = compare_displacements(scaled(a.p1, c.magnitude), scaled(a.reference_at_mesh, c.magnitude));
  r.p1_solve_seconds = a.p1_seconds;
  const Scene cs = case_scene(*v.scene, c);
  const std::vector<Vec3> ref = scaled(a.reference_at_network, c.magnitude);
  // A solver failure on one case (e.g. Newton not converging) is that case's outcome, not the
  // study's: recorded and shown, the other cases still evaluated.
  const auto evaluate = [&](const auto& model, auto& errors, double& update_seconds, bool& ok,
                            std::string& failure) {
    try {
      const ModelAnswer answer = solve_model(cs, spec, model, v.mesh, c.magnitude);
      errors = compare_displacements(answer.u, ref);
      update_seconds = answer.update_seconds;
    } catch (const InputError&) {
      throw;
    } catch (const std::runtime_error& e) {
      ok = false;
      failure = e.what();
    }
  };
  evaluate(v.base, r.base, r.base_update_seconds, r.base_ok, r.base_failure);
  if (calibrated) {
    evaluate(*calibrated, r.calibrated, r.calibrated_update_seconds, r.ok, r.failure);
  } else {
    r.ok = false;
    r.failure = why_not;
  }
  log << "  " << r.scene << " L" << r.level << " " << r.name << " (" << r.holds_out << ", "
      << r.magnitude << "): relative L2 P1 " << r.p1.relative_l2 << ", base ";
  if (r.base_ok) {
    log << r.base.relative_l2;
  } else {
    log << "failed (" << r.base_failure << ")";
  }
  if (r.ok) {
    log << ", calibrated " << r.calibrated.relative_l2;
  } else {
    log << ", calibrated failed (" << r.failure << ")";
  }
  log << "\n";
  return r;
}

/// The fitted parameters of a granularity on `net`; `kappa_halves`: κ per half of the wall (a
/// prior with them) for the mesh-indexed granularities.
msm::StiffnessParameters fit_parameters(CalibrationGranularity g, const msm::SpringNetwork& net,
                                        const VesselParams& vessel, bool has_kappa,
                                        bool kappa_halves) {
  switch (g) {
    case CalibrationGranularity::groups: return msm::group_parameters(net, vessel, has_kappa);
    case CalibrationGranularity::wall_layers:
    case CalibrationGranularity::edge_types:
      return msm::wall_layer_parameters(net, vessel, has_kappa,
                                        g == CalibrationGranularity::edge_types);
    case CalibrationGranularity::per_section_spring:
      return msm::per_section_spring_parameters(net, vessel, has_kappa, kappa_halves);
    case CalibrationGranularity::per_spring:
      return msm::per_spring_parameters(net, has_kappa, kappa_halves ? &vessel : nullptr);
  }
  throw std::logic_error("fit_parameters: unknown granularity");
}

/// ν of the study: the option's, else 0.45 where the scene lists it, else the scene's first.
double study_poisson_ratio(const Scene& s, const CalibrateOptions& o) {
  double nu = s.poisson_ratios.front();
  if (std::find(s.poisson_ratios.begin(), s.poisson_ratios.end(), 0.45) != s.poisson_ratios.end())
    nu = 0.45;
  if (o.poisson_ratio) nu = *o.poisson_ratio;
  return nu;
}

/// Held-out cases at the scene's other magnitudes, at the point of its own load kind (else the
/// first case's, contact θ+0°).
void add_other_magnitudes(std::vector<LoadCase>& cases, VesselContext& main, const Scene& scene,
                          double nu, std::ostream& log) {
  const LoadCase& first = cases.front();  // contact θ+0°
  LoadCase own = first;
  for (const LoadCase& c : cases) {
    if (c.kind == scene.load.kind) {
      own = c;
      break;
    }
  }
  const ShapeAnswer& a = shape_answer(main, own, nu, log);
  for (const double m : other_magnitudes(scene, a.strain_unit)) {
    LoadCase c = own;
    c.training = false;
    c.holds_out = "other magnitude";
    c.magnitude = m;
    cases.push_back(c);
  }
}

/// The fit's cases: each training load's force and reference displacements on the network.
struct TrainingSet {
  std::vector<msm::FitCase> cases;
  std::vector<char> fixed;  ///< the model's fixed dofs (the same for every case)
};

/// The training cases (recorded in cal.training_loads), weighted equally or by 1/(P1's relative
/// error)², the weights scaled to a mean of 1. InputError if there is none.
TrainingSet training_set(VesselContext& main, const Scene& scene,
                         const std::vector<LoadCase>& cases, double nu, CaseWeights weights,
                         Calibration& cal, std::ostream& log) {
  TrainingSet t;
  for (const LoadCase& c : cases) {
    if (!c.training) continue;
    const ShapeAnswer& a = shape_answer(main, c, nu, log);
    const auto model = msm::make_model(main.base);
    const msm::Problem p = msm_problem(case_scene(scene, c), *model, main.base, main.mesh, c.magnitude);
    t.fixed = p.fixed;
    Eigen::VectorXd r(p.num_dofs());
    for (std::size_t i = 0; i < a.reference_at_network.size(); ++i) {
      r.segment<3>(3 * static_cast<Eigen::Index>(i)) = c.magnitude * a.reference_at_network[i];
    }
    double weight = 1.0;
    if (weights == CaseWeights::p1) {
      // P1's relative error on this case (linear: the same at every magnitude).
      const double e = compare_displacements(a.p1, a.reference_at_mesh).relative_l2;
      weight = 1.0 / (e * e);
    }
    t.cases.push_back({c.name, p.external_force, r, weight});
    cal.training_loads.push_back({c.name, c.kind, c.magnitude, c.point});
  }
  if (t.cases.empty()) throw InputError("calibrate: no training load; expected --train kinds");
  double mean = 0.0;
  for (const auto& fc : t.cases) mean += fc.weight / static_cast<double>(t.cases.size());
  for (auto& fc : t.cases) fc.weight /= mean;
  return t;
}

/// The fit's start: zero log factors, or with a prior its log factors on this network
/// (refused, naming the file and key, if it belongs to another model or mesh): each
/// parameter's, the mean over its springs (or tets for κ): one value when the prior's classes
/// are unions of these (geometric classes, κ halves).
Eigen::VectorXd prior_start(const CalibrateOptions& o, const VesselContext& main,
                            const ModelSpec& spec, double youngs_modulus, double nu,
                            const msm::StiffnessParameters& params) {
  Eigen::VectorXd theta0 = Eigen::VectorXd::Zero(params.size());
  if (!o.prior) return theta0;
  msm::BuiltNetwork check = main.base;
  apply_calibration(*o.prior, o.prior_source, check, main.mesh, main.vessel, spec,
                    youngs_modulus, nu, false);
  const auto [pp, pt] = calibration_parameters(*o.prior, o.prior_source, main.base, main.vessel);
  std::map<int, std::pair<double, int>> mean;
  for (std::size_t sp = 0; sp < params.of_spring.size(); ++sp) {
    mean[params.of_spring[sp]].first += pp.spring_log_factor(pt, sp);
    mean[params.of_spring[sp]].second += 1;
  }
  for (std::size_t e = 0; e < main.base.network.tets.size(); ++e) {
    const int q = params.kappa_of_tet(e);
    if (q < 0) continue;
    mean[q].first += pp.tet_log_factor(pt, e);
    mean[q].second += 1;
  }
  for (const auto& [q, sum] : mean) theta0[q] = sum.first / sum.second;
  return theta0;
}

/// L-BFGS on the linearised fit from theta0, logging every tenth iteration; its time in
/// `seconds`.
msm::LbfgsResult run_fit(const msm::LinearisedFit& fit, const Eigen::VectorXd& theta0,
                         int max_iterations, std::ostream& log, double& seconds) {
  msm::LbfgsOptions lo;
  lo.max_iterations = max_iterations;
  lo.gradient_tolerance = 1e-6;
  lo.relative_decrease = 1e-10;
  lo.on_iteration = [&](int it, double f, double g) {
    if (it % 10 == 0) log << "    iteration " << it << ": J = " << f << ", |∇J|∞ = " << g << "\n";
  };
  Stopwatch fit_clock;
  const msm::LbfgsResult res = msm::minimize_lbfgs(
      [&](const Eigen::VectorXd& x, Eigen::VectorXd& g) { return fit.objective(x, g); }, theta0,
      lo);
  seconds = fit_clock.seconds();
  return res;
}

/// The model and mesh a calibration belongs to, as its file records them.
void describe_calibrated_model(Calibration& cal, const Scene& s, const ModelSpec& spec,
                               const VesselContext& main, CalibrationGranularity granularity,
                               double nu, int level) {
  cal.granularity = to_string(granularity);
  cal.scene = s.name;
  cal.model = spec.name;
  cal.model_kind = to_string(spec.kind);
  cal.stiffness = msm::to_string(spec.stiffness);
  cal.volume_term = spec.volume_term;
  cal.volume_moduli = msm::to_string(spec.volume_moduli);
  cal.poisson_ratio = nu;
  cal.youngs_modulus = s.youngs_modulus;
  cal.mesh_hash = mesh_hash(main.mesh);
  cal.vessel = describe(main.vessel);
  cal.level = level;
  cal.nodes = main.base.network.nodes.size();
  cal.springs = main.base.network.springs.size();
  cal.tets = main.base.network.tets.size();
}

/// The calibration file's sentence on how it was fitted.
std::string calibration_method(const CalibrateOptions& o, int reference_level) {
  std::ostringstream method;
  method << "least squares on nodal displacements against the P2 reference (level "
         << reference_level << "), model linearised at rest, adjoint gradients, L-BFGS; "
         << (o.granularity == CalibrationGranularity::groups
                 ? "a factor per spring class and kappa, ridge on the log factors"
             : o.granularity == CalibrationGranularity::wall_layers
                 ? "a factor per spring class (direction x layer through the wall) and per half "
                   "of the wall for kappa, ridge on the log factors"
             : o.granularity == CalibrationGranularity::edge_types
                 ? "a factor per spring class (edge type x layer through the wall) and per half "
                   "of the wall for kappa, ridge on the log factors"
             : o.granularity == CalibrationGranularity::per_section_spring
                 ? "a factor per spring of a cross-section (springs that are images of each "
                   "other along the centreline share it) and kappa, smoothness regulariser on "
                   "log k over springs sharing a node"
                 : "a factor per spring and kappa, smoothness regulariser on log k over springs "
                   "sharing a node");
  if (o.prior) {
    method << "; started from and regularised towards the " << o.prior->granularity
           << " calibration " << o.prior_source
           << " (smoothness and ridge on each factor's departure from it)";
  }
  if (o.weights == CaseWeights::p1) {
    method << "; training cases weighted by 1/(P1's relative L2 error)^2 (the fit minimises the "
              "mean squared ratio to P1)";
  }
  return method.str();
}

/// Other vessels: the group calibration applied to their meshes (calibration_transfer), each
/// case evaluated; a calibration that does not transfer is each case's failure.
void add_transfer_cases(CalibrationStudy& study, const CalibrateOptions& o, const ModelSpec& spec,
                        const Calibration& cal, const std::vector<LoadKind>& train, double nu,
                        std::ostream& log) {
  for (const Scene& other_scene : o.other_vessels) {
    const int other_level = other_scene.model_levels.front();
    VesselContext other =
        make_context(other_scene, spec, other_level, other_scene.reference_level, nu, o);
    msm::BuiltNetwork transferred = other.base;
    std::string why;
    const msm::BuiltNetwork* use = &transferred;
    try {
      apply_calibration(cal, "calibration", transferred, other.mesh, other.vessel, spec,
                        other_scene.youngs_modulus, nu, true);
    } catch (const InputError& e) {
      why = e.what();
      use = nullptr;
    }
    for (const LoadCase& c : load_cases(other_scene, train, true, o.gravity)) {
      study.cases.push_back(evaluate_case(other, c, spec, use, why, nu, log));
    }
  }
}

}  // namespace

CalibrationStudy calibrate_scene(const Scene& s, const CalibrateOptions& o) {
  std::ostream null_stream(nullptr);
  std::ostream& log = o.log ? *o.log : null_stream;
  const ModelSpec& spec = pick_model(s, o.model);
  const double nu = study_poisson_ratio(s, o);
  const int level = o.level.value_or(s.model_levels.front());
  const int reference_level = o.reference_level.value_or(s.reference_level);
  const bool mesh_indexed = o.granularity == CalibrationGranularity::per_spring ||
                            o.granularity == CalibrationGranularity::per_section_spring;
  if (mesh_indexed && !o.other_vessels.empty()) {
    throw InputError(
        "calibrate: --held-out-scene with --granularity " + to_string(o.granularity) +
        ": such a calibration cannot transfer to another mesh (its factors are indexed by one "
        "mesh's springs); use --granularity groups for another vessel");
  }
  std::vector<LoadKind> train = o.train.empty() ? std::vector<LoadKind>{s.load.kind} : o.train;
  Scene scene = s;
  scene.reference_level = reference_level;

  log << "calibrate " << spec.name << " of " << s.name << " (ν = " << nu << ", level " << level
      << ", reference P2 level " << reference_level << ", " << to_string(o.granularity) << ")\n";
  VesselContext main = make_context(scene, spec, level, reference_level, nu, o);

  // The cases: the fixed list, plus the scene's other magnitudes at its point.
  std::vector<LoadCase> cases = load_cases(scene, train, false, o.gravity);
  add_other_magnitudes(cases, main, scene, nu, log);

  // The fit on the training cases.
  const bool has_kappa = main.base.terms.volume_kappa.has_value();
  if (o.prior && !mesh_indexed) {
    throw InputError("calibrate: --prior " + o.prior_source + " with --granularity " +
                     to_string(o.granularity) + ": expected --granularity per-spring or "
                     "per-section-spring (a prior is what their factors depart from)");
  }
  const bool prior_halves =
      o.prior && std::find(o.prior->names.begin(), o.prior->names.end(), "kappa/inner") !=
                     o.prior->names.end();
  msm::StiffnessParameters params =
      fit_parameters(o.granularity, main.base.network, main.vessel, has_kappa, prior_halves);
  Calibration cal;
  const TrainingSet training = training_set(main, scene, cases, nu, o.weights, cal, log);
  // Groups: the ridge alone (without it a contact-only fit drove the circumferential classes to
  // ~0 and κ up 12×, which fitted contact and failed pressure by 4× P1; docs/physics/calibration.md).
  msm::Regulariser reg = !mesh_indexed ? msm::Regulariser{0.0, o.regulariser.ridge, {}}
                                       : o.regulariser;
  const Eigen::VectorXd theta0 = prior_start(o, main, spec, s.youngs_modulus, nu, params);
  if (o.prior) reg.centre = theta0;
  const msm::LinearisedFit fit(main.base.network, main.base.terms.volume_kappa, training.fixed, params,
                               training.cases, reg);
  log << "  fitting " << params.size() << " parameters on " << training.cases.size()
      << " training loads (model linearised at rest, adjoint gradients, L-BFGS"
      << (o.prior ? ", from and towards " + o.prior_source : std::string()) << ")\n";
  const std::vector<double> before = fit.relative_errors(theta0);
  CalibrationStudy study;
  const msm::LbfgsResult res = run_fit(fit, theta0, o.max_iterations, log, study.fit_seconds);
  const std::vector<double> after = fit.relative_errors(res.x);
  log << "  fit: J " << fit.misfit(theta0) << " → " << res.f << " in " << res.iterations
      << " iterations (" << res.stop_reason << "), " << study.fit_seconds << " s\n";

  describe_calibrated_model(cal, s, spec, main, o.granularity, nu, level);
  set_calibration_parameters(cal, params, res.x);
  cal.method = calibration_method(o, reference_level);
  cal.smoothness = reg.smoothness;
  cal.ridge = reg.ridge;
  cal.objective_before = fit.misfit(theta0) + fit.regularisation(theta0);
  cal.objective_after = res.f;
  cal.iterations = res.iterations;
  cal.stop_reason = res.stop_reason;
  for (std::size_t i = 0; i < training.cases.size(); ++i) {
    cal.fit_cases.push_back({training.cases[i].name, before[i], after[i]});
  }
  study.calibration = cal;

  // The calibrated network through the file's own path (apply_calibration), then every case.
  msm::BuiltNetwork calibrated = main.base;
  apply_calibration(cal, "calibration", calibrated, main.mesh, main.vessel, spec, s.youngs_modulus,
                    nu, false);
  std::ostringstream detail;
  detail << msm::to_string(spec.stiffness)
         << (spec.volume_term ? " + volume term (" + msm::to_string(spec.volume_moduli) + ")" : "")
         << ", " << msm::to_string(spec.solver);
  study.model_detail = detail.str();
  for (const LoadCase& c : cases) {
    study.cases.push_back(evaluate_case(main, c, spec, &calibrated, "", nu, log));
  }
  add_transfer_cases(study, o, spec, cal, train, nu, log);
  return study;
}

}  // namespace vessel
