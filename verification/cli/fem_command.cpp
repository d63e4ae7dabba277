/// `vesselverify fem`: solve the linear-elastic FEM reference on a vessel mesh under pressure, a
/// contact patch or gravity; print DoFs, phase timings, displacements, energy, strain, reactions;
/// write VTU and JSON. The flags become a Scene; the problem comes from scene_problems.hpp, the
/// checks from fem_reference/reference_checks.hpp and the files from verification/fem_document.
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <numbers>
#include <sstream>

#include "fem_reference/distributed_elasticity.hpp"
#include "fem_reference/elasticity.hpp"
#include "fem_reference/hyperelastic.hpp"
#include "fem_reference/reference_checks.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/foundation/solver_threads.hpp"
#include "meshes/vtu_io.hpp"
#include "verification/cli/commands.hpp"
#include "verification/cli/jobs_option.hpp"
#include "verification/cli/vessel_options.hpp"
#include "verification/fem_document.hpp"
#include "verification/scene_problems.hpp"

namespace vessel::cli {

namespace fs = std::filesystem;

namespace {

struct FemCommandOptions {
  VesselOptions vessel;
  int degree = 1;
  double youngs_modulus = fem::Material{}.youngs_modulus;
  double poisson_ratio = fem::Material{}.poisson_ratio;
  double density = fem::Material{}.density;
  std::string formulation = "auto";
  double mixed_threshold = fem::SolverOptions{}.mixed_threshold;
  std::vector<std::string> loads{"pressure"};
  double pressure = 10.0;
  double force = 1e-4;
  std::vector<double> contact_point;  // empty: default_contact_point on the chosen wall
  double contact_radius = ContactPatchSpec{}.radius;
  std::string contact_surface = std::string(group_names::inner_wall);
  std::vector<double> gravity{0.0, -kStandardGravity, 0.0};
  std::string bc = "auto";
  std::string solver = "auto";
  std::size_t direct_max_dofs = fem::SolverOptions{}.direct_max_dofs;
  std::size_t direct_max_mixed_dofs = fem::SolverOptions{}.direct_max_mixed_dofs;
  std::size_t matrix_free_min_dofs = fem::SolverOptions{}.matrix_free_min_dofs;
  double tolerance = fem::SolverOptions{}.cg_relative_tolerance;
  unsigned max_iterations = fem::SolverOptions{}.max_iterations;
  unsigned gmres_restart = fem::SolverOptions{}.gmres_restart;
  int threads = 1;  // --threads: the core count (add_threads_option)
  int modes = 0;
  bool curved = false;
  bool distributed = false;
  bool transient = false;  // Newmark step response after the static solve
  double dt = fem::TransientOptions{}.dt;
  int steps = fem::TransientOptions{}.steps;
  double mass_damping = 0.0;
  fs::path history_csv;
  bool richardson = false;  // also solve level − 1: Richardson / GCI of the contact-point u
  double richardson_order = 2.0;
  fs::path vtu;
  fs::path json;
  std::string reference = "linear";  // or finite-strain (neo-Hookean, fem::HyperelasticSolver)
  bool dead_pressure = false;         // finite-strain: pressure on the reference surface
};

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string mm(const Vec3& v, int precision = 6) {
  std::ostringstream s;
  s << std::setprecision(precision) << "(" << v.x() * 1e3 << ", " << v.y() * 1e3 << ", "
    << v.z() * 1e3 << ")";
  return s.str();
}

bool has_load(const FemCommandOptions& o, const std::string& name) {
  return std::find(o.loads.begin(), o.loads.end(), name) != o.loads.end();
}

/// "roller" for pressure alone, "clamped" otherwise (--bc auto); else --bc itself.
std::string end_condition_name(const FemCommandOptions& o) {
  if (o.bc != "auto") return o.bc;
  if (!o.vessel.params.parametric()) return "clamped";  // rollers need the straight tube's ends
  return has_load(o, "pressure") && o.loads.size() == 1 ? "roller" : "clamped";
}

/// One --load as a scene load at its single magnitude.
LoadSpec command_load(const FemCommandOptions& o, const std::string& name) {
  LoadSpec l;
  if (name == "pressure") {
    l.kind = LoadKind::pressure;
    l.magnitudes = {o.pressure};
    l.contact.surface_group = std::string(group_names::inner_wall);
  } else if (name == "contact") {
    l.kind = LoadKind::contact;
    l.magnitudes = {o.force};
    l.contact.surface_group = o.contact_surface;
    l.contact.radius = o.contact_radius;
    l.contact.point = o.contact_point.empty()
                          ? default_contact_point(o.vessel.params, o.contact_surface)
                          : Vec3(o.contact_point[0], o.contact_point[1], o.contact_point[2]);
  } else {
    const Vec3 g(o.gravity[0], o.gravity[1], o.gravity[2]);
    if (!g.allFinite()) throw InputError("--gravity: expected three finite numbers, m/s²");
    l.kind = LoadKind::gravity;
    l.magnitudes = {g.norm() / kStandardGravity};
    if (g.norm() > 0.0) l.gravity_direction = g.normalized();
  }
  return l;
}

/// The command's flags as a scene: vessel, material, ends and every --load at its magnitude.
Scene command_scene(const FemCommandOptions& o) {
  Scene s;
  s.name = "fem";
  s.source = "vesselverify fem";
  s.vessel = o.vessel.params;
  s.youngs_modulus = o.youngs_modulus;
  s.poisson_ratios = {o.poisson_ratio};
  s.density = o.density;
  const std::string ends = end_condition_name(o);
  const EndCondition inlet = ends == "roller" ? EndCondition::roller : EndCondition::clamped;
  s.boundary = {{"inlet", inlet},
                {"outlet", ends == "clamped-inlet" ? EndCondition::free : inlet}};
  // The first --load is the scene's load, the others are applied with it.
  for (std::size_t i = 0; i < o.loads.size(); ++i) {
    if (i == 0) {
      s.load = command_load(o, o.loads[i]);
    } else {
      s.constant_loads.push_back(command_load(o, o.loads[i]));
    }
  }
  return s;
}

/// The scene's FEM problem with the command's element and solver settings.
fem::ElasticityProblem command_problem(const FemCommandOptions& o, const Scene& s,
                                       const TetMesh& mesh) {
  fem::ElasticityProblem problem =
      fem_problem(s, mesh, o.poisson_ratio, o.degree, s.load.magnitudes.front());
  auto& opt = problem.options;
  opt.formulation = o.formulation == "mixed"          ? fem::Formulation::mixed
                    : o.formulation == "displacement" ? fem::Formulation::displacement
                                                      : fem::Formulation::automatic;
  opt.mixed_threshold = o.mixed_threshold;
  opt.solver = o.solver == "direct"        ? fem::LinearSolver::direct
               : o.solver == "cg-amg"      ? fem::LinearSolver::cg_amg
               : o.solver == "gmres-block" ? fem::LinearSolver::gmres_block
               : o.solver == "matrix-free" ? fem::LinearSolver::matrix_free
                                           : fem::LinearSolver::automatic;
  opt.direct_max_dofs = o.direct_max_dofs;
  opt.direct_max_mixed_dofs = o.direct_max_mixed_dofs;
  opt.matrix_free_min_dofs = o.matrix_free_min_dofs;
  opt.cg_relative_tolerance = o.tolerance;
  opt.max_iterations = o.max_iterations;
  opt.gmres_restart = o.gmres_restart;
  if (o.curved) {
    if (o.vessel.params.kind != VesselKind::straight) {
      throw InputError("--curved is available for the straight tube only (its walls are cylinders)");
    }
    problem.curved_surfaces =
        fem::tube_curved_walls(o.vessel.params.inner_radius, o.vessel.params.outer_radius());
  }
  return problem;
}

/// The contact the problem loads (its first patch), or nothing.
std::optional<ContactRecord> contact_record(const Scene& s, const fem::ElasticityProblem& p) {
  const LoadSpec* contact = s.load.kind == LoadKind::contact ? &s.load : nullptr;
  for (const auto& l : s.constant_loads) {
    if (l.kind == LoadKind::contact) contact = &l;
  }
  if (!contact || p.patches.empty()) return std::nullopt;
  const TractionPatch& patch = p.patches.front();
  ContactRecord c;
  c.point = patch.centre;
  c.inward_normal = -patch.outward_normal;
  c.radius = contact->contact.radius;
  c.force = contact->magnitudes.front();
  c.patch_area = patch.area;
  c.patch_triangles = patch.triangles.size();
  std::cout << "contact patch: " << c.patch_triangles << " triangles of '"
            << contact->contact.surface_group << "', area " << c.patch_area * 1e6 << " mm² (disc "
            << std::numbers::pi * c.radius * c.radius * 1e6 << " mm²), traction "
            << patch.traction.norm() << " Pa, at " << mm(c.point) << " mm pushing along "
            << mm(c.inward_normal * 1e-3, 4) << "\n";
  return c;
}

/// The run's header facts, shared by the serial and distributed paths.
FemRunRecord run_record(const FemCommandOptions& o, const TetMesh& mesh, bool cache_hit,
                        double mesh_seconds) {
  FemRunRecord run;
  run.vessel = o.vessel.params;
  run.youngs_modulus = o.youngs_modulus;
  run.poisson_ratio = o.poisson_ratio;
  run.density = o.density;
  run.loads = o.loads;
  run.ends = end_condition_name(o);
  run.mesh_nodes = mesh.nodes.size();
  run.mesh_tets = mesh.tets.size();
  run.cache_hit = cache_hit;
  run.mesh_seconds = mesh_seconds;
  return run;
}

/// Where the matrix-free solve's time went: the set-up's parts, then the CG's.
void print_matrix_free_profile(const fem::MatrixFreeProfile& p) {
  const double per_application =
      p.operator_applications ? p.operator_seconds / p.operator_applications : 0.0;
  std::cout << std::fixed << std::setprecision(3) << "matrix-free set-up (s): fine operator "
            << p.fine_operator << ", P1 level " << p.coarse_level << ", transfer " << p.transfer
            << ", diagonal " << p.diagonal << ", eigenvalue estimate " << p.eigenvalue_estimate
            << ", P1 matrix " << p.coarse_matrix << ", P1 solver (" << p.coarse_method << ") "
            << p.coarse_factor << "\n"
            << "matrix-free CG (s): " << p.cg << " in all; " << p.operator_applications
            << " operator applications " << p.operator_seconds << " (" << per_application * 1e3
            << " ms each, " << p.quadrature_points << " quadrature points per cell), "
            << p.coarse_solves << " P1 solves " << p.coarse_solve_seconds << " ("
            << p.coarse_iterations << " inner CG iterations), transfers " << p.transfer_seconds
            << "; Chebyshev degree " << p.chebyshev_degree << std::defaultfloat << "\n";
}

void print_solver(const fem::ElasticityResult& r) {
  std::cout << " " << fem::to_string(r.solver);
  if (r.solver == fem::LinearSolver::cg_amg) std::cout << ", " << r.iterations << " CG iterations";
  if (r.solver == fem::LinearSolver::matrix_free) {
    std::cout << ", " << r.iterations << " CG iterations ("
              << (r.element == "P1"
                      ? "ML on P1"
                      : "p-multigrid P2->P1, " + r.matrix_free.coarse_method + " on P1")
              << ")";
  }
  if (r.solver == fem::LinearSolver::gmres_block) {
    std::cout << ", " << r.iterations << " FGMRES iterations (" << std::setprecision(3)
              << r.inner_iterations << " CG iterations per pressure-mass solve)"
              << std::setprecision(6);
  }
  std::cout << "\n";
  if (r.solver == fem::LinearSolver::matrix_free) print_matrix_free_profile(r.matrix_free);
}

/// The reference's own uncertainty at the contact point (or the inner wall's default point): the
/// same problem one level coarser, Richardson extrapolation and GCI.
RichardsonRecord richardson_record(const FemCommandOptions& o, const Scene& s,
                                   const fem::ElasticitySolver& fine,
                                   const std::optional<ContactRecord>& contact) {
  VesselOptions coarse_options = o.vessel;
  coarse_options.params.level -= 1;
  std::cout << "richardson: the same problem on level " << coarse_options.params.level << "\n";
  const TetMesh coarse_mesh = mesh_vessel(coarse_options, std::cout);
  fem::ElasticitySolver coarse(coarse_mesh, command_problem(o, s, coarse_mesh));
  const auto& rc = coarse.solve();
  RichardsonRecord r;
  r.coarse_level = coarse_options.params.level;
  r.coarse_dofs = rc.n_dofs;
  const Vec3 point = contact ? contact->point : qoi_point(s);
  r.direction = contact ? contact->inward_normal : Vec3(Vec3(point.x(), point.y(), 0).normalized());
  r.value = fem::richardson_at_point(coarse, fine, point, r.direction, o.richardson_order);
  const auto& v = r.value;
  std::cout << std::setprecision(6) << "  u at " << mm(point) << " mm along " << mm(r.direction * 1e-3, 4)
            << ": level " << r.coarse_level << " (" << rc.n_dofs << " DoFs, "
            << fem::to_string(rc.solver) << ") " << v.u_coarse * 1e3 << " mm, level "
            << o.vessel.params.level << " " << v.u_fine * 1e3 << " mm\n"
            << "  Richardson (order " << v.order << ", ratio 2): extrapolated "
            << v.estimate.extrapolated * 1e3 << " mm, estimated error of level "
            << o.vessel.params.level << " " << v.estimate.error_fine * 1e3 << " mm ("
            << 100.0 * v.estimate.error_fine / std::abs(v.u_fine) << " %), GCI "
            << 100.0 * v.estimate.gci_fine << " % (safety factor 3)\n";
  return r;
}

/// The step response at the probe (contact point): sampled table, peak, and the CSV.
void print_transient(const FemCommandOptions& o, const fem::TransientResult& tr,
                     const Vec3& probe, const Vec3& u_static, const Vec3& dir) {
  std::cout << std::fixed << std::setprecision(3) << " setup " << tr.setup_seconds << " s, "
            << tr.seconds_per_step * 1e3 << " ms/step" << std::defaultfloat << "\n";
  std::cout << std::setprecision(3) << "  probe " << mm(probe) << " mm, displacement along ("
            << dir.x() << ", " << dir.y() << ", " << dir.z() << "), static "
            << u_static.dot(dir) * 1e3 << " mm:\n"
            << std::setprecision(6);
  double peak = 0.0, sum = 0.0;
  for (std::size_t n = 0; n < tr.time.size(); ++n) {
    const double u = tr.probe_displacement[n][0].dot(dir);
    peak = std::max(peak, std::abs(u));
    if (n > 0) sum += u;
  }
  std::cout << "    t (ms)      u (mm)        |u| (mm)\n";
  const std::size_t rows = std::min<std::size_t>(20, tr.time.size() - 1);
  for (std::size_t k = 0; k <= rows; ++k) {
    const std::size_t n = rows == 0 ? 0 : k * (tr.time.size() - 1) / rows;
    const Vec3& u = tr.probe_displacement[n][0];
    std::cout << "    " << std::setw(10) << tr.time[n] * 1e3 << "  " << std::setw(12)
              << u.dot(dir) * 1e3 << "  " << std::setw(12) << u.norm() * 1e3 << "\n";
  }
  const double mean = sum / static_cast<double>(tr.time.size() - 1);
  std::cout << "  peak |u| " << peak * 1e3 << " mm (" << peak / std::abs(u_static.dot(dir))
            << " x static), time mean " << mean * 1e3 << " mm, final "
            << tr.probe_displacement.back()[0].dot(dir) * 1e3 << " mm\n";
  if (!o.history_csv.empty()) {
    write_transient_csv(o.history_csv, tr);
    std::cout << "wrote " << o.history_csv.string() << "\n";
  }
}

/// The Newmark step response at the contact point (else the QoI point).
void run_transient(const FemCommandOptions& o, const Scene& s, const fem::ElasticitySolver& solver,
                   FemRunRecord& run) {
  fem::TransientOptions to;
  to.dt = o.dt;
  to.steps = o.steps;
  to.mass_damping = o.mass_damping;
  const Vec3 probe = run.contact ? run.contact->point : qoi_point(s);
  to.probe_points = {probe};
  std::cout << "transient (Newmark average acceleration, step load at t = 0): " << o.steps
            << " steps of " << o.dt << " s, mass damping " << o.mass_damping << " 1/s ..."
            << std::flush;
  run.transient = solver.transient(to);
  run.transient_options = to;
  const Vec3 u_static = solver.displacement_at({probe})[0];
  const Vec3 dir = run.contact ? run.contact->inward_normal
                               : (u_static.norm() > 0 ? Vec3(u_static.normalized()) : Vec3::UnitX());
  print_transient(o, *run.transient, probe, u_static, dir);
}

/// The results block: displacement, energy, strain, Lamé, loads and reactions, timings.
void print_results(const FemRunRecord& run, const char* timing_note) {
  const fem::ElasticityResult& r = run.result;
  std::cout << std::setprecision(6) << "results (mm, mN, mJ):\n";
  std::cout << "  max |u|                 " << run.max_displacement() * 1e3 << " mm\n";
  if (run.contact) {
    std::cout << "  u at contact point      " << mm(run.contact->displacement)
              << " mm, along the patch normal "
              << run.contact->displacement.dot(run.contact->inward_normal) * 1e3 << " mm\n";
  }
  std::cout << "  strain energy           " << r.strain_energy * 1e3 << " mJ\n";
  std::cout << "  max principal strain    " << r.max_principal_strain << " (max |eigenvalue| "
            << r.max_abs_principal_strain << ")\n";
  if (r.max_abs_principal_strain > 0.05) {
    std::cout << "  WARNING: strain above 5 %: outside the linear reference's validity\n";
  }
  if (run.lame_error) {
    std::cout << "  Lamé closed form        FEM relative L2 error " << *run.lame_error << "\n";
  }
  std::cout << "  applied load            " << mm(r.applied_load) << " mN\n";
  Vec3 reaction_sum = Vec3::Zero();
  for (const auto& g : r.reactions) {
    std::cout << "  reaction on " << std::left << std::setw(12) << g.group << std::right
              << mm(g.force) << " mN\n";
    reaction_sum += g.force;
  }
  // Relative to the largest force in the balance (a pressure's net load is zero by symmetry).
  double scale = r.applied_load.norm();
  for (const auto& g : r.reactions) scale = std::max(scale, g.force.norm());
  const double imbalance = (r.applied_load + reaction_sum).norm();
  std::cout << "  |applied + reactions|   " << imbalance * 1e3 << " mN";
  if (scale > 0) std::cout << " (" << imbalance / scale << " of the largest force in the balance)";
  std::cout << "\n";
  std::cout << std::fixed << std::setprecision(3) << "timings (s" << timing_note << "): mesh "
            << run.mesh_seconds << ", setup " << r.timings.setup << ", assembly "
            << r.timings.assembly << ", solve " << r.timings.solve << ", postprocess "
            << r.timings.postprocess << ", output " << run.output_seconds << std::defaultfloat
            << "\n";
}

/// Writes --vtu and --json (rank 0 only for a distributed run: it holds the gathered field).
void write_outputs(const FemCommandOptions& o, const TetMesh& mesh, FemRunRecord& run) {
  const auto t0 = Clock::now();
  if (!o.vtu.empty()) write_fem_vtu(o.vtu, mesh, run);
  run.output_seconds = since(t0);
  print_results(run, run.distributed ? ", slowest rank" : "");
  if (!o.vtu.empty()) std::cout << "wrote " << o.vtu.string() << "\n";
  if (!o.json.empty()) {
    write_fem_json(o.json, run);
    std::cout << "wrote " << o.json.string() << "\n";
  }
}

/// Discards what is written to it: the non-root ranks' std::cout in a --distributed run.
struct NullBuffer : std::streambuf {
  int overflow(int c) override { return c; }
};

/// The serial solve with its optional studies (Lamé, Richardson, modes, transient).
void run_serial(const FemCommandOptions& o, const Scene& s, const TetMesh& mesh,
                const fem::ElasticityProblem& problem, FemRunRecord& run) {
  fem::ElasticitySolver solver(mesh, problem);
  const auto& pre = solver.result();
  std::cout << "element " << pre.element << (pre.curved ? " on curved walls" : "") << ": "
            << pre.n_dofs << " DoFs";
  if (pre.n_pressure_dofs) std::cout << " (" << pre.n_pressure_dofs << " pressure)";
  // One problem: its direct solvers' BLAS (CHOLMOD, UMFPACK) and the matrix-free operator get
  // every core by default, as the harness gives a reference solved alone.
  set_solver_threads(o.threads);
  std::cout << "\nsolving on " << solver_threads() << " thread(s) ..." << std::flush;
  run.result = solver.solve();
  print_solver(run.result);
  std::cout << "solver " << fem::to_string(run.result.solver) << ": "
            << (o.solver == "auto" ? run.result.solver_reason : "requested by --solver " + o.solver)
            << "\n";
  if (run.contact) run.contact->displacement = solver.displacement_at({run.contact->point})[0];
  const bool lame_setup = run.ends == "roller" && o.loads == std::vector<std::string>{"pressure"};
  if (lame_setup) {  // plane strain is exact with roller ends: Lamé's closed form applies
    const VesselParams& v = o.vessel.params;
    run.lame_error = fem::lame_relative_l2_error(
        solver, {v.inner_radius, v.outer_radius(), o.pressure, o.youngs_modulus, o.poisson_ratio});
  }
  if (o.richardson) run.richardson = richardson_record(o, s, solver, run.contact);
  if (o.modes > 0) {
    std::cout << "modal analysis: lowest " << o.modes << " natural frequencies ..." << std::flush;
    run.modal = solver.modes(o.modes);
    std::cout << " " << std::fixed << std::setprecision(3) << run.modal->seconds << " s"
              << std::defaultfloat << "\n  f (Hz):" << std::setprecision(6);
    for (double f : run.modal->frequencies_hz) std::cout << " " << f;
    std::cout << "\n";
  }
  if (o.transient) run_transient(o, s, solver, run);
}

/// The same problem solved over the MPI ranks; every rank solves, rank 0 prints and writes.
void run_distributed(const TetMesh& mesh,
                     const fem::ElasticityProblem& problem, FemRunRecord& run) {
  fem::DistributedOptions dopt;
  if (run.contact) dopt.evaluation_points = {run.contact->point};
  std::cout << "solving distributed ..." << std::flush;
  const auto d = fem::solve_elasticity_distributed(mesh, problem, dopt);
  run.result = d.fem;
  std::vector<double> peak_mb;
  for (auto b : d.peak_memory_per_rank) peak_mb.push_back(static_cast<double>(b) / 1e6);
  run.distributed = DistributedRecord{d.n_ranks, d.cells_per_rank, d.dofs_per_rank,
                                      d.local_tets_per_rank, peak_mb};
  if (run.contact) run.contact->displacement = d.point_displacement.at(0);
  std::cout << " " << d.n_ranks << " MPI rank(s)\n";
  std::cout << "element " << run.result.element << ": " << run.result.n_dofs << " DoFs;";
  print_solver(run.result);
  std::cout << "solver " << fem::to_string(run.result.solver) << ": " << run.result.solver_reason
            << "\n  per rank: tets owned";
  for (auto c : d.cells_per_rank) std::cout << " " << c;
  std::cout << ", held (with ghosts)";
  for (auto c : d.local_tets_per_rank) std::cout << " " << c;
  std::cout << "; DoFs";
  for (auto c : d.dofs_per_rank) std::cout << " " << c;
  std::cout << "; peak memory MB";
  for (double m : peak_mb) std::cout << " " << static_cast<long>(m + 0.5);
  std::cout << "\n";
}

/// --distributed: rank 0 meshes, builds the problem, prints and writes; every rank solves its
/// part, and the other ranks never hold the whole mesh (solve_elasticity_distributed sends them
/// theirs).
void run_distributed_command(FemCommandOptions& o, bool root) {
  const auto t0 = Clock::now();
  TetMesh mesh;
  fem::ElasticityProblem problem;
  FemRunRecord run;
  fem::run_on_rank0([&] {
    MeshSource source;
    mesh = mesh_vessel(o.vessel, std::cout, &source);
    run = run_record(o, mesh, source.cache_hit, since(t0));
    std::cout << "mesh: " << mesh.nodes.size() << " nodes, " << mesh.tets.size() << " tets\n";
    const Scene scene = resolve_file_vessel(command_scene(o), mesh);
    problem = command_problem(o, scene, mesh);
    run.contact = contact_record(scene, problem);
    std::cout << std::setprecision(6) << "material: E " << o.youngs_modulus << " Pa, nu "
              << o.poisson_ratio << ", rho " << o.density << " kg/m³; ends: " << run.ends << "\n";
  });
  run_distributed(mesh, problem, run);
  if (root) write_outputs(o, mesh, run);
}

/// The finite-strain solution at the contact point along the patch's inward normal, or for
/// gravity and pressure at the scene's QoI point along the radial direction (as --richardson
/// reads it), beside the linear reference's at the same load factor.
QoiReading finite_strain_qoi(const fem::HyperelasticSolver& solver, double load_factor,
                             const Scene& scene, const TetMesh& mesh,
                             const fem::ElasticityProblem& problem, const FemRunRecord& run) {
  QoiReading q;
  q.point = run.contact ? run.contact->point : qoi_point(scene);
  q.direction = run.contact ? run.contact->inward_normal
                            : Vec3(q.point.x(), q.point.y(), 0.0).normalized();
  q.displacement = solver.displacement_at({q.point})[0];
  fem::ElasticitySolver linear(mesh, problem);
  linear.solve();
  q.linear_displacement = linear.displacement_at({q.point})[0] * load_factor;
  return q;
}

/// The finite-strain reference on the same problem: load steps, Newton iterations, how far the
/// load got, the contact (else QoI) point's displacement beside the linear reference's, timings.
void run_finite_strain(const FemCommandOptions& o, const Scene& scene,
                       const fem::ElasticityProblem& problem, const TetMesh& mesh,
                       FemRunRecord& run) {
  fem::HyperelasticOptions ho;
  ho.follower_pressure = !o.dead_pressure;
  fem::HyperelasticSolver solver(mesh, problem, ho);
  std::cout << "element " << solver.result().element << ": " << solver.n_dofs() << " DoFs\n"
            << "solving finite strain (compressible neo-Hookean"
            << (solver.result().formulation == fem::Formulation::mixed ? ", mixed u-p" : "")
            << (problem.pressures.empty() ? ""
                                          : (o.dead_pressure ? ", dead pressure"
                                                             : ", follower pressure"))
            << ") ..." << std::flush;
  const auto& r = solver.solve();
  std::cout << " " << fem::to_string(r.solver);
  if (r.linear_iterations > 0) std::cout << ", " << r.linear_iterations << " Krylov iterations";
  std::cout << "\n  load steps " << r.steps.size() << " accepted, " << r.rejected_steps
            << " rejected; Newton iterations " << r.newton_iterations << "\n";
  std::cout << "  solver " << fem::to_string(r.solver) << ": "
            << (o.solver == "auto" ? r.solver_reason : "requested by --solver " + o.solver) << "\n";
  if (r.solver == fem::LinearSolver::matrix_free) {
    std::cout << "  the Newton systems' p-multigrid, summed over them:\n";
    print_matrix_free_profile(r.matrix_free);
  }
  if (r.completed) {
    std::cout << "  load factor reached 1 (the full load)\n";
  } else {
    std::cout << "  WARNING: stopped at load factor " << r.load_factor << " of the load: "
              << r.stop_reason << "\n";
  }
  double max_u = 0.0;
  for (const auto& u : r.nodal_displacement) max_u = std::max(max_u, u.norm());
  std::cout << std::setprecision(6) << "results (mm, mJ), at load factor " << r.load_factor
            << ":\n  max |u|                 " << max_u * 1e3 << " mm\n";
  const QoiReading q = finite_strain_qoi(solver, r.load_factor, scene, mesh, problem, run);
  if (run.contact) run.contact->displacement = q.displacement;
  run.finite_strain_qoi = q;
  std::cout << (run.contact ? "  u at contact point      " : "  u at QoI point         ")
            << mm(q.displacement) << " mm, along the "
            << (run.contact ? "patch normal " : "radial direction ")
            << q.displacement.dot(q.direction) * 1e3 << " mm (linear reference at the same load "
            << q.linear_displacement.dot(q.direction) * 1e3 << " mm)\n";
  std::cout << "  strain energy           " << r.strain_energy * 1e3 << " mJ\n"
            << "  max principal Green-Lagrange strain " << r.max_abs_principal_strain
            << ", min J " << r.min_jacobian << "\n";
  std::cout << std::fixed << std::setprecision(3) << "timings (s): mesh " << run.mesh_seconds
            << ", setup " << r.timings.setup << ", assembly " << r.timings.assembly << ", solve "
            << r.timings.solve << ", postprocess " << r.timings.postprocess << std::defaultfloat
            << "\n";
  if (!o.vtu.empty()) {  // the displacement at the load factor reached, as the linear --vtu
    VtuField disp{"displacement", 3, {}};
    for (const Vec3& u : r.nodal_displacement) disp.values.insert(disp.values.end(), {u.x(), u.y(), u.z()});
    write_vtu(o.vtu, mesh, {disp});
    std::cout << "wrote " << o.vtu.string() << "\n";
  }
  if (!o.json.empty()) {
    write_finite_strain_json(o.json, run, r);
    std::cout << "wrote " << o.json.string() << "\n";
  }
}

void check_options(const FemCommandOptions& o) {
  if (o.reference == "finite-strain") {
    const char* other = o.distributed      ? "--distributed"
                        : o.modes > 0      ? "--modes"
                        : o.transient      ? "--transient"
                        : o.richardson     ? "--richardson"
                                           : nullptr;
    if (other) {
      throw InputError(std::string(other) +
                       " is available with the linear reference only: drop it, or drop "
                       "--reference finite-strain");
    }
  } else if (o.dead_pressure) {
    throw InputError("--dead-pressure is for --reference finite-strain (the linear reference's "
                     "pressure is always on the reference surface)");
  }
  if (o.richardson && o.vessel.params.level < 1) {
    throw InputError("--richardson also solves one level coarser: it needs --level >= 1, found " +
                     std::to_string(o.vessel.params.level));
  }
  if (o.distributed) {
    if (o.modes > 0) throw InputError("--modes is serial only: drop it or --distributed");
    if (o.transient) throw InputError("--transient is serial only: drop it or --distributed");
    if (o.richardson) throw InputError("--richardson is serial only: drop it or --distributed");
  }
}

void run(FemCommandOptions& o) {
  check_options(o);
  if (o.distributed) {
    // MPI lives for this command only (the serial program never initialises it unless CG-AMG
    // needs Trilinos); rank 0 meshes and prints, every rank solves its part.
    const fem::MpiSession mpi;
    static NullBuffer null_buffer;
    if (mpi.rank() != 0) std::cout.rdbuf(&null_buffer);
    run_distributed_command(o, mpi.rank() == 0);
    return;
  }
  const auto t0 = Clock::now();
  MeshSource source;
  const TetMesh mesh = mesh_vessel(o.vessel, std::cout, &source);
  FemRunRecord run = run_record(o, mesh, source.cache_hit, since(t0));
  std::cout << "mesh: " << mesh.nodes.size() << " nodes, " << mesh.tets.size() << " tets\n";
  // A vessel from a file: the contact point moves onto the chosen wall of its mesh.
  const Scene scene = resolve_file_vessel(command_scene(o), mesh);
  const fem::ElasticityProblem problem = command_problem(o, scene, mesh);
  run.contact = contact_record(scene, problem);
  std::cout << std::setprecision(6) << "material: E " << o.youngs_modulus << " Pa, nu "
            << o.poisson_ratio << ", rho " << o.density << " kg/m³; ends: " << run.ends << "\n";
  if (o.reference == "finite-strain") {
    run_finite_strain(o, scene, problem, mesh, run);
    return;
  }
  run_serial(o, scene, mesh, problem, run);
  write_outputs(o, mesh, run);
}

}  // namespace

namespace {

/// Element, material and formulation.
void add_material_options(CLI::App* cmd, FemCommandOptions& o) {
  cmd->add_option("--degree", o.degree, "Displacement element degree (1 or 2)")
      ->check(CLI::IsMember({1, 2}))
      ->capture_default_str();
  cmd->add_option("--E", o.youngs_modulus, "Young's modulus, Pa")->capture_default_str();
  cmd->add_option("--nu", o.poisson_ratio, "Poisson's ratio, 0..0.5")->capture_default_str();
  cmd->add_option("--density", o.density, "Density, kg/m³")->capture_default_str();
  cmd->add_option("--formulation", o.formulation,
                  "auto (mixed when nu >= --mixed-threshold), displacement, or mixed (P2-P1)")
      ->check(CLI::IsMember({"auto", "displacement", "mixed"}))
      ->capture_default_str();
  cmd->add_option("--mixed-threshold", o.mixed_threshold,
                  "auto: mixed formulation when nu >= this")
      ->capture_default_str();
  cmd->add_option("--reference", o.reference,
                  "linear (small strain) or finite-strain (compressible neo-Hookean with the same "
                  "E and nu, total Lagrangian, Newton with load stepping; mixed u-p as above; "
                  "docs/physics/finite_strain.md)")
      ->check(CLI::IsMember({"linear", "finite-strain"}))
      ->capture_default_str();
  cmd->add_flag("--dead-pressure", o.dead_pressure,
                "finite-strain: pressure acts on the reference surface (dead load) instead of the "
                "deformed one (follower load, the default)");
}

/// Loads: pressure, contact patch, gravity.
void add_load_options(CLI::App* cmd, FemCommandOptions& o) {
  cmd->add_option("--load", o.loads, "Load(s): pressure, contact, gravity (repeatable)")
      ->check(CLI::IsMember({"pressure", "contact", "gravity"}))
      ->capture_default_str();
  cmd->add_option("--pressure", o.pressure, "Internal pressure on inner_wall, Pa")
      ->capture_default_str();
  cmd->add_option("--force", o.force, "Contact force, N (pushes into the wall)")
      ->capture_default_str();
  cmd->add_option("--contact-point", o.contact_point,
                  "Contact point x y z, metres (default: the chosen wall at mid-length, (r, 0, L/2) "
                  "on the tube, the outer bend's apex (0, R + r, 0) on the arch)")
      ->expected(3);
  cmd->add_option("--contact-radius", o.contact_radius, "Contact patch radius, metres")
      ->capture_default_str();
  cmd->add_option("--contact-surface", o.contact_surface, "Surface group the contact acts on")
      ->check(CLI::IsMember({"inner_wall", "outer_wall"}))
      ->capture_default_str();
  cmd->add_option("--gravity", o.gravity, "Gravity vector gx gy gz, m/s²")
      ->expected(3)
      ->capture_default_str();
}

/// Ends and the linear solver.
void add_solver_options(CLI::App* cmd, FemCommandOptions& o) {
  cmd->add_option("--bc", o.bc, "End conditions: auto, roller, clamped, clamped-inlet")
      ->check(CLI::IsMember({"auto", "roller", "clamped", "clamped-inlet"}))
      ->capture_default_str();
  cmd->add_option("--solver", o.solver,
                  "Linear solver: auto (matrix-free for one P2 solve on straight-sided tets from "
                  "--matrix-free-min-dofs; else direct up to --direct-max-dofs / "
                  "--direct-max-mixed-dofs, else iterative), direct (CHOLMOD; UMFPACK for the "
                  "mixed system), cg-amg (CG "
                  "with Trilinos ML AMG, displacement system), gmres-block (FGMRES with a "
                  "block-triangular preconditioner: AMG on the displacement block, scaled "
                  "pressure mass for the Schur complement; mixed system), matrix-free (CG on "
                  "the matrix-free operator: for P2 a P2->P1 p-multigrid with ML-CG on P1, for "
                  "P1 ML; displacement system; with --reference finite-strain the Newton "
                  "systems on the matrix-free neo-Hookean tangent, FGMRES with follower "
                  "pressure; auto takes it there with follower pressure where it takes the "
                  "linear solve, the assembled tangent if a Krylov solve fails)")
      ->check(CLI::IsMember({"auto", "direct", "cg-amg", "gmres-block", "matrix-free"}))
      ->capture_default_str();
  cmd->add_option("--direct-max-dofs", o.direct_max_dofs,
                  "auto: direct solver up to this many DoFs")
      ->capture_default_str();
  cmd->add_option("--matrix-free-min-dofs", o.matrix_free_min_dofs,
                  "auto: the matrix-free P2 solve from this many DoFs (straight-sided tets, one "
                  "solve; 0: never)")
      ->capture_default_str();
  cmd->add_option("--direct-max-mixed-dofs", o.direct_max_mixed_dofs,
                  "auto: direct solver (UMFPACK) for the mixed system up to this many DoFs")
      ->capture_default_str();
  cmd->add_option("--tolerance", o.tolerance, "CG / FGMRES relative residual tolerance")
      ->capture_default_str();
  cmd->add_option("--max-iterations", o.max_iterations, "CG / FGMRES iteration limit")
      ->capture_default_str();
  cmd->add_option("--gmres-restart", o.gmres_restart,
                  "gmres-block: Krylov basis size before FGMRES restarts (2 vectors each)")
      ->check(CLI::Range(2u, 2000u))
      ->capture_default_str();
  add_threads_option(*cmd, o.threads,
                     "Threads of the serial solve (CHOLMOD's BLAS, the matrix-free operator's "
                     "cells; default: the core count)");
}

/// Curved geometry, modes, Richardson, MPI, transient and output files.
void add_study_options(CLI::App* cmd, FemCommandOptions& o) {
  cmd->add_flag("--curved", o.curved,
                "Quadratic elements: put the P2 geometry nodes on the exact cylinders (straight "
                "tube), so the wall is curved (O(h³) geometry instead of straight-sided O(h²))");
  cmd->add_option("--modes", o.modes,
                  "Also compute this many lowest natural frequencies and mode shapes (consistent "
                  "mass, on the same end conditions; e.g. 10)")
      ->check(CLI::Range(0, 100));
  cmd->add_flag("--richardson", o.richardson,
                "Also solve one level coarser (--level >= 1) and print the Richardson "
                "extrapolation and grid convergence index of the contact point's displacement "
                "(the reference's own discretisation uncertainty)");
  cmd->add_option("--richardson-order", o.richardson_order,
                  "Assumed convergence order for --richardson (2 is conservative for P1 and P2)")
      ->check(CLI::Range(0.5, 6.0))
      ->capture_default_str();
  cmd->add_flag(
      "--distributed", o.distributed,
      "Solve in parallel over the MPI ranks (run under 'mpirun -np N'): fully distributed "
      "mesh; P1/P2 by the matrix-free p-multigrid CG where auto takes it (or --solver "
      "matrix-free), else Trilinos CG with ML AMG; Taylor-Hood (nu >= --mixed-threshold) by "
      "FGMRES with the block preconditioner; no --curved, --modes or --transient. Rank 0 prints "
      "and "
      "writes the files; --vtu gets the nodal displacement only");
  cmd->add_flag("--transient", o.transient,
                "Also run the step response: the loads applied at t = 0 to the body at rest, "
                "Newmark average acceleration with the consistent mass; prints the contact "
                "point's displacement over time (sampled) and the timings");
  cmd->add_option("--dt", o.dt, "Transient time step, s")->capture_default_str();
  cmd->add_option("--steps", o.steps, "Transient number of steps")->capture_default_str();
  cmd->add_option("--mass-damping", o.mass_damping,
                  "Transient mass-proportional damping alpha (C = alpha M), 1/s")
      ->capture_default_str();
  cmd->add_option("--history-csv", o.history_csv,
                  "Transient: write the contact point's displacement (mm) and the energies (mJ) "
                  "at every step as CSV");
  cmd->add_option("--vtu", o.vtu,
                  "Write displacement and mode shapes (nodes), strain and stress (tets) as VTU; "
                  "with --reference finite-strain the displacement at the load factor reached");
  cmd->add_option("--json", o.json,
                  "Write a JSON summary (with --reference finite-strain: the load factor reached, "
                  "Newton iterations, displacements, strain energy and strains)");
}

}  // namespace

void add_fem_command(CLI::App& app) {
  auto o = std::make_shared<FemCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "fem",
      "Solve the linear-elastic FEM reference (deal.II, P1/P2 tets, Taylor-Hood P2-P1 for nu near "
      "0.5) on a vessel mesh and print DoFs, phase timings, displacement (mm), strain energy, "
      "largest principal strain and reaction forces (mN).\n"
      "Ends: 'roller' holds u_z = 0 on both end faces (plane strain, the Lamé set-up; three pins "
      "remove the in-plane rigid motion), 'clamped' holds both ends, 'clamped-inlet' only the "
      "inlet; 'auto' is roller for pressure alone and clamped otherwise.\n"
      "Examples:\n"
      "  vesselverify fem                                   # P1, 10 Pa internal pressure\n"
      "  vesselverify fem --degree 2 --level 1 --structured --vtu tube.vtu\n"
      "  vesselverify fem --load contact --force 1e-4 --contact-radius 5e-4 --json fem.json\n"
      "  vesselverify fem --load gravity --bc clamped-inlet\n"
      "  vesselverify fem --nu 0.5                          # Taylor-Hood P2-P1 (automatic)\n"
      "  vesselverify fem --load contact --force 0.02 --reference finite-strain\n"
      "  vesselverify fem --degree 2 --bc clamped-inlet --modes 10   # natural frequencies\n"
      "  vesselverify fem --degree 2 --level 2 --solver cg-amg\n"
      "  vesselverify fem --load contact --degree 2 --transient --dt 1e-4 --steps 200 "
      "--history-csv h.csv\n"
      "  mpirun -np 2 vesselverify fem --distributed --degree 2 --level 1 --load contact");
  add_vessel_options(*cmd, o->vessel);
  add_mesh_file_option(*cmd, o->vessel);
  add_material_options(cmd, *o);
  add_load_options(cmd, *o);
  add_solver_options(cmd, *o);
  add_study_options(cmd, *o);
  cmd->callback([o] { run(*o); });
}

}  // namespace vessel::cli
