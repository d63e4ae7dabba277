/// `vesselverify msm`: build a surface or volume mass-spring model on a vessel mesh, load it with
/// the shared contact patch, solve statically or dynamically, print and optionally write results.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <limits>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "meshes/atomic_file.hpp"
#include "meshes/errors.hpp"
#include "meshes/msh_io.hpp"
#include "meshes/stl_io.hpp"
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
  fs::path input;                                            ///< .msh or .stl instead of --vessel
  double fix_below_z = std::numeric_limits<double>::quiet_NaN();  ///< m
  double fix_above_z = std::numeric_limits<double>::quiet_NaN();  ///< m
  bool fix_boundary = false;
  bool fixed_given = false;  ///< --fixed on the command line
  int curvature_iterations = msm::StaticOptions{}.curvature_iterations;
  double curvature_shift = msm::StaticOptions{}.curvature_shift;
  int exact_backoff = msm::StaticOptions{}.exact_backoff;
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

/// Fixes the network nodes selected by --fix-below-z, --fix-above-z and --fix-boundary (the nodes
/// on edges of a single triangle: the open ends of a tube). InputError if an option fixes nothing.
void fix_by_options(const MsmOptions& o, const msm::SpringNetwork& net, msm::Problem& p) {
  auto fix = [&](std::size_t i) {
    for (int k = 0; k < 3; ++k) p.fixed[3 * i + k] = 1;
  };
  double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
  for (const Vec3& x : net.nodes) {
    zmin = std::min(zmin, x.z());
    zmax = std::max(zmax, x.z());
  }
  auto by_z = [&](double z, bool below, const std::string& name) {
    if (std::isnan(z)) return;
    if (!std::isfinite(z)) throw InputError(name + ": expected a finite z in metres");
    std::size_t n = 0;
    for (std::size_t i = 0; i < net.nodes.size(); ++i) {
      if (below ? net.nodes[i].z() <= z : net.nodes[i].z() >= z) {
        fix(i);
        ++n;
      }
    }
    if (n == 0) {
      std::ostringstream m;
      m << name << " " << z << ": fixes no node; the model spans z from " << zmin * 1e3 << " to "
        << zmax * 1e3 << " mm (the option is in metres)";
      throw InputError(m.str());
    }
    std::cout << name << " " << z * 1e3 << " mm: " << n << " nodes fixed\n";
  };
  by_z(o.fix_below_z, true, "--fix-below-z");
  by_z(o.fix_above_z, false, "--fix-above-z");
  if (o.fix_boundary) {
    std::map<std::pair<int, int>, int> edges;
    for (const Triangle& t : net.triangles) {
      for (int k = 0; k < 3; ++k) {
        const int a = t[k], b = t[(k + 1) % 3];
        ++edges[{std::min(a, b), std::max(a, b)}];
      }
    }
    std::set<int> nodes;
    for (const auto& [e, count] : edges) {
      if (count == 1) nodes.insert({e.first, e.second});
    }
    if (nodes.empty()) {
      throw InputError("--fix-boundary: the surface is closed (every edge has two triangles); "
                       "fix nodes with --fix-below-z or --fix-above-z");
    }
    for (int i : nodes) fix(static_cast<std::size_t>(i));
    std::cout << "--fix-boundary: " << nodes.size() << " nodes on the open boundary fixed\n";
  }
  if (std::find(p.fixed.begin(), p.fixed.end(), 0) == p.fixed.end()) {
    throw InputError("fixed nodes: every node of the model is fixed; nothing can move (check the "
                     "--fix-below-z/--fix-above-z values, in metres)");
  }
  if (std::find(p.fixed.begin(), p.fixed.end(), 1) == p.fixed.end()) {
    std::cout << "warning: no node is fixed; the static solvers need supports\n";
  }
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

  // The mesh: generated (--vessel ...), a user .msh (both models, physical groups) or an STL
  // surface (surface model only; no groups: fixed nodes and contact point from options).
  std::string ext = o.input.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  const bool from_file = !o.input.empty();
  const bool is_stl = from_file && ext == ".stl";
  if (from_file && ext != ".msh" && !is_stl) {
    throw InputError("--input " + o.input.string() + ": expected a .msh mesh or an .stl surface, got '" +
                     ext + "'");
  }
  if (from_file) {
    const std::string in = "--input " + o.input.string();
    if (o.vessel.structured || o.topology == "grid") {
      throw InputError(in + ": seed 000's grid topology needs the generated --structured tube; " +
                       "a file gives the triangle topology");
    }
    if (o.model == "surface" && o.surface == "mid") {
      throw InputError(in + ": --surface mid needs the generated vessel's centreline; use inner or outer");
    }
  }
  if (is_stl) {
    const std::string in = "--input " + o.input.string();
    if (o.model == "volume") {
      throw InputError(in + " is an STL surface: the volume model (--model volume) needs " +
                       "tetrahedra; give a .msh mesh, or use --model surface");
    }
    if (o.contact_point.empty() && o.force != 0.0) {
      throw InputError(in + ": --contact-point x y z (m) is required with an STL surface (no " +
                       "vessel geometry to place the default contact point on)");
    }
    if (o.fixed_given) {
      throw InputError(in + ": --fixed names physical groups, which an STL file does not have; " +
                       "fix nodes with --fix-below-z, --fix-above-z or --fix-boundary");
    }
    if (std::isnan(o.fix_below_z) && std::isnan(o.fix_above_z) && !o.fix_boundary) {
      throw InputError(in + ": an STL surface has no physical groups to fix; fix nodes with " +
                       "--fix-below-z Z, --fix-above-z Z (m) or --fix-boundary (the open ends)");
    }
    if (o.pressure != 0.0) {
      throw InputError(in + ": --pressure acts on the 'inner_wall' group, which an STL file has not");
    }
    o.fixed_groups.clear();
  }
  if (o.fix_boundary && o.model != "surface") {
    throw InputError("--fix-boundary: fixes the open boundary of a surface model; for the volume "
                     "model use --fixed groups or --fix-below-z/--fix-above-z");
  }

  TetMesh mesh;
  TriangleSurface stl_surface;
  const std::string surface_group = is_stl ? "surface" : std::string(group_names::inner_wall);
  if (!from_file) {
    mesh = mesh_vessel(o.vessel, std::cout);
  } else {
    (void)resolve(o.vessel);  // wall thickness, default contact point
    if (is_stl) {
      stl_surface = read_stl(o.input);
      // A TetMesh without tets holding the surface as one group, so the shared contact-patch
      // loads (meshes/surface_loads.hpp) work on it unchanged; network node i = mesh node i.
      mesh.nodes = stl_surface.nodes;
      mesh.triangles = stl_surface.triangles;
      PhysicalGroup g{surface_group, 2, 1, {}};
      g.elements.resize(mesh.triangles.size());
      std::iota(g.elements.begin(), g.elements.end(), 0);
      mesh.groups.push_back(g);
      stl_surface.source_node.resize(stl_surface.nodes.size());
      std::iota(stl_surface.source_node.begin(), stl_surface.source_node.end(), 0);
      std::cout << "surface " << o.input.string() << ": " << stl_surface.nodes.size()
                << " nodes, " << stl_surface.triangles.size() << " triangles\n";
    } else {
      mesh = read_msh(o.input);
      const std::string in = o.input.string();
      if (o.model == "volume" && mesh.tets.empty()) {
        throw InputError(in + ": the volume model needs tetrahedra, the file has none");
      }
      if (o.model == "surface") {
        (void)mesh.require_group(o.surface == "outer" ? group_names::outer_wall
                                                      : group_names::inner_wall,
                                 2, in);
      }
      for (const auto& name : o.fixed_groups) (void)mesh.require_group(name, 2, in);
      std::cout << "mesh " << in << ": " << mesh.nodes.size() << " nodes, " << mesh.tets.size()
                << " tets, " << mesh.triangles.size() << " boundary triangles\n";
    }
  }
  std::cout << std::defaultfloat << std::setprecision(6);
  const VesselParams& params = o.vessel.params;
  // Shared load definition: the same patch and consistent nodal loads the FEM gets.
  ContactPatchSpec spec;
  spec.point = o.contact_point.empty()
                   ? default_contact_point(params)
                   : Vec3(o.contact_point[0], o.contact_point[1], o.contact_point[2]);
  spec.radius = o.patch_radius;
  spec.surface_group = surface_group;
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
  msm::BuiltNetwork built =
      is_stl ? msm::build_surface_network(stl_surface, params.wall_thickness, network_options)
             : msm::build_network(mesh, params, network_options);
  const msm::SpringNetwork& net = built.network;
  const std::string& topology = built.topology;
  const std::vector<double>& masses = built.masses;
  const msm::SpringModel model(net, o.point_damping);
  msm::Problem problem = msm::make_problem(model, net, masses, mesh, loads, o.fixed_groups);
  fix_by_options(o, net, problem);
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
  if (from_file) result["input"] = o.input.string();

  Eigen::VectorXd x;
  if (o.solver == "static" || o.solver == "linear") {
    msm::StaticOptions static_options;
    if (o.verbose) static_options.log = &std::cout;
    static_options.load_steps = o.load_steps;
    static_options.curvature_iterations = o.curvature_iterations;
    static_options.curvature_shift = o.curvature_shift;
    static_options.exact_backoff = o.exact_backoff;
    const msm::StaticResult r = o.solver == "static" ? msm::solve_static(problem, static_options)
                                                     : msm::solve_linear(problem);
    x = r.x;
    std::cout << (o.solver == "static" ? "static Newton" : "linearised model") << ": "
              << r.iterations << " iteration(s), residual " << r.residual << " N, "
              << std::setprecision(4) << r.seconds << " s per static solve (" << r.symbolic_analyses
              << " symbolic, " << r.numeric_factorisations << " numeric CHOLMOD factorisations, "
              << r.factorisation_seconds << " s)\n";
    if (o.solver == "static") {
      std::cout << "  " << r.indefinite_iterations << " iteration(s) with an indefinite Hessian, "
                << r.negative_curvature_steps << " negative-curvature step(s); assembly "
                << r.assembly_seconds << " s, negative-curvature search " << r.curvature_seconds
                << " s\n";
    }
    std::cout << std::setprecision(6);
    result["solver"] = {{"name", o.solver},
                        {"iterations", r.iterations},
                        {"residual_N", r.residual},
                        {"seconds", r.seconds},
                        {"numeric_factorisations", r.numeric_factorisations},
                        {"factorisation_seconds", r.factorisation_seconds},
                        {"indefinite_iterations", r.indefinite_iterations},
                        {"negative_curvature_steps", r.negative_curvature_steps}};
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
  CLI::Option* fixed =
      cmd->add_option("--fixed", o->fixed_groups, "Surface groups whose nodes are fixed")
          ->capture_default_str();
  cmd->add_option("--input", o->input,
                  "Mesh file instead of a generated vessel: .msh (both models, with the vessel's "
                  "physical groups) or .stl (surface model; needs --contact-point and a --fix-* "
                  "option)");
  cmd->add_option("--fix-below-z", o->fix_below_z, "Also fix the nodes with z ≤ this, m");
  cmd->add_option("--fix-above-z", o->fix_above_z, "Also fix the nodes with z ≥ this, m");
  cmd->add_flag("--fix-boundary", o->fix_boundary,
                "Also fix the nodes on the surface's open boundary (the ends of a tube)");
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
  cmd->add_option("--curvature-iterations", o->curvature_iterations,
                  "Static Newton: power iterations for a negative-curvature direction where the "
                  "Hessian is indefinite (0: plain projected Newton)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--curvature-shift", o->curvature_shift,
                  "Static Newton: smallest relative eigenvalue δ of the blended Hessian "
                  "(1 − τ)H + τHp where H is indefinite (≥ 1: projected Hessian only)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--exact-backoff", o->exact_backoff,
                  "Static Newton: after an indefinite exact Hessian, skip trying it for up to this "
                  "many iterations (doubling while it keeps failing; 0: try every iteration)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("-v,--verbose", o->verbose, "Print the Newton iterations");
  cmd->add_option("--json", o->json, "Write the results as JSON (atomically)");
  cmd->callback([o, fixed] {
    o->fixed_given = fixed->count() > 0;
    run(*o);
  });
}

}  // namespace vessel::cli
