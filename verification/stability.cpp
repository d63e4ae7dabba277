#include "verification/stability.hpp"

#include <cmath>
#include <iomanip>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <sstream>

#include "fem_reference/elasticity.hpp"
#include "meshes/atomic_file.hpp"
#include "meshes/errors.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/mesh_cache.hpp"
#include "meshes/mesh_quality.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/model/build_network.hpp"
#include "msm/model/spring_model.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/solvers/static_solver.hpp"
#include "msm/stability/critical_step.hpp"
#include "msm/stability/stability_search.hpp"
#include "verification/timing.hpp"

namespace vessel {

namespace {

using msm::Integrator;

std::ostream& null_stream() {
  static std::ostringstream sink;
  sink.str("");
  return sink;
}

std::string fmt(double v, int precision = 4) {
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

/// Default contact point: inner wall at mid-length on the θ = 0 side (as `vesselverify msm`).
Vec3 default_contact_point(const VesselParams& p) {
  if (p.kind == VesselKind::straight) return {p.inner_radius, 0.0, 0.5 * p.length};
  const double alpha = std::numbers::pi / 2;
  return (p.bend_radius + p.inner_radius) * Vec3(std::cos(alpha), std::sin(alpha), 0.0);
}

int nearest_node(const std::vector<Vec3>& nodes, const Vec3& p) {
  int best = 0;
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const double di = (nodes[i] - p).squaredNorm();
    if (di < d) {
      d = di;
      best = static_cast<int>(i);
    }
  }
  return best;
}

/// A mass-spring model on a mesh with the shared contact load, inlet and outlet fixed.
struct Msm {
  msm::BuiltNetwork built;
  std::unique_ptr<msm::SpringModel> model;
  msm::Problem problem;
  Vec3 point = Vec3::Zero();
  int contact_node = 0;
  [[nodiscard]] double contact_displacement(const Eigen::VectorXd& x) const {
    return (x.segment<3>(3 * contact_node) - problem.rest.segment<3>(3 * contact_node)).norm();
  }
};

struct ModelSpec {
  std::string model;  ///< surface | volume
  msm::StiffnessRule rule;
  [[nodiscard]] std::string name() const { return model + " / " + msm::to_string(rule); }
};

std::unique_ptr<Msm> make_msm(const TetMesh& mesh, const VesselParams& params,
                              const ModelSpec& spec, double E, double nu, double force,
                              const Vec3& point, double patch_radius = 0.5e-3,
                              double point_damping = 0.0) {
  auto m = std::make_unique<Msm>();
  msm::NetworkOptions no;
  no.model = msm::parse_model_type(spec.model);
  no.stiffness = spec.rule;
  no.stiffness_params.youngs_modulus = E;
  no.stiffness_params.poisson_ratio = nu;
  m->built = msm::build_network(mesh, params, no);
  m->model = std::make_unique<msm::SpringModel>(m->built.network, point_damping);
  std::vector<Vec3> loads(mesh.nodes.size(), Vec3::Zero());
  if (force > 0) {
    ContactPatchSpec cs;
    cs.point = point;
    cs.radius = patch_radius;
    cs.force = force;
    loads = traction_nodal_loads(mesh, contact_patch(mesh, cs));
  }
  m->problem = msm::make_problem(*m->model, m->built.network, m->built.masses, mesh, loads,
                                 {"inlet", "outlet"});
  m->point = point;
  m->contact_node = nearest_node(m->built.network.nodes, point);
  return m;
}

/// The same network with point damping c (a new SpringModel; problem copied).
std::unique_ptr<Msm> with_damping(const Msm& base, double c) {
  auto m = std::make_unique<Msm>();
  m->built = base.built;
  m->model = std::make_unique<msm::SpringModel>(m->built.network, c);
  m->problem = base.problem;
  m->problem.form = m->model.get();
  m->point = base.point;
  m->contact_node = base.contact_node;
  return m;
}

double mean_mass(const msm::Problem& p) { return p.mass.sum() / static_cast<double>(p.mass.size()); }

struct FemRun {
  bool ok = false;
  std::string error;
  std::string element;
  double u_contact = 0.0;  ///< m
  double max_strain = 0.0;
  double seconds = 0.0;
  std::vector<Vec3> u;
};

FemRun run_fem(const TetMesh& mesh, double E, double nu, int degree, fem::Formulation f,
               const Vec3& point, double force, double patch_radius = 0.5e-3) {
  FemRun r;
  Stopwatch clock;
  try {
    fem::ElasticityProblem pb;
    pb.material.youngs_modulus = E;
    pb.material.poisson_ratio = nu;
    pb.dirichlet = {fem::DirichletCondition::clamped("inlet"),
                    fem::DirichletCondition::clamped("outlet")};
    ContactPatchSpec cs;
    cs.point = point;
    cs.radius = patch_radius;
    cs.force = force;
    pb.patches = {contact_patch(mesh, cs)};
    pb.options.degree = degree;
    pb.options.formulation = f;
    pb.options.solver = fem::LinearSolver::direct;
    const fem::ElasticityResult res = fem::solve_elasticity(mesh, pb);
    r.u = res.nodal_displacement;
    r.element = res.element;
    r.u_contact = r.u[static_cast<std::size_t>(nearest_node(mesh.nodes, point))].norm();
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
std::size_t inverted_tets(const TetMesh& mesh, const std::vector<Vec3>& x) {
  std::size_t n = 0;
  for (const Tet& t : mesh.tets) {
    if (!(signed_volume(x[t[0]], x[t[1]], x[t[2]], x[t[3]]) > 0)) ++n;
  }
  return n;
}

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

/// Static Newton on an Msm; outcome with the contact displacement.
HardCaseOutcome static_outcome(const std::string& name, const Msm& m,
                               Eigen::VectorXd* x_out = nullptr) {
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
                                double dt, int steps, const Eigen::VectorXd& v0 = {},
                                Eigen::VectorXd* x_out = nullptr) {
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

TetMesh load_mesh(const VesselParams& p, const StabilityOptions& o) {
  return load_or_generate_vessel(p, o.cache_dir, {});
}

// ---------------------------------------------------------------------------------------------
// (a) predicted vs found critical steps

struct IntegratorConfig {
  Integrator integrator;
  double zeta;  ///< target damping ratio on the top mode; 0: undamped
};
constexpr IntegratorConfig kConfigs[] = {{Integrator::symplectic_euler, 0.0},
                                         {Integrator::verlet, 0.0},
                                         {Integrator::explicit_euler, 0.3},
                                         {Integrator::symplectic_euler, 0.3}};

std::vector<CriticalStepRow> critical_step_table(const StabilityOptions& o, int max_level,
                                                 int steps, std::ostream& log) {
  const std::vector<ModelSpec> specs{{"surface", msm::StiffnessRule::seed000},
                                     {"volume", msm::StiffnessRule::seed001},
                                     {"volume", msm::StiffnessRule::van_gelder}};
  std::vector<CriticalStepRow> rows;
  for (int level = 0; level <= max_level; ++level) {
    VesselParams params;
    params.level = level;
    const TetMesh mesh = load_mesh(params, o);
    for (const ModelSpec& spec : specs) {
      const auto base = make_msm(mesh, params, spec, 14.24e3, 0.25, 0.0, Vec3::Zero());
      const msm::Spectrum s0 = msm::analyse_spectrum(base->problem, {.lowest = false});
      for (const IntegratorConfig& cfg : kConfigs) {
        Stopwatch clock;
        CriticalStepRow row;
        row.model = spec.name();
        row.integrator = msm::to_string(cfg.integrator);
        row.zeta = cfg.zeta;
        row.level = level;
        row.nodes = static_cast<int>(base->built.network.nodes.size());
        row.springs = static_cast<int>(base->built.network.springs.size());
        row.h_nominal = unstructured_mesh_size(params);
        // Point damping c = 2ζ ω_max m̄ (seed 000 eq. 3.3): ζ on the top mode exactly for
        // uniform masses, approximately (Rayleigh quotient) for the consistent ones used here.
        row.point_damping = 2.0 * cfg.zeta * s0.omega_max * mean_mass(base->problem);
        std::unique_ptr<Msm> damped;
        const Msm* m = base.get();
        msm::Spectrum s = s0;
        if (cfg.zeta > 0) {
          damped = with_damping(*base, row.point_damping);
          m = damped.get();
          s = msm::analyse_spectrum(m->problem, {.lowest = cfg.integrator ==
                                                            Integrator::explicit_euler});
        }
        row.omega_max = s.omega_max;
        row.omega_gershgorin = s.gershgorin;
        row.omega_min = s.omega_min;
        row.gamma_max = s.gamma_max;
        row.predicted_dt = msm::predicted_critical_step(cfg.integrator, s);
        row.guaranteed_dt = msm::guaranteed_critical_step(cfg.integrator, s);
        msm::StabilitySearchOptions so;
        so.integrator = cfg.integrator;
        so.steps = steps;
        so.tolerance = 5e-3;
        const msm::StabilitySearchResult r =
            msm::find_stable_step(m->problem, row.predicted_dt, so);
        row.found_dt = r.stable_dt;
        row.unstable_dt = r.unstable_dt;
        row.trials = r.trials;
        row.steps_per_trial = steps;
        row.seconds = clock.seconds();
        log << "  L" << level << " " << row.model << ", " << row.integrator
            << (cfg.zeta > 0 ? " (ζ " + fmt(cfg.zeta) + ")" : "") << ": predicted "
            << fmt(row.predicted_dt) << " s, found " << fmt(row.found_dt) << " s (×"
            << fmt(row.found_dt / row.predicted_dt, 4) << "; guaranteed " << fmt(row.guaranteed_dt)
            << " s), " << r.trials << " trials, "
            << fmt(row.seconds, 2) << " s" << std::endl;
        rows.push_back(row);
      }
    }
  }
  return rows;
}

std::vector<RefinementFit> refinement_fits(const std::vector<CriticalStepRow>& rows) {
  std::vector<RefinementFit> fits;
  std::set<std::tuple<std::string, std::string, double>> keys;
  for (const auto& r : rows) keys.insert({r.model, r.integrator, r.zeta});
  for (const auto& [model, integrator, zeta] : keys) {
    RefinementFit f{model, integrator, zeta, {}, 0.0, 0.0};
    std::vector<double> h, found, predicted;
    for (const auto& r : rows) {
      if (r.model == model && r.integrator == integrator && r.zeta == zeta) {
        f.levels.push_back(r.level);
        h.push_back(r.h_nominal);
        found.push_back(r.found_dt);
        predicted.push_back(r.predicted_dt);
      }
    }
    if (h.size() < 2) continue;
    f.exponent = loglog_slope(h, found);
    f.predicted_exponent = loglog_slope(h, predicted);
    fits.push_back(f);
  }
  return fits;
}

// ---------------------------------------------------------------------------------------------
// (b) hard cases

HardCase case_poisson(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "poisson";
  hc.title = "Near-incompressible material: ν = 0.49, 0.499, 0.5";
  const double force = 1e-4;
  hc.setup =
      "Straight tube, level 0, inlet and outlet clamped, contact load " + fmt(force * 1e3) +
      " mN on the shared 0.5 mm patch, E = 14.24 kPa. FEM P1 and P2 in the displacement "
      "formulation and Taylor–Hood P2–P1 (mixed); volume mass-spring models with each stiffness "
      "rule (static Newton; only `lloyd` reads ν). Displacement at the mesh node nearest the "
      "contact point.";
  VesselParams params;
  const TetMesh mesh = load_mesh(params, o);
  const Vec3 point = default_contact_point(params);
  for (double nu : {0.49, 0.499, 0.5}) {
    log << "  ν = " << nu << std::endl;
    const FemRun mixed = run_fem(mesh, 14.24e3, nu, 2, fem::Formulation::mixed, point, force);
    for (int degree : {1, 2}) {
      const FemRun r =
          run_fem(mesh, 14.24e3, nu, degree, fem::Formulation::displacement, point, force);
      HardCaseOutcome oc = fem_outcome("FEM P" + std::to_string(degree) +
                                           " displacement, ν = " + fmt(nu),
                                       r);
      if (r.ok && mixed.ok) {
        oc.reported += "; " + fmt(r.u_contact / mixed.u_contact, 3) + " × the mixed element's";
        oc.values["ratio_to_mixed"] = r.u_contact / mixed.u_contact;
      }
      hc.outcomes.push_back(oc);
    }
    hc.outcomes.push_back(fem_outcome("FEM P2–P1 mixed, ν = " + fmt(nu), mixed));
    for (msm::StiffnessRule rule : {msm::StiffnessRule::seed000, msm::StiffnessRule::seed001,
                                    msm::StiffnessRule::van_gelder, msm::StiffnessRule::lloyd}) {
      // Rules other than lloyd ignore ν: run them once (at ν = 0.49).
      if (rule != msm::StiffnessRule::lloyd && nu != 0.49) continue;
      const ModelSpec spec{"volume", rule};
      const std::string name =
          spec.name() + (rule == msm::StiffnessRule::lloyd ? ", ν = " + fmt(nu) : " (any ν)");
      try {
        const auto m = make_msm(mesh, params, spec, 14.24e3, nu, force, point);
        HardCaseOutcome oc = static_outcome(name, *m);
        if (oc.finished && mixed.ok) {
          oc.reported += "; " + fmt(oc.values["u_contact_mm"] / (mixed.u_contact * 1e3), 3) +
                         " × the mixed FEM's at ν = " + fmt(nu);
        }
        hc.outcomes.push_back(oc);
      } catch (const std::exception& e) {
        hc.outcomes.push_back({name, false, false, {}, "refused: " + short_error(e.what()), {}});
      }
    }
  }
  return hc;
}

HardCase case_youngs_modulus(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "youngs_modulus";
  hc.title = "E from 1 kPa to 1 MPa at a fixed step";
  const int steps = o.quick ? 1000 : 5000;
  VesselParams params;
  const TetMesh mesh = load_mesh(params, o);
  const Vec3 point = default_contact_point(params);
  const ModelSpec spec{"volume", msm::StiffnessRule::seed001};
  const double E0 = 14.24e3;
  const auto ref = make_msm(mesh, params, spec, E0, 0.25, 0.0, point);
  const double dt =
      0.9 * msm::predicted_critical_step(Integrator::symplectic_euler,
                                         msm::analyse_spectrum(ref->problem, {.lowest = false}));
  hc.setup = "Volume model (seed001), straight tube level 0, contact load 0.1 mN × E/14.24 kPa "
             "(the same strain at every E), suddenly applied, undamped; every run at dt = " +
             fmt(dt) + " s (0.9 × the predicted critical step at E = 14.24 kPa), " +
             std::to_string(steps) + " steps (20 for implicit Euler). FEM P1 static at the "
             "extremes.";
  for (double E : {1e3, 1e4, E0, 1e5, 1e6}) {
    log << "  E = " << E << " Pa" << std::endl;
    const double force = 1e-4 * E / E0;
    const auto m = make_msm(mesh, params, spec, E, 0.25, force, point);
    const double crit = msm::predicted_critical_step(
        Integrator::symplectic_euler, msm::analyse_spectrum(m->problem, {.lowest = false}));
    for (Integrator in : {Integrator::symplectic_euler, Integrator::verlet,
                          Integrator::implicit_euler}) {
      HardCaseOutcome oc =
          dynamic_outcome(spec.name() + ", " + msm::to_string(in) + ", E = " + fmt(E) + " Pa",
                          m->problem, in, dt, in == Integrator::implicit_euler ? 20 : steps);
      oc.reported += "; predicted critical step " + fmt(crit) + " s (dt/critical " +
                     fmt(dt / crit, 3) + ")";
      oc.values["critical_dt_s"] = crit;
      hc.outcomes.push_back(oc);
    }
    if (E == 1e3 || E == 1e6) {
      const FemRun r = run_fem(mesh, E, 0.3, 1, fem::Formulation::displacement, point, force);
      hc.outcomes.push_back(fem_outcome("FEM P1, ν = 0.3, E = " + fmt(E) + " Pa", r));
    }
  }
  return hc;
}

/// Moves one interior node towards the opposite face of one of its tets until that tet's
/// smallest dihedral angle is below 5°, keeping every tet positively oriented.
struct Sliver {
  TetMesh mesh;
  int node = -1;
  double min_dihedral_deg = 180.0;
};

Sliver make_sliver(const TetMesh& mesh, const Vec3& near) {
  std::set<int> boundary;
  for (const Triangle& t : mesh.triangles)
    for (int n : t) boundary.insert(n);
  std::vector<int> order;
  for (int i = 0; i < static_cast<int>(mesh.nodes.size()); ++i) {
    if (!boundary.count(i)) order.push_back(i);
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return (mesh.nodes[a] - near).squaredNorm() < (mesh.nodes[b] - near).squaredNorm();
  });
  std::vector<std::vector<int>> tets_of(mesh.nodes.size());
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    for (int n : mesh.tets[t]) tets_of[n].push_back(static_cast<int>(t));
  for (std::size_t k = 0; k < std::min<std::size_t>(order.size(), 50); ++k) {
    const int n = order[k];
    for (int t : tets_of[n]) {
      const Tet& tet = mesh.tets[t];
      std::vector<int> face;
      for (int v : tet)
        if (v != n) face.push_back(v);
      const Vec3 a = mesh.nodes[face[0]], b = mesh.nodes[face[1]], c = mesh.nodes[face[2]];
      const Vec3 normal = (b - a).cross(c - a).normalized();
      const double height = (mesh.nodes[n] - a).dot(normal);
      for (double f : {0.8, 0.9, 0.95, 0.97, 0.98, 0.99}) {
        Sliver s{mesh, n, 180.0};
        s.mesh.nodes[n] = mesh.nodes[n] - f * height * normal;
        bool valid = true;
        for (int u : tets_of[n]) {
          const Tet& q = s.mesh.tets[u];
          if (!(signed_volume(s.mesh.nodes[q[0]], s.mesh.nodes[q[1]], s.mesh.nodes[q[2]],
                              s.mesh.nodes[q[3]]) > 0))
            valid = false;
        }
        if (!valid) break;
        const Tet& q = s.mesh.tets[t];
        const auto ang = dihedral_angles_deg(s.mesh.nodes[q[0]], s.mesh.nodes[q[1]],
                                             s.mesh.nodes[q[2]], s.mesh.nodes[q[3]]);
        s.min_dihedral_deg = *std::min_element(ang.begin(), ang.end());
        if (s.min_dihedral_deg < 5.0) return s;
      }
    }
  }
  throw std::runtime_error("could not make a sliver tet near the contact point");
}

/// Predicted and found symplectic-Euler step of a volume model, as an outcome.
HardCaseOutcome step_outcome(const std::string& name, const Msm& m, int steps) {
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

HardCase case_sliver(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "sliver";
  hc.title = "Sliver tetrahedra (minimum dihedral angle below 5°)";
  VesselParams params;
  const TetMesh mesh = load_mesh(params, o);
  const Vec3 point = default_contact_point(params);
  const Sliver s = make_sliver(mesh, point + Vec3(0.5e-3, 0, 0));
  const MeshQuality q0 = compute_quality(mesh), q1 = compute_quality(s.mesh);
  hc.setup = "Straight tube level 0 with one interior node near the contact point moved towards "
             "the opposite face of one of its tets: minimum dihedral angle " +
             fmt(q0.dihedral_deg.min, 3) + "° → " + fmt(q1.dihedral_deg.min, 3) +
             "°, smallest tet volume " + fmt(q0.volume.min * 1e9, 3) + " → " +
             fmt(q1.volume.min * 1e9, 3) + " mm³, no tet inverted (" +
             std::to_string(q1.inverted) + "). Contact load 0.1 mN; clamped ends.";
  const int steps = o.quick ? 300 : 1000;
  for (const auto* m : {&mesh, &s.mesh}) {
    const std::string tag = m == &mesh ? " (regular mesh)" : " (sliver mesh)";
    log << "  " << tag << std::endl;
    for (msm::StiffnessRule rule : {msm::StiffnessRule::seed001, msm::StiffnessRule::van_gelder}) {
      const ModelSpec spec{"volume", rule};
      const auto model = make_msm(*m, params, spec, 14.24e3, 0.25, 1e-4, point);
      hc.outcomes.push_back(step_outcome(spec.name() + tag, *model, steps));
      hc.outcomes.push_back(static_outcome(spec.name() + tag, *model));
    }
    for (int degree : {1, 2}) {
      hc.outcomes.push_back(fem_outcome(
          "FEM P" + std::to_string(degree) + tag,
          run_fem(*m, 14.24e3, 0.3, degree, fem::Formulation::displacement, point, 1e-4)));
    }
  }
  return hc;
}

HardCase case_refined_patch(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "refined_patch";
  hc.title = "A finely refined contact patch";
  VesselParams params;
  const Vec3 point = default_contact_point(params);
  const double fine = o.quick ? 0.1e-3 : 0.05e-3;
  const TetMesh coarse = load_mesh(params, o);
  const TetMesh mesh = refined_patch_mesh(params, point, fine, 0.5e-3);
  const MeshQuality q = compute_quality(mesh);
  hc.setup = "Straight tube meshed with gmsh (OpenCASCADE) at 1 mm, graded down to " +
             fmt(fine * 1e3) + " mm within 0.5 mm of the contact point: " +
             std::to_string(mesh.nodes.size()) + " nodes, " + std::to_string(mesh.tets.size()) +
             " tets (level 0: " + std::to_string(coarse.nodes.size()) +
             " nodes), shortest edge " + fmt(q.edge_length.min * 1e3, 3) +
             " mm, minimum dihedral " + fmt(q.dihedral_deg.min, 3) +
             "°. Contact load 0.1 mN on the 0.5 mm patch; clamped ends.";
  const int steps = o.quick ? 300 : 1000;
  for (const auto* m : {&coarse, &mesh}) {
    const std::string tag = m == &coarse ? " (level 0)" : " (refined patch)";
    log << "  " << tag << std::endl;
    for (const ModelSpec& spec : {ModelSpec{"volume", msm::StiffnessRule::seed001},
                                  ModelSpec{"surface", msm::StiffnessRule::seed000}}) {
      const auto model = make_msm(*m, params, spec, 14.24e3, 0.25, 1e-4, point);
      hc.outcomes.push_back(step_outcome(spec.name() + tag, *model, steps));
      if (spec.model == "volume") hc.outcomes.push_back(static_outcome(spec.name() + tag, *model));
    }
    hc.outcomes.push_back(fem_outcome(
        "FEM P2" + tag,
        run_fem(*m, 14.24e3, 0.3, 2, fem::Formulation::displacement, point, 1e-4)));
  }
  return hc;
}

HardCase case_inverting_load(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "inverting_load";
  hc.title = "A large load that inverts elements";
  VesselParams params;
  const TetMesh mesh = load_mesh(params, o);
  const Vec3 point = default_contact_point(params);
  hc.setup = "Straight tube level 0, clamped ends, contact load on the 0.5 mm patch raised "
             "from 1 mN to 100 mN. After each solve the deformed volume mesh is checked for "
             "tets with non-positive signed volume (inverted): reported, not hidden.";
  const ModelSpec spec{"volume", msm::StiffnessRule::seed001};
  for (double force : {1e-3, 1e-2, 1e-1}) {
    log << "  " << force * 1e3 << " mN" << std::endl;
    const auto m = make_msm(mesh, params, spec, 14.24e3, 0.25, force, point);
    Eigen::VectorXd x;
    HardCaseOutcome oc =
        static_outcome(spec.name() + ", static, " + fmt(force * 1e3) + " mN", *m, &x);
    if (oc.finished) {
      const std::size_t inv = inverted_tets(mesh, unflatten(x));
      oc.reported += "; " + std::to_string(inv) + " inverted tets in the deformed mesh" +
                     (inv ? " (result not physical)" : "");
      oc.values["inverted_tets"] = static_cast<double>(inv);
    }
    hc.outcomes.push_back(oc);
    // Dynamic: the load applied suddenly, symplectic Euler at half the predicted step.
    const double dt = 0.5 * msm::predicted_critical_step(
                                Integrator::symplectic_euler,
                                msm::analyse_spectrum(m->problem, {.lowest = false}));
    Eigen::VectorXd xd;
    HardCaseOutcome od = dynamic_outcome(
        spec.name() + ", symplectic Euler, " + fmt(force * 1e3) + " mN", m->problem,
        Integrator::symplectic_euler, dt, o.quick ? 2000 : 10000, {}, &xd);
    if (od.finished) {
      const std::size_t inv = inverted_tets(mesh, unflatten(xd));
      od.reported += "; " + std::to_string(inv) + " inverted tets at the end";
      od.values["inverted_tets"] = static_cast<double>(inv);
    }
    hc.outcomes.push_back(od);
    const FemRun r = run_fem(mesh, 14.24e3, 0.3, 1, fem::Formulation::displacement, point, force);
    HardCaseOutcome of = fem_outcome("FEM P1 (linear), " + fmt(force * 1e3) + " mN", r);
    if (r.ok) {
      std::vector<Vec3> deformed = mesh.nodes;
      for (std::size_t i = 0; i < deformed.size(); ++i) deformed[i] += r.u[i];
      const std::size_t inv = inverted_tets(mesh, deformed);
      of.reported += "; " + std::to_string(inv) + " inverted tets in the deformed mesh" +
                     (r.max_strain > 0.05 ? "; strain beyond 5 %: outside the linear reference's "
                                            "validity"
                                          : "");
      of.values["inverted_tets"] = static_cast<double>(inv);
    }
    hc.outcomes.push_back(of);
  }
  return hc;
}

HardCase case_long_run(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "long_run";
  hc.title = "A long run";
  const long long steps = o.long_run_steps > 0 ? o.long_run_steps : (o.quick ? 20000 : 1000000);
  // The smallest mesh that is still the vessel: a 10 mm segment of the default tube (same
  // cross-section and cells, so the same ω_max and step) at structured level 0, 6 rings of 24
  // nodes on the inner wall. On the full 40 mm tube (552 nodes) a step costs ~4× more and the three
  // 10⁶-step runs took ~3 min (measured); on the segment they take under a minute.
  VesselParams params;
  params.style = MeshStyle::structured;
  params.length = 10e-3;
  const TetMesh mesh = load_mesh(params, o);
  const ModelSpec spec{"surface", msm::StiffnessRule::seed000};
  const auto base = make_msm(mesh, params, spec, 14.24e3, 0.25, 0.0, Vec3::Zero());
  const msm::Spectrum s0 = msm::analyse_spectrum(base->problem, {.lowest = false});
  const long long early = std::max<long long>(steps / 10, 1);
  hc.setup = "The smallest model: seed 000's grid surface model on a 10 mm segment of the "
             "structured level-0 tube (" +
             std::to_string(base->built.network.nodes.size()) + " nodes, " +
             std::to_string(base->built.network.springs.size()) + " springs), ends fixed, no "
             "load, started from a random velocity (strain ~1e-4); " + std::to_string(steps) +
             " steps at 0.9 × each integrator's predicted critical step" +
             (o.quick ? " (quick mode: scaled down from 10⁶)" : "") +
             "; energy H = ½vᵀMv + E(x) sampled every 100 steps. Bounded: no blow-up and the "
             "largest H/H₀ over the whole run at most 1.5 × the largest over its first 10 % (" +
             std::to_string(early) + " steps). H oscillates from the start without growing: "
             "on a linear mode symplectic Euler and Verlet conserve a modified energy exactly, "
             "and H/H₀ ≤ (1 + a)/(1 − a) (symplectic Euler) or 1/(1 − a²) (Verlet), a = hω/2 "
             "(19 and 5.3 at a = 0.9); energy that grows with time fails the test.";
  // Random velocity giving displacements of ~1e-4 of a spring.
  double mean_rest = 0.0;
  for (const auto& sp : base->built.network.springs) mean_rest += sp.rest_length;
  mean_rest /= static_cast<double>(base->built.network.springs.size());
  const Eigen::VectorXd v0 = msm::random_velocity(base->problem, 1e-4 * mean_rest * s0.omega_max, 11);
  struct Run {
    IntegratorConfig cfg;
    double fraction;
  };
  for (const Run& run : {Run{{Integrator::symplectic_euler, 0.0}, 0.9},
                         Run{{Integrator::verlet, 0.0}, 0.9},
                         Run{{Integrator::explicit_euler, 0.3}, 0.9},
                         Run{{Integrator::explicit_euler, 0.0}, 0.0}}) {
    const double c = 2.0 * run.cfg.zeta * s0.omega_max * mean_mass(base->problem);
    const auto m = with_damping(*base, c);
    const msm::Spectrum s = msm::analyse_spectrum(m->problem, {.lowest = c > 0});
    double dt = run.fraction * msm::predicted_critical_step(run.cfg.integrator, s);
    if (dt == 0.0) dt = 0.1 * 2.0 / s.omega_max;  // undamped explicit Euler: 0.1 × 2/ω_max
    const std::string name = msm::to_string(run.cfg.integrator) +
                             (c > 0 ? " (point damping, ζ " + fmt(run.cfg.zeta) + ")" : "");
    log << "  " << name << ": " << steps << " steps of " << fmt(dt) << " s" << std::endl;
    const double H0 = msm::total_energy(m->problem, m->problem.rest, v0);
    double hmax = H0, hmin = H0, hmax_early = H0;
    msm::DynamicOptions d;
    d.integrator = run.cfg.integrator;
    d.dt = dt;
    d.steps = static_cast<int>(steps);
    Stopwatch clock;
    d.on_step = [&](int step, const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
      if (step % 100 == 0) {
        const double h = msm::total_energy(m->problem, x, v);
        hmax = std::max(hmax, h);
        hmin = std::min(hmin, h);
        if (step <= early) hmax_early = hmax;
      }
      if (step % early == 0) {
        const double t = clock.seconds();
        log << "    step " << step << " / " << steps << ", H/H0 " << fmt(hmax / H0) << " max, "
            << fmt(t, 3) << " s, ~" << fmt(t / step * static_cast<double>(steps - step), 2)
            << " s to go" << std::endl;
      }
    };
    HardCaseOutcome oc;
    oc.model = spec.name() + ", " + name;
    oc.values["dt_s"] = dt;
    oc.values["steps"] = static_cast<double>(steps);
    try {
      const msm::DynamicResult r = msm::integrate(m->problem, d, m->problem.rest, v0);
      const double secs = clock.seconds();
      oc.finished = true;
      oc.bounded = hmax <= 1.5 * hmax_early;
      oc.reported = std::to_string(steps) + " steps of " + fmt(dt) + " s (" +
                    fmt(dt * s.omega_max / 2.0, 3) + " × 2/ω_max): H/H₀ max " + fmt(hmax / H0) +
                    " over the run (" + fmt(hmax_early / H0) + " over its first 10 %), min " +
                    fmt(hmin / H0) + ", final " + fmt(r.energy / H0) + " (" + fmt(secs, 3) +
                    " s, " + fmt(1e6 * secs / static_cast<double>(steps), 3) + " µs per step)";
      oc.values["energy_max_over_initial"] = hmax / H0;
      oc.values["energy_max_first_tenth_over_initial"] = hmax_early / H0;
      oc.values["energy_final_over_initial"] = r.energy / H0;
      oc.values["seconds"] = secs;
    } catch (const msm::DivergenceError& e) {
      oc.finished = false;
      oc.bounded = false;
      oc.reported = "stopped: " + short_error(e.what());
      oc.values["diverged_at_step"] = e.step;
    }
    hc.outcomes.push_back(oc);
  }
  return hc;
}

HardCase case_tight_bend(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "tight_bend";
  hc.title = "The tight bend of the arch";
  hc.setup = "180° arch, level 0, bend radius 15 mm (default), 6 mm and 4.5 mm (the wall's "
             "outer radius is 4 mm), contact load 0.1 mN on a 1 mm patch (level 0's triangles "
             "are too coarse for 0.5 mm) at mid-arch on the outer side of the bend, clamped "
             "ends.";
  const int steps = o.quick ? 300 : 1000;
  for (double R : {15e-3, 6e-3, 4.5e-3}) {
    log << "  R = " << R * 1e3 << " mm" << std::endl;
    VesselParams params;
    params.kind = VesselKind::arch;
    params.bend_radius = R;
    const std::string tag = ", R = " + fmt(R * 1e3) + " mm";
    TetMesh mesh;
    try {
      mesh = load_mesh(params, o);
    } catch (const std::exception& e) {
      hc.outcomes.push_back({"gmsh" + tag, false, {}, {}, "meshing failed: " + short_error(e.what()), {}});
      continue;
    }
    const MeshQuality q = compute_quality(mesh);
    hc.outcomes.push_back({"mesh" + tag, true, {}, {},
                           std::to_string(mesh.nodes.size()) + " nodes, minimum dihedral " +
                               fmt(q.dihedral_deg.min, 3) + "°, shortest edge " +
                               fmt(q.edge_length.min * 1e3, 3) + " mm",
                           {{"min_dihedral_deg", q.dihedral_deg.min}}});
    const Vec3 point = default_contact_point(params);
    const ModelSpec spec{"volume", msm::StiffnessRule::seed001};
    const auto m = make_msm(mesh, params, spec, 14.24e3, 0.25, 1e-4, point, 1e-3);
    hc.outcomes.push_back(step_outcome(spec.name() + tag, *m, steps));
    hc.outcomes.push_back(static_outcome(spec.name() + tag, *m));
    hc.outcomes.push_back(fem_outcome(
        "FEM P2" + tag,
        run_fem(mesh, 14.24e3, 0.3, 2, fem::Formulation::displacement, point, 1e-4, 1e-3)));
  }
  return hc;
}

HardCase case_zero_length(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "zero_length";
  hc.title = "Springs with zero rest length, coincident nodes";
  hc.setup = "(1) The level-0 volume model (seed001) plus one extra node coincident with a free "
             "node near the contact point, tied to it by a zero-rest-length spring of the mean "
             "stiffness; (2) the level-0 mesh with one interior node moved onto a neighbour "
             "(coincident nodes, zero-volume tets): a .msh file like it is refused by the "
             "reader (inverted or zero-volume tets, exit 1); the models are run on it here "
             "anyway to show why. Contact load 0.1 mN, clamped ends.";
  VesselParams params;
  const TetMesh mesh = load_mesh(params, o);
  const Vec3 point = default_contact_point(params);
  const ModelSpec spec{"volume", msm::StiffnessRule::seed001};
  log << "  zero-length spring" << std::endl;
  {
    auto m = make_msm(mesh, params, spec, 14.24e3, 0.25, 1e-4, point);
    msm::SpringNetwork net = m->built.network;
    const int j = m->contact_node;
    double kmean = 0.0;
    for (const auto& sp : net.springs) kmean += sp.law.k1;
    kmean /= static_cast<double>(net.springs.size());
    net.nodes.push_back(net.nodes[j]);
    net.source_node.push_back(-1);
    msm::Spring z;
    z.a = j;
    z.b = static_cast<int>(net.nodes.size()) - 1;
    z.rest_length = 0.0;
    z.law = {kmean, kmean};
    net.springs.push_back(z);
    const msm::SpringModel model(net);
    msm::Problem p = m->problem;
    p.form = &model;
    const Eigen::Index n = p.rest.size();
    p.rest.conservativeResize(n + 3);
    p.rest.tail<3>() = net.nodes.back();
    p.mass.conservativeResize(n + 3);
    p.mass.tail<3>().setConstant(p.mass[3 * j]);
    p.external_force.conservativeResize(n + 3);
    p.external_force.tail<3>().setZero();
    p.fixed.resize(static_cast<std::size_t>(n + 3), 0);
    HardCaseOutcome sp;
    sp.model = "volume / seed001 + zero-length spring: spectrum";
    try {
      const msm::Spectrum s = msm::analyse_spectrum(p);
      sp.finished = true;
      // ½kL² has the Hessian k[I −I; −I I] at zero length; a kernel that returned zero there
      // would leave the extra node without stiffness (ω_min = 0).
      sp.reported = "ω_max " + fmt(s.omega_max) + " rad/s, ω_min " + fmt(s.omega_min) + " rad/s" +
                    (s.omega_min > 0.0 ? " (the zero-length spring's Hessian k[I −I; −I I] holds "
                                         "the extra node)"
                                       : " (0: the extra node has no stiffness at rest)");
      sp.values["omega_min"] = s.omega_min;
    } catch (const std::exception& e) {
      sp.reported = "failed: " + short_error(e.what());
    }
    hc.outcomes.push_back(sp);
    Msm tmp;
    tmp.problem = p;
    tmp.contact_node = j;
    tmp.model = std::make_unique<msm::SpringModel>(net);
    tmp.problem.form = tmp.model.get();
    hc.outcomes.push_back(static_outcome("volume / seed001 + zero-length spring: static", tmp));
    const double dt = 0.5 * msm::predicted_critical_step(
                                Integrator::symplectic_euler,
                                msm::analyse_spectrum(m->problem, {.lowest = false}));
    hc.outcomes.push_back(dynamic_outcome("volume / seed001 + zero-length spring: symplectic Euler",
                                          tmp.problem, Integrator::symplectic_euler, dt, 2000));
  }
  log << "  coincident nodes" << std::endl;
  {
    // The tet nearest the contact point: its first node is moved onto its second.
    int a = -1, b = -1;
    double best = std::numeric_limits<double>::infinity();
    for (const Tet& t : mesh.tets) {
      const double d = (mesh.nodes[t[0]] - point).squaredNorm();
      if (d < best) {
        best = d;
        a = t[0];
        b = t[1];
      }
    }
    TetMesh bad = mesh;
    if (a >= 0) bad.nodes[a] = bad.nodes[b];
    const MeshQuality q = compute_quality(bad);
    hc.outcomes.push_back({"mesh quality", true, {}, {},
                           std::to_string(q.degenerate) + " zero-volume and " +
                               std::to_string(q.inverted) + " inverted tets reported",
                           {{"degenerate_tets", static_cast<double>(q.degenerate)}}});
    // The same mesh as a user's .msh file: the reader's volume check (require_positive_volumes)
    // refuses it before any model sees it. The rows below show what happens without that check.
    try {
      require_positive_volumes(bad, "coincident-node mesh");
      hc.outcomes.push_back({"reading it as a user .msh", true, {}, {}, "accepted", {}});
    } catch (const InputError& e) {
      hc.outcomes.push_back({"reading it as a user .msh", false, {}, {},
                             "refused: " + short_error(e.what()), {}});
    }
    for (msm::StiffnessRule rule : {msm::StiffnessRule::seed001, msm::StiffnessRule::van_gelder}) {
      const ModelSpec sp{"volume", rule};
      try {
        const auto m = make_msm(bad, params, sp, 14.24e3, 0.25, 1e-4, point);
        std::size_t bad_k = 0;
        for (const auto& s : m->built.network.springs) {
          if (!std::isfinite(s.law.k1)) ++bad_k;
        }
        HardCaseOutcome oc = static_outcome(sp.name() + ", coincident nodes", *m);
        oc.reported = std::to_string(bad_k) + " springs with non-finite k; " + oc.reported;
        hc.outcomes.push_back(oc);
      } catch (const std::exception& e) {
        hc.outcomes.push_back({sp.name() + ", coincident nodes", false, false, {},
                               "refused: " + short_error(e.what()), {}});
      }
    }
    hc.outcomes.push_back(fem_outcome(
        "FEM P1, coincident nodes",
        run_fem(bad, 14.24e3, 0.3, 1, fem::Formulation::displacement, point, 1e-4)));
  }
  return hc;
}

std::string yes_no(const std::optional<bool>& b) {
  if (!b) return "–";
  return *b ? "yes" : "**no**";
}

}  // namespace

double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<std::pair<double, double>> p;
  for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i) {
    if (x[i] > 0 && y[i] > 0 && std::isfinite(x[i]) && std::isfinite(y[i]))
      p.emplace_back(std::log(x[i]), std::log(y[i]));
  }
  if (p.size() < 2) throw InputError("loglog_slope: expected at least two positive pairs");
  double mx = 0, my = 0;
  for (auto [a, b] : p) {
    mx += a;
    my += b;
  }
  mx /= static_cast<double>(p.size());
  my /= static_cast<double>(p.size());
  double sxy = 0, sxx = 0;
  for (auto [a, b] : p) {
    sxy += (a - mx) * (b - my);
    sxx += (a - mx) * (a - mx);
  }
  if (!(sxx > 0)) throw InputError("loglog_slope: expected at least two distinct x values");
  return sxy / sxx;
}

StabilityReport run_stability(const StabilityOptions& o) {
  std::ostream& log = o.log ? *o.log : null_stream();
  Stopwatch clock;
  StabilityReport rep;
  rep.quick = o.quick;
  rep.command_line = o.command_line;
  rep.trial_steps = o.trial_steps > 0 ? o.trial_steps : (o.quick ? 500 : 1000);
  const int max_level = o.max_level >= 0 ? o.max_level : (o.quick ? 1 : 2);
  for (const auto& id : o.only_cases) {
    if (std::find(kHardCaseIds.begin(), kHardCaseIds.end(), id) == kHardCaseIds.end()) {
      std::string known;
      for (const auto k : kHardCaseIds) known += (known.empty() ? "" : ", ") + std::string(k);
      throw InputError("--hard-case: unknown case '" + id + "'; expected one of " + known);
    }
  }
  if (max_level > kMaxMeshLevel) {
    throw InputError("--max-level: expected 0.." + std::to_string(kMaxMeshLevel) + ", got " +
                     std::to_string(max_level));
  }
  log << "[stability] critical steps, levels 0.." << max_level << ", " << rep.trial_steps
      << " steps per trial" << std::endl;
  rep.rows = critical_step_table(o, max_level, rep.trial_steps, log);
  rep.fits = refinement_fits(rep.rows);
  if (o.hard_cases) {
    using CaseFn = HardCase (*)(const StabilityOptions&, std::ostream&);
    const std::pair<const char*, CaseFn> all_cases[] = {
        {"ν → 0.5", case_poisson},          {"E sweep", case_youngs_modulus},
        {"sliver tets", case_sliver},       {"refined contact patch", case_refined_patch},
        {"inverting load", case_inverting_load}, {"long run", case_long_run},
        {"tight bend", case_tight_bend},    {"zero-length springs", case_zero_length}};
    static_assert(std::size(all_cases) == kHardCaseIds.size());
    std::vector<std::pair<const char*, CaseFn>> cases;
    for (std::size_t i = 0; i < kHardCaseIds.size(); ++i) {
      if (o.only_cases.empty() || std::find(o.only_cases.begin(), o.only_cases.end(),
                                            kHardCaseIds[i]) != o.only_cases.end()) {
        cases.push_back(all_cases[i]);
      }
    }
    std::size_t k = 0;
    for (const auto& [what, fn] : cases) {
      ++k;
      log << "[stability] hard case " << k << "/" << std::size(cases) << ": " << what << " ("
          << fmt(clock.seconds(), 3) << " s so far)" << std::endl;
      Stopwatch c;
      HardCase hc;
      try {
        hc = fn(o, log);
      } catch (const std::exception& e) {
        // A case that cannot even be set up is recorded, not allowed to stop the study.
        hc.id = "case_" + std::to_string(k);
        hc.title = what;
        hc.setup = "the case could not be set up";
        hc.outcomes.push_back({"setup", false, {}, {}, "failed: " + short_error(e.what()), {}});
        log << "  failed: " << e.what() << std::endl;
      }
      hc.seconds = c.seconds();
      rep.hard_cases.push_back(std::move(hc));
    }
  }
  rep.seconds = clock.seconds();
  log << "[stability] done in " << fmt(rep.seconds, 3) << " s" << std::endl;
  return rep;
}

std::string stability_json(const StabilityReport& r) {
  nlohmann::json j;
  j["schema"] = "vesselverify.stability";
  j["schema_version"] = 1;
  j["command"] = r.command_line;
  j["quick"] = r.quick;
  j["units"] = {{"time", "s"}, {"length", "m"}, {"angular_frequency", "rad/s"},
                {"damping", "N·s/m"}, {"values", "SI unless the key ends in _mm"}};
  j["steps_per_trial"] = r.trial_steps;
  j["critical_steps"] = nlohmann::json::array();
  for (const auto& row : r.rows) {
    j["critical_steps"].push_back({{"model", row.model},
                                   {"integrator", row.integrator},
                                   {"zeta", row.zeta},
                                   {"point_damping", row.point_damping},
                                   {"level", row.level},
                                   {"nodes", row.nodes},
                                   {"springs", row.springs},
                                   {"h_nominal", row.h_nominal},
                                   {"omega_max", row.omega_max},
                                   {"omega_gershgorin", row.omega_gershgorin},
                                   {"omega_min", row.omega_min},
                                   {"gamma_max", row.gamma_max},
                                   {"predicted_dt", row.predicted_dt},
                                   {"found_dt", row.found_dt},
                                   {"unstable_dt", row.unstable_dt},
                                   {"found_over_predicted", row.found_dt / row.predicted_dt},
                                   {"guaranteed_dt", std::isfinite(row.guaranteed_dt)
                                                         ? nlohmann::json(row.guaranteed_dt)
                                                         : nlohmann::json()},
                                   {"found_over_guaranteed",
                                    std::isfinite(row.guaranteed_dt) && row.guaranteed_dt > 0
                                        ? nlohmann::json(row.found_dt / row.guaranteed_dt)
                                        : nlohmann::json()},
                                   {"trials", row.trials},
                                   {"seconds", row.seconds}});
  }
  j["refinement"] = nlohmann::json::array();
  for (const auto& f : r.fits) {
    j["refinement"].push_back({{"model", f.model},
                               {"integrator", f.integrator},
                               {"zeta", f.zeta},
                               {"levels", f.levels},
                               {"found_exponent", f.exponent},
                               {"predicted_exponent", f.predicted_exponent}});
  }
  j["hard_cases"] = nlohmann::json::array();
  for (const auto& hc : r.hard_cases) {
    nlohmann::json c{{"id", hc.id}, {"title", hc.title}, {"setup", hc.setup},
                     {"seconds", hc.seconds}, {"outcomes", nlohmann::json::array()}};
    for (const auto& oc : hc.outcomes) {
      nlohmann::json v = nlohmann::json::object();
      for (const auto& [k, x] : oc.values) v[k] = std::isfinite(x) ? nlohmann::json(x) : nlohmann::json();
      c["outcomes"].push_back({{"model", oc.model},
                               {"finished", oc.finished},
                               {"converged", oc.converged ? nlohmann::json(*oc.converged)
                                                          : nlohmann::json()},
                               {"bounded", oc.bounded ? nlohmann::json(*oc.bounded)
                                                      : nlohmann::json()},
                               {"reported", oc.reported},
                               {"values", v}});
    }
    j["hard_cases"].push_back(c);
  }
  j["total_seconds"] = r.seconds;
  return j.dump(2) + "\n";
}

std::string stability_markdown(const StabilityReport& r) {
  std::ostringstream md;
  md << "## Numerical stability\n\n"
     << "How large a time step each explicit integrator of the mass-spring models takes before "
        "it blows up — predicted from the largest eigenvalue of M⁻¹K at rest (Lanczos) and found "
        "by running (bisection on dt, " << r.trial_steps
     << " steps per trial from a small random velocity, unstable when the energy exceeds "
        "1000× its start or turns non-finite) — and what every model does on hard cases. "
        "Produced by `" << r.command_line << "`" << (r.quick ? " (quick mode)" : "")
     << " in " << fmt(r.seconds, 3) << " s.\n\n"
     << "### Predicted vs found stable step\n\n"
     << "Straight tube, unstructured levels; surface models on the inner wall (triangle "
        "topology), E = 14.24 kPa, consistent masses, inlet and outlet fixed. Damped rows: point "
        "damping c = 2ζ·ω_max·(mean nodal mass), seed 000 eq. (3.3). Predicted: symplectic "
        "Euler 4/(γ + √(γ² + 4ω²)), Verlet the root of its amplification matrix's Jury "
        "condition (2/ω undamped), explicit Euler γ/ω² (= 2ζ/ω) or its overdamped lowest-mode "
        "bound, with γ the damping rate of the top (and lowest) mode. Undamped, the prediction "
        "is exact. **Damped, it is an estimate that may be unsafe**: point damping with "
        "non-uniform (consistent) masses does not decouple into modes, γ is only a Rayleigh "
        "quotient, and the found step can be well below it (found / predicted < 1). The "
        "*guaranteed* column is a proven bound instead: every eigenvalue of the damped system "
        "solves λ² + γλ + ω² = 0 for some ω ∈ [ω_min, ω_max] and γ between the extreme "
        "eigenvalues of M⁻¹C (here c/m_max and c/m_min), so the smallest critical step over "
        "that rectangle is safe for explicit and symplectic Euler "
        "(`msm/stability/critical_step.hpp`; none is proven for damped Verlet). Use it, not the "
        "prediction, as a safe damped step. Steps in µs.\n\n"
     << "| model | integrator | ζ | level | nodes | ω_max (rad/s) | Gershgorin bound | predicted "
        "(µs) | guaranteed (µs) | found stable (µs) | found / predicted | found / guaranteed |\n"
     << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& row : r.rows) {
    md << "| " << row.model << " | " << row.integrator << " | " << fmt(row.zeta) << " | "
       << row.level << " | " << row.nodes << " | " << fmt(row.omega_max, 5) << " | "
       << fmt(row.omega_gershgorin, 5) << " | " << fmt(row.predicted_dt * 1e6, 5) << " | "
       << (std::isfinite(row.guaranteed_dt) ? fmt(row.guaranteed_dt * 1e6, 5) : "–") << " | "
       << fmt(row.found_dt * 1e6, 5) << " | " << fmt(row.found_dt / row.predicted_dt, 4)
       << " | "
       << (std::isfinite(row.guaranteed_dt) && row.guaranteed_dt > 0
               ? fmt(row.found_dt / row.guaranteed_dt, 4)
               : "–")
       << " |\n";
  }
  md << "\nExplicit Euler without damping is not in the table: it is unstable at every step "
        "(|1 + ihω| > 1; the energy grows by a factor 1 + h²ω² per step in each mode), asserted "
        "by the test suite.\n\n"
     << "### Step against refinement\n\n"
     << "Least-squares exponent p of dt ∝ h^p over the levels (h the nominal element size, "
        "halved per level; p = 1 expected for springs whose k scales like E·h and masses like "
        "ρh³).\n\n"
     << "| model | integrator | ζ | levels | p (found) | p (predicted) |\n"
     << "| --- | --- | --- | --- | --- | --- |\n";
  for (const auto& f : r.fits) {
    std::string levels;
    for (int l : f.levels) {
      if (!levels.empty()) levels += ",";
      levels += std::to_string(l);
    }
    md << "| " << f.model << " | " << f.integrator << " | " << fmt(f.zeta) << " | " << levels
       << " | " << fmt(f.exponent, 3) << " | " << fmt(f.predicted_exponent, 3) << " |\n";
  }
  if (!r.hard_cases.empty()) {
    md << "\n### Hard cases\n\n"
       << "Each case lists what every model did: finished (returned a result), converged "
          "(static or linear solve), bounded (dynamic run), and what it reported. Displacements "
          "in mm, loads in mN.\n";
    for (const auto& hc : r.hard_cases) {
      md << "\n#### " << hc.title << "\n\n" << hc.setup << " (" << fmt(hc.seconds, 3) << " s)\n\n"
         << "| model | finished | converged | bounded | reported |\n"
         << "| --- | --- | --- | --- | --- |\n";
      for (const auto& oc : hc.outcomes) {
        std::string rep = oc.reported;
        for (std::size_t p = rep.find('|'); p != std::string::npos; p = rep.find('|', p + 2))
          rep.replace(p, 1, "\\|");
        for (char& ch : rep)
          if (ch == '\n') ch = ' ';
        md << "| " << oc.model << " | " << (oc.finished ? "yes" : "**no**") << " | "
           << yes_no(oc.converged) << " | " << yes_no(oc.bounded) << " | " << rep << " |\n";
      }
    }
  }
  return md.str();
}

void write_stability(const std::filesystem::path& dir, const StabilityReport& report) {
  const std::string json = stability_json(report);
  const std::string md = stability_markdown(report);
  write_file_atomically(dir / "stability.json", [&](std::ostream& out) { out << json; });
  write_file_atomically(dir / "stability.md", [&](std::ostream& out) { out << md; });
}

}  // namespace vessel
