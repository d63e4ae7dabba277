#include "verification/studies/stability/study_models.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "msm/solvers/static_solver.hpp"
#include "msm/solvers/critical_step.hpp"
#include "msm/stability/stability_search.hpp"
#include "verification/scene_problems.hpp"
#include "verification/harness/timing.hpp"

namespace vessel::stability_study {

std::ostream& null_stream() {
  static std::ostringstream sink;
  sink.str("");
  return sink;
}

std::string fmt(double v, int precision) {
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

Scene study_scene(const VesselParams& vessel, double E, double force, double patch_radius) {
  Scene s;
  s.name = "stability";
  s.source = "the stability study";
  s.vessel = vessel;
  s.youngs_modulus = E;
  s.boundary = {{std::string(group_names::inlet), EndCondition::clamped},
                {std::string(group_names::outlet), EndCondition::clamped}};
  s.load.kind = LoadKind::contact;
  s.load.magnitudes = {force};
  s.load.contact.surface_group = std::string(group_names::inner_wall);
  s.load.contact.point = default_contact_point(vessel, s.load.contact.surface_group);
  s.load.contact.radius = patch_radius;
  return s;
}

namespace {
ModelSpec spring_model(ModelKind kind, msm::StiffnessRule rule) {
  ModelSpec m;
  m.kind = kind;
  m.stiffness = rule;
  m.name = std::string(kind == ModelKind::volume_msm ? "volume" : "surface") + " / " +
           msm::to_string(rule);
  return m;
}
}  // namespace

ModelSpec volume_model(msm::StiffnessRule rule) {
  return spring_model(ModelKind::volume_msm, rule);
}
ModelSpec surface_model(msm::StiffnessRule rule) {
  return spring_model(ModelKind::surface_msm, rule);
}

std::unique_ptr<StudyModel> build_model(const Scene& scene, const TetMesh& mesh,
                                        const ModelSpec& spec, double nu) {
  auto m = std::make_unique<StudyModel>();
  m->built = msm::build_network(mesh, scene.vessel, network_options(scene, spec, nu));
  m->model = msm::make_model(m->built, spec.damping);
  m->problem = msm_problem(scene, *m->model, m->built, mesh, scene.load.magnitudes.front());
  m->contact_node = nearest_node(m->built.network.nodes, qoi_point(scene));
  return m;
}

std::unique_ptr<StudyModel> with_damping(const StudyModel& base, double c) {
  auto m = std::make_unique<StudyModel>();
  m->built = base.built;
  m->model = msm::make_model(m->built, c);
  m->problem = base.problem;
  m->problem.form = m->model.get();
  m->contact_node = base.contact_node;
  return m;
}

double mean_mass(const msm::Problem& p) { return p.mass.sum() / static_cast<double>(p.mass.size()); }

FemRun run_fem(const Scene& scene, const TetMesh& mesh, double nu, int degree,
               fem::Formulation f) {
  FemRun r;
  Stopwatch clock;
  try {
    fem::ElasticityProblem pb =
        fem_problem(scene, mesh, nu, degree, scene.load.magnitudes.front());
    pb.options.formulation = f;
    pb.options.solver = fem::LinearSolver::direct;
    const fem::ElasticityResult res = fem::solve_elasticity(mesh, pb);
    r.u = res.nodal_displacement;
    r.element = res.element;
    r.u_contact = r.u[nearest_node(mesh.nodes, qoi_point(scene))].norm();
    r.max_strain = res.max_abs_principal_strain;
    bool finite = std::isfinite(r.max_strain);
    for (const Vec3& u : r.u) finite = finite && u.allFinite();
    if (!finite) throw std::runtime_error("non-finite displacement in the FEM result");
    r.ok = true;
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  r.seconds = clock.seconds();
  return r;
}

/// Tets of `mesh` with non-positive signed volume when its nodes are at `x` (flat, 3 per node).
std::string short_error(const std::string& what) {
  return what.size() > 300 ? what.substr(0, 300) + " …" : what;
}

HardCaseOutcome fem_outcome(const std::string& name, const FemRun& r) {
  HardCaseOutcome o;
  o.model = name;
  o.finished = r.ok;
  o.converged = r.ok;
  if (r.ok) {
    o.reported = "contact-point displacement " + fmt(r.u_contact * 1e3) +
                 " mm, largest |principal strain| " + fmt(r.max_strain * 100, 3) + " % (" +
                 fmt(r.seconds, 2) + " s)";
    o.values["u_contact_mm"] = r.u_contact * 1e3;
    o.values["max_strain"] = r.max_strain;
  } else {
    o.reported = "refused/failed: " + short_error(r.error);
  }
  return o;
}

/// Static Newton on a model; outcome with the contact displacement.
HardCaseOutcome static_outcome(const std::string& name, const StudyModel& m,
                               Eigen::VectorXd* x_out) {
  HardCaseOutcome o;
  o.model = name;
  Stopwatch clock;
  try {
    const msm::StaticResult r = msm::solve_static(m.problem);
    o.finished = true;
    o.converged = r.converged;
    bool finite = r.x.allFinite();
    if (!finite) {
      o.finished = false;
      o.reported = "non-finite result";
      return o;
    }
    const double u = m.contact_displacement(r.x);
    o.reported = "static Newton: " + std::to_string(r.iterations) +
                 " iterations, contact-point displacement " + fmt(u * 1e3) +
                 " mm, largest spring strain " + fmt(m.model->max_strain(r.x) * 100, 3) + " % (" +
                 fmt(clock.seconds(), 2) + " s)";
    o.values["u_contact_mm"] = u * 1e3;
    o.values["iterations"] = r.iterations;
    o.values["max_spring_strain"] = m.model->max_strain(r.x);
    if (x_out) *x_out = r.x;
  } catch (const std::exception& e) {
    o.finished = false;
    o.converged = false;
    o.reported = "static Newton failed: " + short_error(e.what());
  }
  return o;
}

std::vector<Vec3> unflatten(const Eigen::VectorXd& x) {
  std::vector<Vec3> v(static_cast<std::size_t>(x.size() / 3));
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = x.segment<3>(3 * static_cast<Eigen::Index>(i));
  return v;
}

/// A dynamic run; outcome bounded or the DivergenceError's message.
HardCaseOutcome dynamic_outcome(const std::string& name, const msm::Problem& p, Integrator in,
                                double dt, int steps, const Eigen::VectorXd& v0,
                                Eigen::VectorXd* x_out) {
  HardCaseOutcome o;
  o.model = name;
  msm::DynamicOptions d;
  d.integrator = in;
  d.dt = dt;
  d.steps = steps;
  Stopwatch clock;
  try {
    const msm::DynamicResult r = msm::integrate(p, d, p.rest, v0);
    o.finished = true;
    o.bounded = true;
    o.reported = std::to_string(steps) + " steps of " + fmt(dt) + " s: bounded, final energy " +
                 fmt(r.energy) + " J (" + fmt(clock.seconds(), 2) + " s)";
    o.values["final_energy_J"] = r.energy;
    if (x_out) *x_out = r.x;
  } catch (const msm::DivergenceError& e) {
    o.finished = false;
    o.bounded = false;
    o.reported = "stopped: " + short_error(e.what());
    o.values["diverged_at_step"] = e.step;
  } catch (const std::exception& e) {
    o.finished = false;
    o.reported = "failed: " + short_error(e.what());
  }
  o.values["dt_s"] = dt;
  return o;
}

TetMesh case_mesh(const Scene& scene, const StabilityOptions& o) {
  return vessel::scene_mesh(scene, scene.vessel.level, o.cache_dir);
}

/// Predicted and found symplectic-Euler step of a volume model, as an outcome.
HardCaseOutcome step_outcome(const std::string& name, const StudyModel& m, int steps) {
  HardCaseOutcome o;
  o.model = name;
  try {
    const msm::Spectrum s = msm::analyse_spectrum(m.problem, {.lowest = false});
    const double pred = msm::predicted_critical_step(Integrator::symplectic_euler, s);
    msm::StabilitySearchOptions so;
    so.steps = steps;
    so.tolerance = 1e-2;
    const auto r = msm::find_stable_step(m.problem, pred, so);
    o.finished = true;
    o.bounded = true;
    o.reported = "symplectic Euler critical step predicted " + fmt(pred) + " s, found " +
                 fmt(r.stable_dt) + " s (ω_max " + fmt(s.omega_max) + " rad/s)";
    o.values["predicted_dt_s"] = pred;
    o.values["found_dt_s"] = r.stable_dt;
  } catch (const std::exception& e) {
    o.reported = "failed: " + short_error(e.what());
  }
  return o;
}

}  // namespace vessel::stability_study
