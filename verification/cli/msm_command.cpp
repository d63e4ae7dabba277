/// `vesselverify msm`: build a surface or volume mass-spring model on a vessel mesh, load it with
/// the shared contact patch, solve statically or dynamically, print and optionally write results.
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "meshes/atomic_file.hpp"
#include "meshes/errors.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/model/build_network.hpp"
#include "msm/model/spring_model.hpp"
#include "msm/pbd/constraints.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/solvers/static_solver.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "msm/topology/springs.hpp"
#include "verification/cli/commands.hpp"
#include "verification/cli/vessel_options.hpp"

namespace vessel::cli {

namespace fs = std::filesystem;

namespace {

struct MsmOptions {
  VesselOptions vessel;
  std::string model = "surface";
  std::string surface = "inner";
  std::string topology = "auto";
  bool two_ring = false;
  std::string stiffness = "seed000";
  msm::StiffnessParams stiffness_params;
  std::string mass = "consistent";
  double density = msm::kVesselDensity;
  std::string solver = "static";
  double dt = 0.0;  ///< 0: automatic
  int steps = 1000;
  double point_damping = 0.0;
  double axial_damping = 0.0;
  double force = 1e-3;
  std::vector<double> contact_point;
  double patch_radius = 0.5e-3;
  std::vector<std::string> fixed_groups{"inlet", "outlet"};
  fs::path json;
  bool verbose = false;
  int pbd_iterations = 10;
  double bending_compliance = 0.0;
  bool angle_constraints = false;
  bool no_dihedral = false;
  double pbd_damping = 0.01;
  double pressure = 0.0;
  bool gravity = false;
  int load_steps = 1;
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Default contact point: on the inner wall at mid-length, on the section's θ = 0 side.
Vec3 default_contact_point(const VesselParams& p) {
  if (p.kind == VesselKind::straight) return {p.inner_radius, 0.0, 0.5 * p.length};
  const double alpha = std::numbers::pi / 2;  // arch mid-length
  const Vec3 er(std::cos(alpha), std::sin(alpha), 0.0);
  return (p.bend_radius + p.inner_radius) * er;
}

void run(MsmOptions& o) {
  const auto t_total = std::chrono::steady_clock::now();
  std::cout << std::setprecision(6);
  if (o.model != "surface" && o.model != "volume") {
    throw InputError("--model: expected 'surface' or 'volume', got '" + o.model + "'");
  }
  const msm::StiffnessRule rule = msm::parse_stiffness_rule(o.stiffness);
  const msm::MassRule mass_rule = msm::parse_mass_rule(o.mass);
  msm::validate(o.stiffness_params);
  const bool is_static = o.solver == "static" || o.solver == "linear" || o.solver == "relaxation";
  msm::Integrator integrator = msm::Integrator::symplectic_euler;
  if (!is_static && o.solver != "pbd") integrator = msm::parse_integrator(o.solver);
  if (o.solver == "pbd" && o.model != "surface") {
    throw InputError(
        "--solver pbd: the position-based constraints of seed 002 are for the surface "
        "model (--model surface)");
  }
  if (o.dt < 0 || !std::isfinite(o.dt)) {
    throw InputError("--dt: expected a time step > 0 s (or 0 for automatic), got " +
                     std::to_string(o.dt));
  }
  if (o.steps < 1) throw InputError("--steps: expected ≥ 1, got " + std::to_string(o.steps));
  if (!(o.force >= 0) || !std::isfinite(o.force)) {
    throw InputError("--force: expected a finite value ≥ 0 N, got " + std::to_string(o.force));
  }
  if (!o.contact_point.empty() && o.contact_point.size() != 3) {
    throw InputError("--contact-point: expected three coordinates x y z in metres");
  }

  const TetMesh mesh = mesh_vessel(o.vessel, std::cout);
  std::cout << std::defaultfloat << std::setprecision(6);
  const VesselParams& params = o.vessel.params;
  // Shared load definition: the same patch and consistent nodal loads the FEM gets.
  ContactPatchSpec spec;
  spec.point = o.contact_point.empty()
                   ? default_contact_point(params)
                   : Vec3(o.contact_point[0], o.contact_point[1], o.contact_point[2]);
  spec.radius = o.patch_radius;
  spec.force = o.force;
  const TractionPatch patch = contact_patch(mesh, spec);
  std::vector<Vec3> loads = traction_nodal_loads(mesh, patch);
  if (o.pressure != 0.0) {
    if (!std::isfinite(o.pressure)) throw InputError("--pressure: expected a finite value in Pa");
    // Shared definition: −p n A/3 per inner-wall triangle node, the FEM's consistent load.
    const auto pl = pressure_nodal_loads(mesh, std::string(group_names::inner_wall), o.pressure);
    for (std::size_t i = 0; i < loads.size(); ++i) loads[i] += pl[i];
  }

  const auto t_build = std::chrono::steady_clock::now();
  msm::NetworkOptions network_options;
  network_options.model = o.model;
  network_options.surface = o.surface;
  network_options.topology = o.topology;
  network_options.two_ring = o.two_ring;
  network_options.stiffness = rule;
  network_options.stiffness_params = o.stiffness_params;
  network_options.mass = mass_rule;
  network_options.density = o.density;
  network_options.axial_damping = o.axial_damping;
  msm::BuiltNetwork built = msm::build_network(mesh, params, network_options);
  const msm::SpringNetwork& net = built.network;
  const std::string& topology = built.topology;
  const std::vector<double>& masses = built.masses;
  const msm::SpringModel model(net, o.point_damping);
  msm::Problem problem = msm::make_problem(model, net, masses, mesh, loads, o.fixed_groups);
  if (o.gravity) {
    // Gravity −9.81 m/s² along y on the nodal masses: for the volume model with consistent masses
    // this is exactly the shared body_force_nodal_loads (ρV/4 per tet vertex); a surface model
    // carries its own (shell) mass ρ·t·A/3 per triangle vertex.
    for (Eigen::Index i = 0; i < problem.num_dofs(); i += 3) {
      problem.external_force[i + 1] -= 9.81 * problem.mass[i];
    }
  }
  const double build_seconds = seconds_since(t_build);

  std::cout << "model: " << o.model << (o.model == "surface" ? " (" + o.surface + " wall)" : "")
            << ", " << topology << ", " << net.nodes.size() << " nodes\n";
  nlohmann::json counts = nlohmann::json::object();
  std::cout << "springs:";
  for (msm::SpringFamily f : msm::kAllFamilies) {
    const std::size_t c = net.count(f);
    if (c == 0) continue;
    counts[msm::to_string(f)] = c;
    std::cout << " " << msm::to_string(f) << " " << c;
  }
  std::cout << " (total " << net.springs.size() << ")\n";
  double kmin = std::numeric_limits<double>::infinity(), kmax = 0.0;
  for (const auto& s : net.springs) {
    kmin = std::min(kmin, s.law.k1);
    kmax = std::max(kmax, s.law.k1);
  }
  double total_mass = problem.mass.sum() / 3.0;
  std::cout << "stiffness rule " << msm::to_string(rule) << ": k from " << kmin << " to " << kmax
            << " N/m; mass rule " << msm::to_string(mass_rule) << ": total " << total_mass * 1e3
            << " g\n";
  std::cout << "contact: " << o.force * 1e3 << " mN over " << patch.triangles.size()
            << " triangles (" << patch.area * 1e6 << " mm²) at (" << spec.point.x() * 1e3 << ", "
            << spec.point.y() * 1e3 << ", " << spec.point.z() * 1e3 << ") mm\n";

  nlohmann::json result{{"schema", "vesselverify.msm_result"},
                        {"schema_version", 1},
                        {"units", {{"length", "mm"}, {"time", "s"}, {"force", "mN"}}},
                        {"vessel", describe(params)},
                        {"model", o.model},
                        {"topology", topology},
                        {"stiffness_rule", msm::to_string(rule)},
                        {"mass_rule", msm::to_string(mass_rule)},
                        {"nodes", net.nodes.size()},
                        {"springs", counts},
                        {"force_mN", o.force * 1e3},
                        {"build_seconds", build_seconds}};
  if (o.model == "surface") result["surface"] = o.surface;

  Eigen::VectorXd x;
  if (o.solver == "static" || o.solver == "linear") {
    msm::StaticOptions static_options;
    if (o.verbose) static_options.log = &std::cout;
    static_options.load_steps = o.load_steps;
    const msm::StaticResult r = o.solver == "static" ? msm::solve_static(problem, static_options)
                                                     : msm::solve_linear(problem);
    x = r.x;
    std::cout << (o.solver == "static" ? "static Newton" : "linearised model") << ": "
              << r.iterations << " iteration(s), residual " << r.residual << " N, "
              << std::setprecision(4) << r.seconds << " s per static solve (" << r.symbolic_analyses
              << " symbolic, " << r.numeric_factorisations << " numeric CHOLMOD factorisations)\n"
              << std::setprecision(6);
    result["solver"] = {{"name", o.solver},
                        {"iterations", r.iterations},
                        {"residual_N", r.residual},
                        {"seconds", r.seconds}};
  } else if (o.solver == "relaxation") {
    const msm::RelaxationResult r = msm::dynamic_relaxation(problem);
    x = r.x;
    std::cout << "dynamic relaxation: " << r.steps << " steps of " << r.dt << " s, residual "
              << r.residual << " N, " << r.seconds << " s (" << r.seconds / r.steps * 1e6
              << " µs per step)\n";
    result["solver"] = {{"name", o.solver},
                        {"steps", r.steps},
                        {"dt", r.dt},
                        {"residual_N", r.residual},
                        {"seconds", r.seconds}};
  } else if (o.solver == "pbd") {
    // Seed 002: stretching (compliance 1/k of each structural spring), dihedral bending and,
    // optionally, the simplified angle constraint, solved with XPBD.
    std::vector<Vec3> net_loads(net.nodes.size(), Vec3::Zero());
    for (std::size_t i = 0; i < net.nodes.size(); ++i) {
      net_loads[i] = problem.external_force.segment<3>(3 * static_cast<Eigen::Index>(i));
    }
    msm::PbdConstraintOptions co;
    co.dihedral = !o.no_dihedral;
    co.angle = o.angle_constraints;
    co.bending_compliance = o.bending_compliance;
    co.angle_compliance = o.bending_compliance;
    const auto constraints = msm::build_pbd_constraints(net, net_loads, co);
    std::size_t counts_by_type[3] = {0, 0, 0};
    for (const auto& c : constraints) ++counts_by_type[static_cast<int>(c.type)];
    msm::PbdOptions po;
    po.dt = o.dt > 0 ? o.dt : 1e-3;
    po.steps = o.steps;
    po.iterations = o.pbd_iterations;
    po.velocity_damping = o.pbd_damping;
    std::cout << "XPBD: " << counts_by_type[0] << " stretching, " << counts_by_type[1]
              << " dihedral, " << counts_by_type[2] << " angle constraints; " << po.steps
              << " steps of " << po.dt << " s, " << po.iterations << " iterations each ...\n";
    const msm::PbdResult r = msm::run_pbd(problem, constraints, po);
    x = r.x;
    std::cout << "  " << r.seconds << " s, " << r.seconds / r.steps * 1e6
              << " µs per step, largest stretch violation " << r.max_violation * 1e3 << " mm\n";
    result["solver"] = {{"name", "pbd"},
                        {"steps", r.steps},
                        {"dt", po.dt},
                        {"iterations", po.iterations},
                        {"seconds", r.seconds},
                        {"seconds_per_step", r.seconds / r.steps},
                        {"constraints",
                         {{"stretch", counts_by_type[0]},
                          {"dihedral", counts_by_type[1]},
                          {"angle", counts_by_type[2]}}}};
  } else {
    msm::DynamicOptions d;
    d.integrator = integrator;
    const double critical = 2.0 / msm::max_frequency_bound(problem);
    d.dt =
        o.dt > 0 ? o.dt : (integrator == msm::Integrator::implicit_euler ? 10.0 : 0.5) * critical;
    d.steps = o.steps;
    std::cout << msm::to_string(integrator) << ": " << d.steps << " steps of " << d.dt
              << " s (critical step bound 2/ω_max = " << critical << " s) ...\n";
    const msm::DynamicResult r = msm::integrate(problem, d);
    x = r.x;
    std::cout << "  " << r.seconds << " s, " << r.seconds / r.steps * 1e6
              << " µs per step, final energy " << r.energy << " J\n";
    result["solver"] = {{"name", o.solver},     {"steps", r.steps},
                        {"dt", d.dt},           {"critical_dt_bound", critical},
                        {"seconds", r.seconds}, {"seconds_per_step", r.seconds / r.steps},
                        {"energy_J", r.energy}};
  }

  // Displacement at the network node nearest the contact point, and the largest.
  int nearest = 0;
  double best = std::numeric_limits<double>::infinity();
  double max_u = 0.0;
  for (std::size_t i = 0; i < net.nodes.size(); ++i) {
    const double d = (net.nodes[i] - spec.point).squaredNorm();
    if (d < best) {
      best = d;
      nearest = static_cast<int>(i);
    }
    max_u = std::max(max_u, (x.segment<3>(3 * static_cast<Eigen::Index>(i)) - net.nodes[i]).norm());
  }
  const Vec3 u = x.segment<3>(3 * nearest) - net.nodes[nearest];
  const Vec3 inward = -patch.outward_normal;
  const double strain = model.max_strain(x);
  std::cout << "contact-point displacement: " << u.norm() * 1e3 << " mm (along the load "
            << u.dot(inward) * 1e3 << " mm) at node " << nearest << ", " << std::sqrt(best) * 1e3
            << " mm from the contact point\n"
            << "largest nodal displacement " << max_u * 1e3 << " mm, largest spring strain "
            << strain * 100 << " %"
            << (strain > 0.05 ? " (beyond 5 %: outside the linear regime)" : "") << "\n";
  result["contact_displacement_mm"] = u.norm() * 1e3;
  result["contact_displacement_along_load_mm"] = u.dot(inward) * 1e3;
  result["max_displacement_mm"] = max_u * 1e3;
  result["max_spring_strain"] = strain;
  result["total_seconds"] = seconds_since(t_total);
  if (!o.json.empty()) {
    write_file_atomically(o.json, [&](std::ostream& out) { out << result.dump(2) << "\n"; });
    std::cout << "wrote " << o.json.string() << "\n";
  }
}

}  // namespace

void add_msm_command(CLI::App& app) {
  auto o = std::make_shared<MsmOptions>();
  CLI::App* cmd = app.add_subcommand(
      "msm",
      "Run a mass-spring model (surface: seeds 000/002; volume: seed 001) on a vessel mesh under "
      "a contact patch (the FEM's load), statically or dynamically; prints spring counts per "
      "family, timings and the contact-point displacement in mm.\n"
      "Examples:\n"
      "  vesselverify msm                                   # surface model, static, 1 mN\n"
      "  vesselverify msm --model volume --stiffness seed001 --solver verlet --steps 2000\n"
      "  vesselverify msm --structured --surface mid --solver implicit-euler --dt 1e-3");
  add_vessel_options(*cmd, o->vessel);
  cmd->add_option("--model", o->model, "surface or volume")
      ->check(CLI::IsMember({"surface", "volume"}))
      ->capture_default_str();
  cmd->add_option("--surface", o->surface, "Wall surface of the surface model: inner, outer, mid")
      ->check(CLI::IsMember({"inner", "outer", "mid"}))
      ->capture_default_str();
  cmd->add_option("--topology", o->topology,
                  "Surface springs: 'grid' (seed 000 families on a --structured tube), "
                  "'triangles' (any triangle mesh), 'auto' (grid if --structured)")
      ->capture_default_str();
  cmd->add_flag("--two-ring", o->two_ring, "Add two-ring springs (triangle topology)");
  cmd->add_option("--stiffness", o->stiffness,
                  "Stiffness rule: seed000, seed001, van-gelder, lloyd, uniform")
      ->capture_default_str();
  auto& sp = o->stiffness_params;
  cmd->add_option("--youngs-modulus", sp.youngs_modulus, "E, Pa")->capture_default_str();
  cmd->add_option("--poisson-ratio", sp.poisson_ratio, "ν (lloyd rule)")->capture_default_str();
  cmd->add_option("--uniform-k", sp.uniform_k, "k of the uniform rule, N/m")->capture_default_str();
  cmd->add_option("--shear-factor", sp.shear_factor, "Factor on shear springs")
      ->capture_default_str();
  cmd->add_option("--bend-factor", sp.bend_factor, "Factor on bend springs")->capture_default_str();
  cmd->add_option("--two-ring-factor", sp.two_ring_factor, "Factor on two-ring springs")
      ->capture_default_str();
  cmd->add_option("--bilinear-ratio", sp.bilinear_ratio, "k2/k1 of seed 001's bilinear spring")
      ->capture_default_str();
  cmd->add_option("--bilinear-threshold", sp.bilinear_threshold_strain,
                  "Threshold strain of the bilinear spring (default: none, Hooke)");
  cmd->add_option("--mass", o->mass, "Mass rule: uniform, seed001, consistent")
      ->capture_default_str();
  cmd->add_option("--density", o->density, "kg/m³")->capture_default_str();
  cmd->add_option("--solver", o->solver,
                  "static, linear, relaxation, explicit-euler, symplectic-euler, verlet, "
                  "implicit-euler, pbd (XPBD constraints of seed 002, surface model)")
      ->check(CLI::IsMember({"static", "linear", "relaxation", "explicit-euler", "symplectic-euler",
                             "verlet", "implicit-euler", "pbd"}))
      ->capture_default_str();
  cmd->add_option("--dt", o->dt,
                  "Time step, s (default: 0.5 × the critical-step bound; implicit: 10 ×)");
  cmd->add_option("--steps", o->steps, "Number of time steps")->capture_default_str();
  cmd->add_option("--point-damping", o->point_damping, "k_v of seed 000 eq. (3.3), N·s/m")
      ->capture_default_str();
  cmd->add_option("--axial-damping", o->axial_damping, "k_d of seed 000 eq. (3.4), N·s/m")
      ->capture_default_str();
  cmd->add_option("--force", o->force, "Contact force, N")->capture_default_str();
  cmd->add_option("--contact-point", o->contact_point,
                  "Contact point x y z, m (default: inner wall at mid-length)")
      ->expected(3);
  cmd->add_option("--pressure", o->pressure, "Internal pressure on the inner wall, Pa")
      ->capture_default_str();
  cmd->add_flag("--gravity", o->gravity, "Add gravity (9.81 m/s² along −y) on the nodal masses");
  cmd->add_option("--patch-radius", o->patch_radius, "Contact patch radius, m")
      ->capture_default_str();
  cmd->add_option("--fixed", o->fixed_groups, "Surface groups whose nodes are fixed")
      ->capture_default_str();
  cmd->add_option("--pbd-iterations", o->pbd_iterations, "XPBD iterations per step")
      ->capture_default_str();
  cmd->add_option("--bending-compliance", o->bending_compliance,
                  "XPBD compliance of the dihedral/angle constraints, 1/(N·m) (0: rigid)")
      ->capture_default_str();
  cmd->add_flag("--angle-constraints", o->angle_constraints,
                "Add seed 002's simplified angle constraints at loaded nodes");
  cmd->add_flag("--no-dihedral", o->no_dihedral, "Leave out the dihedral-angle constraints");
  cmd->add_option("--pbd-damping", o->pbd_damping, "Fraction of velocity removed per PBD step")
      ->capture_default_str();
  cmd->add_option("--load-steps", o->load_steps, "Static Newton: load increments")
      ->capture_default_str();
  cmd->add_flag("-v,--verbose", o->verbose, "Print the Newton iterations");
  cmd->add_option("--json", o->json, "Write the results as JSON (atomically)");
  cmd->callback([o] { run(*o); });
}

}  // namespace vessel::cli
