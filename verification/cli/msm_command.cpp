/// `vesselverify msm`: build a surface or volume mass-spring model on a vessel mesh, load it with
/// the shared contact patch (and optionally pressure and gravity), solve statically or
/// dynamically, print and optionally write results. The flags become a Scene; the network and
/// problem come from scene_problems.hpp, the solver from msm::solve, the file from msm_document.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "meshes/foundation/errors.hpp"
#include "meshes/msh_io.hpp"
#include "meshes/stl_io.hpp"
#include "msm/kernels/spring_kernels.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/formats/network_file.hpp"
#include "verification/cli/commands.hpp"
#include "verification/cli/vessel_options.hpp"
#include "verification/msm_document.hpp"
#include "verification/scene_problems.hpp"

namespace vessel::cli {

namespace fs = std::filesystem;

namespace {

struct MsmOptions {
  VesselOptions vessel;
  std::string model = "surface";
  std::string surface = msm::to_string(msm::NetworkOptions{}.surface);
  std::string topology = "auto";
  bool two_ring = false;
  std::string stiffness;  ///< empty: seed000, or van-gelder with --volume-term or --bending
  bool volume_term = false;
  bool edge_pairs = false;
  std::string volume_moduli = "golec";
  std::string bending = "none";
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
  double patch_radius = ContactPatchSpec{}.radius;
  std::vector<std::string> fixed_groups{"inlet", "outlet"};
  fs::path json;
  fs::path export_network;  ///< .json or .vtu: the built network in the network-file format
  bool verbose = false;
  int pbd_iterations = 10;
  int lg_iterations = msm::LocalGlobalSettings{}.iterations;
  double cg_tolerance = msm::PcgOptions{}.tolerance;
  std::string cg_preconditioner = "block-jacobi";
  double bending_compliance = 0.0;
  bool angle_constraints = false;
  bool no_dihedral = false;
  double pbd_damping = 0.01;
  double pressure = 0.0;
  bool gravity = false;
  int load_steps = 1;
  std::string globalisation = "line-search";
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

bool is_stl(const MsmOptions& o) {
  std::string ext = o.input.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (!o.input.empty() && ext != ".msh" && ext != ".stl") {
    throw InputError("--input " + o.input.string() +
                     ": expected a .msh mesh or an .stl surface, got '" + ext + "'");
  }
  return ext == ".stl";
}

/// Option combinations that cannot work, refused before any work.
void check_options(const MsmOptions& o) {
  const msm::SolverSpec solver = msm::parse_solver(o.solver);
  if (solver.kind == msm::SolverKind::pbd && o.model != "surface") {
    throw InputError("--solver pbd: the position-based constraints of seed 002 are for the "
                     "surface model (--model surface)");
  }
  if (o.dt < 0 || !std::isfinite(o.dt)) {
    throw InputError("--dt: expected a time step > 0 s (or 0 for automatic), got " +
                     std::to_string(o.dt));
  }
  if (o.steps < 1) throw InputError("--steps: expected ≥ 1, got " + std::to_string(o.steps));
  if (!(o.force >= 0) || !std::isfinite(o.force)) {
    throw InputError("--force: expected a finite value ≥ 0 N, got " + std::to_string(o.force));
  }
  if (!std::isfinite(o.pressure)) throw InputError("--pressure: expected a finite value in Pa");
  if (o.fix_boundary && o.model != "surface") {
    throw InputError("--fix-boundary: fixes the open boundary of a surface model; for the volume "
                     "model use --fixed groups or --fix-below-z/--fix-above-z");
  }
  if (o.input.empty()) return;
  const std::string in = "--input " + o.input.string();
  if (o.vessel.structured || o.topology == "grid") {
    throw InputError(in + ": seed 000's grid topology needs the generated --structured tube; " +
                     "a file gives the triangle topology");
  }
  if (o.model == "surface" && o.surface == "mid") {
    throw InputError(in + ": --surface mid needs the generated vessel's centreline; use inner or outer");
  }
}

/// What an STL surface cannot give (it has no physical groups), refused before any work.
void check_stl_options(const MsmOptions& o) {
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
}

/// The group name an STL surface's triangles get (it has no groups of its own).
constexpr const char* kStlGroup = "surface";

/// The mesh the model is built on: generated, a user .msh, or an STL surface as a mesh without
/// tets (`stl` then holds the surface, node i = mesh node i).
TetMesh load_mesh(MsmOptions& o, TriangleSurface& stl) {
  if (o.input.empty()) return mesh_vessel(o.vessel, std::cout);
  (void)resolve(o.vessel);  // wall thickness, default contact point
  const std::string in = o.input.string();
  if (is_stl(o)) {
    stl = read_stl(o.input);
    stl.source_node.resize(stl.nodes.size());
    std::iota(stl.source_node.begin(), stl.source_node.end(), 0);
    std::cout << "surface " << in << ": " << stl.nodes.size() << " nodes, "
              << stl.triangles.size() << " triangles\n";
    return surface_as_mesh(stl, kStlGroup);
  }
  TetMesh mesh = read_msh(o.input);
  if (o.model == "volume" && mesh.tets.empty()) {
    throw InputError(in + ": the volume model needs tetrahedra, the file has none");
  }
  if (o.model == "surface") {
    (void)mesh.require_group(o.surface == "outer" ? group_names::outer_wall : group_names::inner_wall,
                             2, in);
  }
  for (const auto& name : o.fixed_groups) (void)mesh.require_group(name, 2, in);
  std::cout << "mesh " << in << ": " << mesh.nodes.size() << " nodes, " << mesh.tets.size()
            << " tets, " << mesh.triangles.size() << " boundary triangles\n";
  return mesh;
}

/// The command's flags as a scene: vessel, material, the --fixed groups clamped, the contact
/// force (absent at 0), and pressure and gravity applied with it when asked for.
Scene command_scene(const MsmOptions& o, bool stl) {
  Scene s;
  s.name = "msm";
  s.source = "vesselverify msm";
  s.vessel = o.vessel.params;
  s.youngs_modulus = o.stiffness_params.youngs_modulus;
  s.poisson_ratios = {o.stiffness_params.poisson_ratio};
  s.density = o.density;
  if (!stl) {
    for (const auto& g : o.fixed_groups) s.boundary[g] = EndCondition::clamped;
  }
  s.load.kind = LoadKind::contact;
  s.load.magnitudes = {o.force};
  s.load.contact.radius = o.patch_radius;
  s.load.contact.surface_group = stl ? kStlGroup : std::string(group_names::inner_wall);
  s.load.contact.point = o.contact_point.empty()
                             ? default_contact_point(s.vessel, s.load.contact.surface_group)
                             : Vec3(o.contact_point[0], o.contact_point[1], o.contact_point[2]);
  if (o.pressure != 0.0) {
    LoadSpec& p = s.constant_loads.emplace_back();
    p.kind = LoadKind::pressure;
    p.magnitudes = {o.pressure};
    p.contact.surface_group = std::string(group_names::inner_wall);
  }
  if (o.gravity) {
    LoadSpec& g = s.constant_loads.emplace_back();
    g.kind = LoadKind::gravity;
    g.magnitudes = {1.0};  // 1 g along −y
  }
  return s;
}

/// The model's network: the triangle topology on an STL surface, else build_network.
msm::BuiltNetwork command_network(const MsmOptions& o, const Scene& s, const TetMesh& mesh,
                                  const TriangleSurface& stl) {
  msm::NetworkOptions n;
  n.model = msm::parse_model_type(o.model);
  n.surface = msm::parse_wall_surface(o.surface);
  n.topology = msm::parse_topology(o.topology);
  n.two_ring = o.two_ring;
  n.stiffness = msm::parse_stiffness_rule(o.stiffness);
  n.volume_term = o.volume_term;
  n.edge_pairs = o.edge_pairs;
  n.volume_moduli = msm::parse_volume_moduli(o.volume_moduli);
  n.bending = msm::parse_bending(o.bending);
  n.stiffness_params = o.stiffness_params;
  n.mass = msm::parse_mass_rule(o.mass);
  n.density = o.density;
  n.axial_damping = o.axial_damping;
  if (!stl.nodes.empty()) return msm::build_surface_network(stl, s.vessel.wall_thickness, n);
  return msm::build_network(mesh, s.vessel, n);
}

/// Fixes the network nodes selected by --fix-below-z, --fix-above-z and --fix-boundary. InputError
/// if an option fixes nothing, or if every node ends up fixed.
void fix_by_options(const MsmOptions& o, const msm::SpringNetwork& net, msm::Problem& p) {
  auto fix = [&](const std::vector<std::size_t>& nodes) {
    for (const std::size_t i : nodes) p.fixed[3 * i] = p.fixed[3 * i + 1] = p.fixed[3 * i + 2] = 1;
  };
  auto by_z = [&](double z, bool below, const std::string& name) {
    if (std::isnan(z)) return;
    if (!std::isfinite(z)) throw InputError(name + ": expected a finite z in metres");
    const auto nodes = nodes_beyond_plane_z(net.nodes, z, below);
    if (nodes.empty()) {
      const auto [lo, hi] = std::minmax_element(
          net.nodes.begin(), net.nodes.end(), [](const Vec3& a, const Vec3& b) { return a.z() < b.z(); });
      std::ostringstream m;
      m << name << " " << z << ": fixes no node; the model spans z from " << lo->z() * 1e3
        << " to " << hi->z() * 1e3 << " mm (the option is in metres)";
      throw InputError(m.str());
    }
    fix(nodes);
    std::cout << name << " " << z * 1e3 << " mm: " << nodes.size() << " nodes fixed\n";
  };
  by_z(o.fix_below_z, true, "--fix-below-z");
  by_z(o.fix_above_z, false, "--fix-above-z");
  if (o.fix_boundary) {
    const auto nodes = open_boundary_nodes(net.triangles);
    if (nodes.empty()) {
      throw InputError("--fix-boundary: the surface is closed (every edge has two triangles); "
                       "fix nodes with --fix-below-z or --fix-above-z");
    }
    fix(nodes);
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

/// The solver of the flags: kind, time step (0: automatic), steps, Newton and PBD settings.
msm::SolverSpec command_solver(const MsmOptions& o) {
  msm::SolverSpec spec = msm::parse_solver(o.solver);
  spec.dt = o.dt;
  spec.steps = o.steps;
  auto& so = spec.static_options;
  if (o.verbose) so.log = &std::cout;
  so.load_steps = o.load_steps;
  so.globalisation = msm::parse_static_globalisation(o.globalisation);
  so.curvature_iterations = o.curvature_iterations;
  so.curvature_shift = o.curvature_shift;
  so.exact_backoff = o.exact_backoff;
  spec.pbd.iterations = o.pbd_iterations;
  spec.local_global.iterations = o.lg_iterations;
  spec.pcg.tolerance = o.cg_tolerance;
  spec.pcg.preconditioner = msm::parse_pcg_preconditioner(o.cg_preconditioner);
  spec.pbd.velocity_damping = o.pbd_damping;
  spec.pbd.bending_compliance = o.bending_compliance;
  spec.pbd.dihedral = !o.no_dihedral;
  spec.pbd.angle = o.angle_constraints;
  return spec;
}

/// One line (or two) on what the solver did.
void print_solve(const msm::SolverSpec& spec, const msm::Problem& problem,
                 const msm::SolveResult& s) {
  if (const auto* r = std::get_if<msm::StaticResult>(&s.detail)) {
    const bool newton = spec.kind == msm::SolverKind::static_newton;
    const bool lg = spec.kind == msm::SolverKind::local_global;
    std::cout << (newton ? "static Newton" : lg ? "local-global (Liu et al. 2013)" : "linearised model")
              << ": " << r->iterations
              << " iteration(s), residual " << r->residual << " N, " << std::setprecision(4)
              << r->seconds << " s per static solve (" << r->symbolic_analyses << " symbolic, "
              << r->numeric_factorisations << " numeric CHOLMOD factorisations, "
              << r->factorisation_seconds << " s)\n";
    if (newton) {
      std::cout << "  " << r->indefinite_iterations << " iteration(s) with an indefinite Hessian, "
                << r->negative_curvature_steps << " negative-curvature step(s), "
                << r->boundary_steps << " trust-region step(s) on the boundary, "
                << r->rejected_steps << " rejected; assembly " << r->assembly_seconds
                << " s, negative-curvature search " << r->curvature_seconds << " s\n";
    }
    std::cout << std::setprecision(6);
  } else if (const auto* rel = std::get_if<msm::RelaxationResult>(&s.detail)) {
    std::cout << "dynamic relaxation: " << rel->steps << " steps of " << rel->dt << " s, residual "
              << rel->residual << " N, " << rel->seconds << " s (" << rel->seconds / rel->steps * 1e6
              << " µs per step)\n";
  } else if (const auto* dyn = std::get_if<msm::DynamicResult>(&s.detail)) {
    std::cout << msm::to_string(spec) << ": " << dyn->steps << " steps of " << s.dt
              << " s (critical step bound 2/ω_max = " << 2.0 / msm::max_frequency_bound(problem)
              << " s)\n  ";
    if (spec.kind == msm::SolverKind::local_global_euler) {
      std::cout << spec.local_global.iterations << " local-global iterations per step; set-up "
                << "(assembly and factorisation) " << dyn->setup_seconds << " s, then ";
    } else if (spec.implicit_matrix == msm::ImplicitMatrix::rest_prefactored) {
      std::cout << "set-up (assembly and factorisation at rest) " << dyn->setup_seconds
                << " s (factor of " << dyn->factor_entries << " entries), then ";
    } else if (spec.implicit_matrix == msm::ImplicitMatrix::rest_pcg ||
               spec.implicit_matrix == msm::ImplicitMatrix::current_pcg) {
      if (spec.implicit_matrix == msm::ImplicitMatrix::rest_pcg) {
        std::cout << "set-up (assembly at rest, preconditioner) " << dyn->setup_seconds << " s; ";
      }
      std::cout << "conjugate gradients to relative residual " << spec.pcg.tolerance << ": "
                << static_cast<double>(dyn->linear_iterations) / std::max(dyn->steps, 1)
                << " iterations per step (at most " << dyn->max_linear_iterations << "); then ";
    }
    std::cout << dyn->seconds << " s, " << dyn->seconds / dyn->steps * 1e6
              << " µs per step, final energy " << dyn->energy << " J\n";
  } else if (const auto* pbd = std::get_if<msm::PbdResult>(&s.detail)) {
    std::cout << "XPBD (seed 002): " << pbd->steps << " steps of " << s.dt << " s, "
              << spec.pbd.iterations << " iterations each\n  " << pbd->seconds << " s, "
              << pbd->seconds / pbd->steps * 1e6 << " µs per step, largest stretch violation "
              << pbd->max_violation * 1e3 << " mm\n";
  }
}

/// Spring counts per family, k range and masses.
void print_network(const MsmOptions& o, const msm::BuiltNetwork& built, const msm::Problem& p,
                   MsmRunRecord& run) {
  const msm::SpringNetwork& net = built.network;
  std::cout << "model: " << o.model << (o.model == "surface" ? " (" + o.surface + " wall)" : "")
            << ", " << built.topology << ", " << net.nodes.size() << " nodes\nsprings:";
  for (msm::SpringFamily f : msm::kAllFamilies) {
    const std::size_t c = net.count(f);
    if (c == 0) continue;
    run.springs[msm::to_string(f)] = c;
    std::cout << " " << msm::to_string(f) << " " << c;
  }
  double kmin = std::numeric_limits<double>::infinity(), kmax = 0.0;
  for (const auto& s : net.springs) {
    kmin = std::min(kmin, s.law.k1);
    kmax = std::max(kmax, s.law.k1);
  }
  std::cout << " (total " << net.springs.size() << ")\nstiffness rule " << run.stiffness_rule
            << ": k from " << kmin << " to " << kmax << " N/m; mass rule " << run.mass_rule
            << ": total " << p.mass.sum() / 3.0 * 1e3 << " g\n";
}

/// The contact the problem carries: point, inward normal, patch; nothing at zero force.
std::optional<ContactRecord> contact_record(const Scene& s, const TetMesh& mesh) {
  if (s.load.magnitudes.front() == 0.0) return std::nullopt;
  const TractionPatch patch = scene_contact_patch(s.load, mesh, s.load.magnitudes.front());
  ContactRecord c;
  c.point = patch.centre;
  c.inward_normal = -patch.outward_normal;
  c.radius = s.load.contact.radius;
  c.force = s.load.magnitudes.front();
  c.patch_area = patch.area;
  c.patch_triangles = patch.triangles.size();
  std::cout << "contact: " << c.force * 1e3 << " mN over " << c.patch_triangles << " triangles ("
            << c.patch_area * 1e6 << " mm²) at (" << c.point.x() * 1e3 << ", "
            << c.point.y() * 1e3 << ", " << c.point.z() * 1e3 << ") mm\n";
  return c;
}

/// Displacements at the node nearest the contact point and the largest, and the spring strain.
void print_displacements(const msm::SpringNetwork& net, const msm::MassSpringModel& model,
                         const Eigen::VectorXd& x, MsmRunRecord& run) {
  for (std::size_t i = 0; i < net.nodes.size(); ++i) {
    const double u = (x.segment<3>(3 * static_cast<Eigen::Index>(i)) - net.nodes[i]).norm();
    run.max_displacement = std::max(run.max_displacement, u);
  }
  run.max_spring_strain = model.max_strain(x);
  if (run.contact) {
    const std::size_t nearest = nearest_node(net.nodes, run.contact->point);
    const Vec3 u = x.segment<3>(3 * static_cast<Eigen::Index>(nearest)) - net.nodes[nearest];
    run.contact->displacement = u;
    std::cout << "contact-point displacement: " << u.norm() * 1e3 << " mm (along the load "
              << u.dot(run.contact->inward_normal) * 1e3 << " mm) at node " << nearest << ", "
              << (net.nodes[nearest] - run.contact->point).norm() * 1e3
              << " mm from the contact point\n";
  }
  const double strain = run.max_spring_strain;
  std::cout << "largest nodal displacement " << run.max_displacement * 1e3
            << " mm, largest spring strain " << strain * 100 << " %"
            << (strain > 0.05 ? " (beyond 5 %: outside the linear regime)" : "") << "\n";
}

/// --export-network: the built network (stiffness and mass rules applied) in the network-file
/// format. Its supports: the --fixed groups it follows (a scene then applies its own [boundary] to
/// the nodes on them), and the nodes the --fix-* options held, as fixed nodes.
void export_network(const MsmOptions& o, bool stl, const msm::BuiltNetwork& built,
                    const std::vector<char>& held_by_groups, const msm::Problem& problem) {
  msm::NetworkSupports supports;
  if (!stl) supports.follow_groups = o.fixed_groups;
  for (std::size_t i = 0; 3 * i < problem.fixed.size(); ++i) {
    if (problem.fixed[3 * i] && !held_by_groups[3 * i]) supports.fixed_nodes.push_back(static_cast<int>(i));
  }
  std::ostringstream d;
  d << "exported by vesselverify msm: " << o.model
    << (o.model == "surface" ? " model (" + o.surface + " wall)" : " model") << ", "
    << built.topology << ", " << o.stiffness << " stiffness (E = "
    << o.stiffness_params.youngs_modulus << " Pa), " << o.mass << " masses (density " << o.density
    << " kg/m³)";
  msm::write_network_file(o.export_network,
                     msm::network_file_of(built, std::move(supports), d.str()));
  std::cout << "wrote the network (" << built.network.nodes.size() << " nodes, "
            << built.network.springs.size() << " springs) to " << o.export_network.string() << "\n";
}

void run(MsmOptions& o) {
  const auto t_total = std::chrono::steady_clock::now();
  if (o.stiffness.empty()) {
    o.stiffness = o.volume_term || o.bending != "none" ? "van-gelder" : "seed000";
  }
  std::cout << std::setprecision(6);
  const bool stl = is_stl(o);
  if (stl) check_stl_options(o);  // first: what an STL cannot give explains the rest
  check_options(o);
  TriangleSurface stl_surface;
  const TetMesh mesh = load_mesh(o, stl_surface);
  std::cout << std::defaultfloat << std::setprecision(6);
  // A --lumen vessel: the contact point moves onto the chosen wall of its mesh.
  const Scene scene = resolve_file_vessel(command_scene(o, stl), mesh);
  MsmRunRecord run;
  run.vessel = scene.vessel;
  run.model = o.model;
  run.surface = o.surface;
  run.stiffness_rule = o.stiffness;
  run.mass_rule = o.mass;
  run.input = o.input.string();
  run.contact = contact_record(scene, mesh);
  const auto t_build = std::chrono::steady_clock::now();
  const msm::BuiltNetwork built = command_network(o, scene, mesh, stl_surface);
  const auto model_ptr = msm::make_model(built, o.point_damping);
  const msm::MassSpringModel& model = *model_ptr;
  msm::Problem problem = msm_problem(scene, model, built, mesh, o.force);
  const std::vector<char> held_by_groups = problem.fixed;
  fix_by_options(o, built.network, problem);
  if (!o.export_network.empty()) export_network(o, stl, built, held_by_groups, problem);
  run.build_seconds = seconds_since(t_build);
  run.topology = built.topology;
  run.nodes = built.network.nodes.size();
  print_network(o, built, problem, run);

  const msm::SolverSpec spec = command_solver(o);
  run.solver = o.solver;
  run.solve = msm::solve(problem, spec, &built.network);
  print_solve(spec, problem, run.solve);
  print_displacements(built.network, model, run.solve.x, run);
  run.total_seconds = seconds_since(t_total);
  if (!o.json.empty()) {
    write_msm_json(o.json, run);
    std::cout << "wrote " << o.json.string() << "\n";
  }
}

}  // namespace

namespace {

/// Model, topology, stiffness and mass rules.
void add_model_options(CLI::App* cmd, MsmOptions& o) {
  cmd->add_option("--model", o.model, "surface or volume")
      ->check(CLI::IsMember({"surface", "volume"}))
      ->capture_default_str();
  cmd->add_option("--surface", o.surface, "Wall surface of the surface model: inner, outer, mid")
      ->check(CLI::IsMember({"inner", "outer", "mid"}))
      ->capture_default_str();
  cmd->add_option("--topology", o.topology,
                  "Surface springs: 'grid' (seed 000 families on a --structured tube), "
                  "'triangles' (any triangle mesh), 'auto' (grid if --structured)")
      ->capture_default_str();
  cmd->add_flag("--two-ring", o.two_ring, "Add two-ring springs (triangle topology)");
  cmd->add_option("--stiffness", o.stiffness,
                  "Stiffness rule: seed000, seed001, van-gelder, lloyd, least-squares-fit, uniform "
                  "(default seed000; van-gelder with --volume-term or --bending)");
  cmd->add_flag("--volume-term", o.volume_term,
                "Hybrid volume model (Golec et al. 2020), volume model only: van-gelder springs "
                "carrying the shear modulus plus a volume energy per tet, κ = λ − μ, so that the "
                "network has the material's ν (< 0.5)");
  cmd->add_flag("--edge-pairs", o.edge_pairs,
                "Volume model only: each tet's springs coupled in its edge pairs, the edge-based "
                "StVK tetrahedron of Kikuuwe et al. 2009 (P1 FEM written on the edges, any ν < "
                "0.5); replaces the springs, so --stiffness does not apply");
  cmd->add_option("--volume-moduli", o.volume_moduli,
                  "With --volume-term: golec (default; E_s = 2.5μ, κ = λ − μ) or homogenised "
                  "((E_s, κ) fitted so that this mesh's network, under uniform boundary "
                  "traction, has the target E and ν; ν down to the mesh's floor, ~0.06)");
  cmd->add_option(
         "--bending", o.bending,
         "Surface model's bending: none, or discrete-shells (Grinspun et al. 2003: a hinge "
         "energy on every interior edge with D = E·t³/(12(1 − ν²)) from --youngs-modulus "
         "and --poisson-ratio, replacing the bend springs; triangle topology)")
      ->check(CLI::IsMember({"none", "discrete-shells"}))
      ->capture_default_str();
  auto& sp = o.stiffness_params;
  cmd->add_option("--youngs-modulus", sp.youngs_modulus, "E, Pa")->capture_default_str();
  cmd->add_option("--poisson-ratio", sp.poisson_ratio,
                  "ν (least-squares-fit rule, --volume-term and --bending)")
      ->capture_default_str();
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
  cmd->add_option("--mass", o.mass, "Mass rule: uniform, seed001, consistent")
      ->capture_default_str();
  cmd->add_option("--density", o.density, "kg/m³")->capture_default_str();
}

/// Solver, time step and damping.
void add_solver_options(CLI::App* cmd, MsmOptions& o) {
  std::vector<std::string> names(msm::kSolverNames.begin(), msm::kSolverNames.end());
  std::string listed;
  for (const std::string& n : names) listed += (listed.empty() ? "" : ", ") + n;
  cmd->add_option("--solver", o.solver,
                  listed + " (implicit-euler-rest: the matrix at rest, factorised once; "
                           "implicit-euler-pcg, implicit-euler-rest-pcg: implicit-euler's and "
                           "implicit-euler-rest's step by warm-started preconditioned conjugate "
                           "gradients; pbd: XPBD "
                           "constraints of seed 002, surface model; local-global, "
                           "local-global-euler: Liu et al. 2013, Hooke springs only)")
      ->check(CLI::IsMember(names))
      ->capture_default_str();
  cmd->add_option("--dt", o.dt,
                  "Time step, s (default: 0.5 × the critical-step bound, damped: within the "
                  "guaranteed damped step; implicit: 10 ×)");
  cmd->add_option("--steps", o.steps, "Number of time steps")->capture_default_str();
  cmd->add_option("--point-damping", o.point_damping, "k_v of seed 000 eq. (3.3), N·s/m")
      ->capture_default_str();
  cmd->add_option("--axial-damping", o.axial_damping, "k_d of seed 000 eq. (3.4), N·s/m")
      ->capture_default_str();
}

/// Loads, supports and the mesh source; returns --fixed (to know whether it was given).
CLI::Option* add_load_options(CLI::App* cmd, MsmOptions& o) {
  cmd->add_option("--force", o.force, "Contact force, N")->capture_default_str();
  cmd->add_option("--contact-point", o.contact_point,
                  "Contact point x y z, m (default: the inner wall at mid-length, (a, 0, L/2) on "
                  "the tube, the outer bend's apex (0, R + a, 0) on the arch)")
      ->expected(3);
  cmd->add_option("--pressure", o.pressure, "Internal pressure on the inner wall, Pa")
      ->capture_default_str();
  cmd->add_flag("--gravity", o.gravity, "Add gravity (9.81 m/s² along −y) on the nodal masses");
  cmd->add_option("--patch-radius", o.patch_radius, "Contact patch radius, m")
      ->capture_default_str();
  CLI::Option* fixed =
      cmd->add_option("--fixed", o.fixed_groups, "Surface groups whose nodes are fixed")
          ->capture_default_str();
  cmd->add_option("--input", o.input,
                  "Mesh file instead of a generated vessel: .msh (both models, with the vessel's "
                  "physical groups) or .stl (surface model; needs --contact-point and a --fix-* "
                  "option)");
  cmd->add_option("--fix-below-z", o.fix_below_z, "Also fix the nodes with z ≤ this, m");
  cmd->add_option("--fix-above-z", o.fix_above_z, "Also fix the nodes with z ≥ this, m");
  cmd->add_flag("--fix-boundary", o.fix_boundary,
                "Also fix the nodes on the surface's open boundary (the ends of a tube)");
  return fixed;
}

/// PBD and static Newton settings, verbosity, output.
void add_solver_tuning_options(CLI::App* cmd, MsmOptions& o) {
  cmd->add_option("--pbd-iterations", o.pbd_iterations, "XPBD iterations per step")
      ->capture_default_str();
  cmd->add_option("--cg-tolerance", o.cg_tolerance,
                  "implicit-euler(-rest)-pcg: relative residual ‖b − AΔv‖/‖b‖ at which CG stops")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--cg-preconditioner", o.cg_preconditioner,
                  "implicit-euler(-rest)-pcg: jacobi or block-jacobi (each node's 3×3 block)")
      ->check(CLI::IsMember({"jacobi", "block-jacobi"}))
      ->capture_default_str();
  cmd->add_option("--lg-iterations", o.lg_iterations,
                  "local-global-euler: local-global iterations per step (Liu et al. 2013)")
      ->capture_default_str();
  cmd->add_option("--bending-compliance", o.bending_compliance,
                  "XPBD compliance of the dihedral/angle constraints, 1/(N·m) (0: rigid)")
      ->capture_default_str();
  cmd->add_flag("--angle-constraints", o.angle_constraints,
                "Add seed 002's simplified angle constraints at loaded nodes");
  cmd->add_flag("--no-dihedral", o.no_dihedral, "Leave out the dihedral-angle constraints");
  cmd->add_option("--pbd-damping", o.pbd_damping, "Fraction of velocity removed per PBD step")
      ->capture_default_str();
  cmd->add_option("--load-steps", o.load_steps, "Static Newton: load increments")
      ->capture_default_str();
  cmd->add_option(
         "--globalisation", o.globalisation,
         "Static Newton: line-search (projected Hessian where indefinite) or "
         "trust-region (Steihaug-Toint CG on the exact Hessian, projected-Hessian preconditioner)")
      ->check(CLI::IsMember({"line-search", "trust-region"}))
      ->capture_default_str();
  cmd->add_option("--curvature-iterations", o.curvature_iterations,
                  "Static Newton: power iterations for a negative-curvature direction where the "
                  "Hessian is indefinite (0: plain projected Newton)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--curvature-shift", o.curvature_shift,
                  "Static Newton: smallest relative eigenvalue δ of the blended Hessian "
                  "(1 − τ)H + τHp where H is indefinite (≥ 1: projected Hessian only)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--exact-backoff", o.exact_backoff,
                  "Static Newton: after an indefinite exact Hessian, skip trying it for up to this "
                  "many iterations (doubling while it keeps failing; 0: try every iteration)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("-v,--verbose", o.verbose, "Print the Newton iterations");
  cmd->add_option("--json", o.json, "Write the results as JSON (atomically)");
  cmd->add_option("--export-network", o.export_network,
                  "Write the built network (after its stiffness and mass rules) as a spring-network "
                  "file, .json or .vtu (docs/user_guide/network_format.md), which a scene runs with "
                  "kind = \"network\"");
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
  add_model_options(cmd, *o);
  add_solver_options(cmd, *o);
  CLI::Option* fixed = add_load_options(cmd, *o);
  add_solver_tuning_options(cmd, *o);
  cmd->callback([o, fixed] {
    o->fixed_given = fixed->count() > 0;
    run(*o);
  });
}

}  // namespace vessel::cli
