/// `vesselverify fem`: solve the linear-elastic FEM reference on a vessel mesh under pressure, a
/// contact patch or gravity; print DoFs, phase timings, displacements, energy, strain, reactions;
/// write VTU and JSON.
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "fem_reference/distributed_elasticity.hpp"
#include "fem_reference/elasticity.hpp"
#include "fem_reference/lame.hpp"
#include "meshes/atomic_file.hpp"
#include "meshes/errors.hpp"
#include "meshes/surface_loads.hpp"
#include "meshes/vtu_io.hpp"
#include "verification/cli/commands.hpp"
#include "verification/cli/vessel_options.hpp"

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
  std::vector<double> contact_point;  // empty: (a, 0, L/2) on the inner wall
  double contact_radius = 0.5e-3;
  std::string contact_surface = std::string(group_names::inner_wall);
  std::vector<double> gravity{0.0, -9.81, 0.0};
  std::string bc = "auto";
  std::string solver = "auto";
  std::size_t direct_max_dofs = fem::SolverOptions{}.direct_max_dofs;
  double tolerance = fem::SolverOptions{}.cg_relative_tolerance;
  unsigned max_iterations = fem::SolverOptions{}.max_iterations;
  int modes = 0;
  bool curved = false;
  bool distributed = false;
  bool transient = false;  // Newmark step response after the static solve
  double dt = fem::TransientOptions{}.dt;
  int steps = fem::TransientOptions{}.steps;
  double mass_damping = 0.0;
  fs::path history_csv;
  fs::path vtu;
  fs::path json;
};

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

Vec3 to_vec3(const std::vector<double>& v, const char* name) {
  if (v.size() != 3) throw InputError(std::string(name) + " expects three numbers x y z");
  return {v[0], v[1], v[2]};
}

std::string mm(const Vec3& v, int precision = 6) {
  std::ostringstream s;
  s << std::setprecision(precision) << "(" << v.x() * 1e3 << ", " << v.y() * 1e3 << ", "
    << v.z() * 1e3 << ")";
  return s.str();
}

nlohmann::json json_vec(const Vec3& v, double scale) {
  return nlohmann::json::array({v.x() * scale, v.y() * scale, v.z() * scale});
}

void run_distributed(const FemCommandOptions& o, const TetMesh& mesh,
                     const fem::ElasticityProblem& problem, const std::string& bc,
                     const TractionPatch* patch, const Vec3& contact_point, double mesh_seconds,
                     bool cache_hit);

/// Discards what is written to it: the non-root ranks' std::cout in a --distributed run.
struct NullBuffer : std::streambuf {
  int overflow(int c) override { return c; }
};

void run(FemCommandOptions& o) {
  // --distributed: MPI lives for this command only (the serial program never initialises it
  // unless CG-AMG needs Trilinos); rank 0 meshes and prints, every rank solves its part.
  std::unique_ptr<fem::MpiSession> mpi;
  static NullBuffer null_buffer;
  if (o.distributed) {
    if (o.modes > 0) throw InputError("--modes is serial only: drop it or --distributed");
    if (o.transient) throw InputError("--transient is serial only: drop it or --distributed");
    mpi = std::make_unique<fem::MpiSession>();
    if (mpi->rank() != 0) std::cout.rdbuf(&null_buffer);
  }
  auto t0 = Clock::now();
  MeshSource source;
  const TetMesh mesh =
      o.distributed
          ? fem::make_mesh_on_rank0([&] { return mesh_vessel(o.vessel, std::cout, &source); })
          : mesh_vessel(o.vessel, std::cout, &source);
  const VesselParams& params = o.vessel.params;
  const double mesh_seconds = since(t0);
  std::cout << "mesh: " << mesh.nodes.size() << " nodes, " << mesh.tets.size() << " tets\n";

  fem::ElasticityProblem problem;
  problem.material = {o.youngs_modulus, o.poisson_ratio, o.density};
  auto& opt = problem.options;
  opt.degree = o.degree;
  opt.formulation = o.formulation == "mixed"          ? fem::Formulation::mixed
                    : o.formulation == "displacement" ? fem::Formulation::displacement
                                                      : fem::Formulation::automatic;
  opt.mixed_threshold = o.mixed_threshold;
  opt.solver = o.solver == "direct"   ? fem::LinearSolver::direct
               : o.solver == "cg-amg" ? fem::LinearSolver::cg_amg
                                      : fem::LinearSolver::automatic;
  opt.direct_max_dofs = o.direct_max_dofs;
  opt.cg_relative_tolerance = o.tolerance;
  opt.max_iterations = o.max_iterations;

  bool has_pressure = false, has_contact = false, has_gravity = false;
  for (const auto& l : o.loads) {
    has_pressure |= l == "pressure";
    has_contact |= l == "contact";
    has_gravity |= l == "gravity";
  }
  Vec3 contact_point(params.inner_radius, 0.0, 0.5 * params.length);
  if (params.kind == VesselKind::arch) {
    // The arch's crown: centreline point (0, R, 0); the inner wall on the side of the bend's
    // centre.
    contact_point = Vec3(0.0, params.bend_radius - params.inner_radius, 0.0);
  }
  if (!o.contact_point.empty()) contact_point = to_vec3(o.contact_point, "--contact-point");
  if (o.contact_point.empty() && o.contact_surface == group_names::outer_wall) {
    contact_point = params.kind == VesselKind::straight
                        ? Vec3(params.outer_radius(), 0.0, 0.5 * params.length)
                        : Vec3(0.0, params.bend_radius + params.outer_radius(), 0.0);
  }
  TractionPatch patch;
  if (has_pressure) problem.pressures.push_back({std::string(group_names::inner_wall), o.pressure});
  if (has_contact) {
    ContactPatchSpec spec;
    spec.point = contact_point;
    spec.radius = o.contact_radius;
    spec.force = o.force;
    spec.surface_group = o.contact_surface;
    patch = contact_patch(mesh, spec);
    problem.patches.push_back(patch);
    std::cout << "contact patch: " << patch.triangles.size() << " triangles of '"
              << o.contact_surface << "', area " << patch.area * 1e6 << " mm² (disc "
              << std::numbers::pi * o.contact_radius * o.contact_radius * 1e6 << " mm²), traction "
              << patch.traction.norm() << " Pa\n";
  }
  if (has_gravity) problem.gravity = to_vec3(o.gravity, "--gravity");
  if (o.curved) {
    if (params.kind != VesselKind::straight) {
      throw InputError(
          "--curved is available for the straight tube only (its walls are cylinders)");
    }
    problem.curved_surfaces = fem::tube_curved_walls(params.inner_radius, params.outer_radius());
  }

  // Ends: roller (u_z = 0, plane strain, plus three in-plane pins) or clamped.
  std::string bc = o.bc;
  if (bc == "auto") bc = (has_pressure && !has_contact && !has_gravity) ? "roller" : "clamped";
  if (bc == "roller") {
    if (params.kind != VesselKind::straight) {
      throw InputError(
          "--bc roller (u_z = 0 on the end faces) needs the straight tube; the arch's "
          "ends are not normal to z: use --bc clamped");
    }
    problem.dirichlet = {fem::DirichletCondition::roller("inlet", 2),
                         fem::DirichletCondition::roller("outlet", 2)};
    problem.point_constraints = fem::tube_in_plane_pins(params.inner_radius, 0.0);
  } else if (bc == "clamped") {
    problem.dirichlet = {fem::DirichletCondition::clamped("inlet"),
                         fem::DirichletCondition::clamped("outlet")};
  } else if (bc == "clamped-inlet") {
    problem.dirichlet = {fem::DirichletCondition::clamped("inlet")};
  }
  std::cout << std::setprecision(6) << "material: E " << o.youngs_modulus << " Pa, nu "
            << o.poisson_ratio << ", rho " << o.density << " kg/m³; ends: " << bc << "\n";
  if (o.distributed) {
    run_distributed(o, mesh, problem, bc, has_contact ? &patch : nullptr, contact_point,
                    mesh_seconds, source.cache_hit);
    return;
  }

  fem::ElasticitySolver solver(mesh, problem);
  const auto& pre = solver.result();
  std::cout << "element " << pre.element << (pre.curved ? " on curved walls" : "") << ": "
            << pre.n_dofs << " DoFs";
  if (pre.n_pressure_dofs) std::cout << " (" << pre.n_pressure_dofs << " pressure)";
  std::cout << "\nsolving ..." << std::flush;
  const auto& r = solver.solve();
  std::cout << " " << fem::to_string(r.solver);
  if (r.solver == fem::LinearSolver::cg_amg) std::cout << ", " << r.iterations << " CG iterations";
  std::cout << "\n";

  Vec3 u_contact = Vec3::Zero();
  const bool have_contact_u = has_contact;
  if (have_contact_u) u_contact = solver.displacement_at({contact_point})[0];
  double max_u = 0.0;
  for (const auto& u : r.nodal_displacement) max_u = std::max(max_u, u.norm());

  fem::ModalResult modal;
  if (o.modes > 0) {
    std::cout << "modal analysis: lowest " << o.modes << " natural frequencies ..." << std::flush;
    modal = solver.modes(o.modes);
    std::cout << " " << std::fixed << std::setprecision(3) << modal.seconds << " s"
              << std::defaultfloat << "\n  f (Hz):" << std::setprecision(6);
    for (double f : modal.frequencies_hz) std::cout << " " << f;
    std::cout << "\n";
  }

  // The step response at the contact point (the probe): Newmark average acceleration.
  fem::TransientResult tr;
  if (o.transient) {
    fem::TransientOptions to;
    to.dt = o.dt;
    to.steps = o.steps;
    to.mass_damping = o.mass_damping;
    to.probe_points = {contact_point};
    std::cout << "transient (Newmark average acceleration, step load at t = 0): " << o.steps
              << " steps of " << o.dt << " s, mass damping " << o.mass_damping << " 1/s ..."
              << std::flush;
    tr = solver.transient(to);
    const Vec3 u_static = solver.displacement_at({contact_point})[0];
    const Vec3 dir = has_contact ? Vec3(-patch.outward_normal)
                                 : (u_static.norm() > 0 ? Vec3(u_static.normalized())
                                                        : Vec3(1.0, 0.0, 0.0));
    std::cout << std::fixed << std::setprecision(3) << " setup " << tr.setup_seconds << " s, "
              << tr.seconds_per_step * 1e3 << " ms/step" << std::defaultfloat << "\n";
    std::cout << std::setprecision(3) << "  probe " << mm(contact_point) << " mm, displacement along ("
              << dir.x() << ", " << dir.y() << ", " << dir.z() << "), static "
              << u_static.dot(dir) * 1e3 << " mm:\n"
              << std::setprecision(6);
    const std::size_t rows = std::min<std::size_t>(20, tr.time.size() - 1);
    double peak = 0.0, sum = 0.0;
    for (std::size_t n = 0; n < tr.time.size(); ++n) {
      const double u = tr.probe_displacement[n][0].dot(dir);
      peak = std::max(peak, std::abs(u));
      if (n > 0) sum += u;
    }
    std::cout << "    t (ms)      u (mm)        |u| (mm)\n";
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
      write_file_atomically(o.history_csv, [&](std::ostream& out) {
        out << "t_s,ux_mm,uy_mm,uz_mm,kinetic_energy_mJ,strain_energy_mJ,load_work_mJ\n";
        out << std::setprecision(12);
        for (std::size_t n = 0; n < tr.time.size(); ++n) {
          const Vec3& u = tr.probe_displacement[n][0];
          out << tr.time[n] << "," << u.x() * 1e3 << "," << u.y() * 1e3 << "," << u.z() * 1e3
              << "," << tr.kinetic_energy[n] * 1e3 << "," << tr.strain_energy[n] * 1e3 << ","
              << tr.load_work[n] * 1e3 << "\n";
        }
      });
      std::cout << "wrote " << o.history_csv.string() << "\n";
    }
  }

  t0 = Clock::now();
  if (!o.vtu.empty()) {
    VtuField disp{"displacement", 3, {}}, strain{"strain", 6, {}}, stress{"stress", 6, {}};
    for (const auto& u : r.nodal_displacement)
      disp.values.insert(disp.values.end(), {u.x(), u.y(), u.z()});
    for (const auto& e : r.tet_strain)
      strain.values.insert(strain.values.end(), e.begin(), e.end());
    for (const auto& s : r.tet_stress)
      stress.values.insert(stress.values.end(), s.begin(), s.end());
    std::vector<VtuField> point_fields{disp};
    for (std::size_t k = 0; k < modal.mode_shapes.size(); ++k) {
      VtuField mode{"mode_" + std::to_string(k + 1), 3, {}};
      for (const auto& u : modal.mode_shapes[k])
        mode.values.insert(mode.values.end(), {u.x(), u.y(), u.z()});
      point_fields.push_back(std::move(mode));
    }
    write_vtu(o.vtu, mesh, point_fields, {strain, stress});
  }
  const double output_seconds = since(t0);

  std::cout << std::setprecision(6);
  std::cout << "results (mm, mN, mJ):\n";
  std::cout << "  max |u|                 " << max_u * 1e3 << " mm\n";
  if (have_contact_u) {
    std::cout << "  u at contact point      " << mm(u_contact) << " mm, along the patch normal "
              << u_contact.dot(-patch.outward_normal) * 1e3 << " mm\n";
  }
  std::cout << "  strain energy           " << r.strain_energy * 1e3 << " mJ\n";
  std::cout << "  max principal strain    " << r.max_principal_strain << " (max |eigenvalue| "
            << r.max_abs_principal_strain << ")\n";
  if (r.max_abs_principal_strain > 0.05) {
    std::cout << "  WARNING: strain above 5 %: outside the linear reference's validity\n";
  }
  double lame_error = -1.0;
  if (bc == "roller" && has_pressure && !has_contact && !has_gravity) {
    // The Lamé set-up: compare with the closed form (plane strain is exact with roller ends).
    const fem::LameCylinder lame{params.inner_radius, params.outer_radius(), o.pressure,
                                 o.youngs_modulus, o.poisson_ratio};
    lame_error = solver.relative_l2_error([&](const Vec3& x) { return lame.displacement(x); });
    std::cout << "  Lamé closed form        u_r(a) "
              << lame.radial_displacement(params.inner_radius) * 1e3 << " mm, u_r(b) "
              << lame.radial_displacement(params.outer_radius()) * 1e3
              << " mm; FEM relative L2 error " << lame_error << "\n";
  }
  std::cout << "  applied load            " << mm(r.applied_load) << " mN\n";
  Vec3 reaction_sum = Vec3::Zero();
  for (const auto& g : r.reactions) {
    std::cout << "  reaction on " << std::left << std::setw(12) << g.group << std::right
              << mm(g.force) << " mN\n";
    reaction_sum += g.force;
  }
  std::cout << "  |applied + reactions|   " << (r.applied_load + reaction_sum).norm() * 1e3
            << " mN (equilibrium)\n";
  std::cout << std::fixed << std::setprecision(3) << "timings (s): mesh " << mesh_seconds
            << ", setup " << r.timings.setup << ", assembly " << r.timings.assembly << ", solve "
            << r.timings.solve << ", postprocess " << r.timings.postprocess << ", output "
            << output_seconds << std::defaultfloat << "\n";
  if (!o.vtu.empty()) std::cout << "wrote " << o.vtu.string() << "\n";

  if (!o.json.empty()) {
    nlohmann::json reactions = nlohmann::json::array();
    for (const auto& g : r.reactions)
      reactions.push_back({{"group", g.group}, {"force_mN", json_vec(g.force, 1e3)}});
    nlohmann::json j{
        {"schema", "vesselverify.fem"},
        {"schema_version", 1},
        {"units", {{"length", "mm"}, {"force", "mN"}, {"energy", "mJ"}, {"time", "s"}}},
        {"vessel", describe(params)},
        {"mesh",
         {{"nodes", mesh.nodes.size()},
          {"tets", mesh.tets.size()},
          {"cache_hit", source.cache_hit}}},
        {"material",
         {{"E_Pa", o.youngs_modulus}, {"nu", o.poisson_ratio}, {"density_kg_m3", o.density}}},
        {"loads", o.loads},
        {"ends", bc},
        {"element", r.element},
        {"curved", r.curved},
        {"formulation", fem::to_string(r.formulation)},
        {"solver", fem::to_string(r.solver)},
        {"cg_iterations", r.iterations},
        {"dofs", r.n_dofs},
        {"pressure_dofs", r.n_pressure_dofs},
        {"max_displacement_mm", max_u * 1e3},
        {"strain_energy_mJ", r.strain_energy * 1e3},
        {"max_principal_strain", r.max_principal_strain},
        {"max_abs_principal_strain", r.max_abs_principal_strain},
        {"applied_load_mN", json_vec(r.applied_load, 1e3)},
        {"reactions", reactions},
        {"timings_s",
         {{"mesh", mesh_seconds},
          {"setup", r.timings.setup},
          {"assembly", r.timings.assembly},
          {"solve", r.timings.solve},
          {"postprocess", r.timings.postprocess},
          {"output", output_seconds}}}};
    if (lame_error >= 0.0) j["lame_relative_l2_error"] = lame_error;
    if (o.modes > 0) {
      j["modal"] = {{"frequencies_hz", modal.frequencies_hz},
                    {"dofs", modal.n_dofs},
                    {"seconds", modal.seconds}};
    }
    if (o.transient) {
      j["transient"] = {{"dt_s", o.dt},
                        {"steps", o.steps},
                        {"mass_damping_per_s", o.mass_damping},
                        {"probe_mm", json_vec(contact_point, 1e3)},
                        {"final_probe_displacement_mm",
                         json_vec(tr.probe_displacement.back()[0], 1e3)},
                        {"setup_seconds", tr.setup_seconds},
                        {"seconds_per_step", tr.seconds_per_step}};
    }
    if (have_contact_u) {
      j["contact"] = {{"point_mm", json_vec(contact_point, 1e3)},
                      {"radius_mm", o.contact_radius * 1e3},
                      {"force_mN", o.force * 1e3},
                      {"patch_area_mm2", patch.area * 1e6},
                      {"patch_triangles", patch.triangles.size()},
                      {"displacement_mm", json_vec(u_contact, 1e3)}};
    }
    write_file_atomically(o.json, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
    std::cout << "wrote " << o.json.string() << "\n";
  }
}

/// The --distributed path: the same problem solved over the MPI ranks (fem::
/// solve_elasticity_distributed); every rank solves, rank 0 prints and writes the files.
void run_distributed(const FemCommandOptions& o, const TetMesh& mesh,
                     const fem::ElasticityProblem& problem, const std::string& bc,
                     const TractionPatch* patch, const Vec3& contact_point, double mesh_seconds,
                     bool cache_hit) {
  fem::DistributedOptions dopt;
  if (patch) dopt.evaluation_points = {contact_point};
  std::cout << "solving distributed ..." << std::flush;
  const auto d = fem::solve_elasticity_distributed(mesh, problem, dopt);
  const auto& r = d.fem;
  std::cout << " " << d.n_ranks << " MPI rank(s)\n";
  std::cout << "element " << r.element << ": " << r.n_dofs << " DoFs; cg-amg, " << r.iterations
            << " CG iterations\n  per rank: tets";
  for (auto c : d.cells_per_rank) std::cout << " " << c;
  std::cout << "; DoFs";
  for (auto c : d.dofs_per_rank) std::cout << " " << c;
  std::cout << "\n";
  double max_u = 0.0;
  for (const auto& u : r.nodal_displacement) max_u = std::max(max_u, u.norm());
  const Vec3 u_contact = patch ? d.point_displacement.at(0) : Vec3::Zero();

  auto t0 = Clock::now();
  if (!o.vtu.empty() && !r.nodal_displacement.empty()) {
    // Nodal displacement only: the per-tet strain and stress stay on their ranks.
    VtuField disp{"displacement", 3, {}};
    for (const auto& u : r.nodal_displacement)
      disp.values.insert(disp.values.end(), {u.x(), u.y(), u.z()});
    write_vtu(o.vtu, mesh, {disp}, {});
  }
  const double output_seconds = since(t0);

  std::cout << std::setprecision(6) << "results (mm, mN, mJ):\n";
  std::cout << "  max |u|                 " << max_u * 1e3 << " mm (at the mesh nodes)\n";
  if (patch) {
    std::cout << "  u at contact point      " << mm(u_contact) << " mm, along the patch normal "
              << u_contact.dot(-patch->outward_normal) * 1e3 << " mm\n";
  }
  std::cout << "  strain energy           " << r.strain_energy * 1e3 << " mJ\n";
  std::cout << "  max principal strain    " << r.max_principal_strain << " (max |eigenvalue| "
            << r.max_abs_principal_strain << ")\n";
  if (r.max_abs_principal_strain > 0.05) {
    std::cout << "  WARNING: strain above 5 %: outside the linear reference's validity\n";
  }
  std::cout << "  applied load            " << mm(r.applied_load) << " mN\n";
  Vec3 reaction_sum = Vec3::Zero();
  for (const auto& g : r.reactions) {
    std::cout << "  reaction on " << std::left << std::setw(12) << g.group << std::right
              << mm(g.force) << " mN\n";
    reaction_sum += g.force;
  }
  std::cout << "  |applied + reactions|   " << (r.applied_load + reaction_sum).norm() * 1e3
            << " mN (equilibrium)\n";
  std::cout << std::fixed << std::setprecision(3) << "timings (s, slowest rank): mesh "
            << mesh_seconds << ", setup " << r.timings.setup << ", assembly " << r.timings.assembly
            << ", solve " << r.timings.solve << ", postprocess " << r.timings.postprocess
            << ", output " << output_seconds << std::defaultfloat << "\n";
  if (!o.vtu.empty()) std::cout << "wrote " << o.vtu.string() << "\n";

  if (!o.json.empty() && !r.nodal_displacement.empty()) {  // rank 0 only
    nlohmann::json reactions = nlohmann::json::array();
    for (const auto& g : r.reactions)
      reactions.push_back({{"group", g.group}, {"force_mN", json_vec(g.force, 1e3)}});
    nlohmann::json j{
        {"schema", "vesselverify.fem"},
        {"schema_version", 1},
        {"units", {{"length", "mm"}, {"force", "mN"}, {"energy", "mJ"}, {"time", "s"}}},
        {"vessel", describe(o.vessel.params)},
        {"mesh",
         {{"nodes", mesh.nodes.size()}, {"tets", mesh.tets.size()}, {"cache_hit", cache_hit}}},
        {"material",
         {{"E_Pa", o.youngs_modulus}, {"nu", o.poisson_ratio}, {"density_kg_m3", o.density}}},
        {"loads", o.loads},
        {"ends", bc},
        {"element", r.element},
        {"curved", false},
        {"formulation", fem::to_string(r.formulation)},
        {"solver", fem::to_string(r.solver)},
        {"cg_iterations", r.iterations},
        {"dofs", r.n_dofs},
        {"pressure_dofs", 0},
        {"distributed",
         {{"mpi_ranks", d.n_ranks},
          {"tets_per_rank", d.cells_per_rank},
          {"dofs_per_rank", d.dofs_per_rank}}},
        {"max_displacement_mm", max_u * 1e3},
        {"strain_energy_mJ", r.strain_energy * 1e3},
        {"max_principal_strain", r.max_principal_strain},
        {"max_abs_principal_strain", r.max_abs_principal_strain},
        {"applied_load_mN", json_vec(r.applied_load, 1e3)},
        {"reactions", reactions},
        {"timings_s",
         {{"mesh", mesh_seconds},
          {"setup", r.timings.setup},
          {"assembly", r.timings.assembly},
          {"solve", r.timings.solve},
          {"postprocess", r.timings.postprocess},
          {"output", output_seconds}}}};
    if (patch) {
      j["contact"] = {{"point_mm", json_vec(contact_point, 1e3)},
                      {"radius_mm", o.contact_radius * 1e3},
                      {"force_mN", o.force * 1e3},
                      {"patch_area_mm2", patch->area * 1e6},
                      {"patch_triangles", patch->triangles.size()},
                      {"displacement_mm", json_vec(u_contact, 1e3)}};
    }
    write_file_atomically(o.json, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
    std::cout << "wrote " << o.json.string() << "\n";
  }
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
      "  vesselverify fem --degree 2 --bc clamped-inlet --modes 10   # natural frequencies\n"
      "  vesselverify fem --degree 2 --level 2 --solver cg-amg\n"
      "  vesselverify fem --load contact --degree 2 --transient --dt 1e-4 --steps 200 "
      "--history-csv h.csv\n"
      "  mpirun -np 2 vesselverify fem --distributed --degree 2 --level 1 --load contact");
  add_vessel_options(*cmd, o->vessel);
  cmd->add_option("--degree", o->degree, "Displacement element degree (1 or 2)")
      ->check(CLI::IsMember({1, 2}))
      ->capture_default_str();
  cmd->add_option("--E", o->youngs_modulus, "Young's modulus, Pa")->capture_default_str();
  cmd->add_option("--nu", o->poisson_ratio, "Poisson's ratio, 0..0.5")->capture_default_str();
  cmd->add_option("--density", o->density, "Density, kg/m³")->capture_default_str();
  cmd->add_option("--formulation", o->formulation,
                  "auto (mixed when nu >= --mixed-threshold), displacement, or mixed (P2-P1)")
      ->check(CLI::IsMember({"auto", "displacement", "mixed"}))
      ->capture_default_str();
  cmd->add_option("--mixed-threshold", o->mixed_threshold,
                  "auto: mixed formulation when nu >= this")
      ->capture_default_str();
  cmd->add_option("--load", o->loads, "Load(s): pressure, contact, gravity (repeatable)")
      ->check(CLI::IsMember({"pressure", "contact", "gravity"}))
      ->capture_default_str();
  cmd->add_option("--pressure", o->pressure, "Internal pressure on inner_wall, Pa")
      ->capture_default_str();
  cmd->add_option("--force", o->force, "Contact force, N (pushes into the wall)")
      ->capture_default_str();
  cmd->add_option("--contact-point", o->contact_point,
                  "Contact point x y z, metres (default: mid-length on the chosen wall at +x)")
      ->expected(3);
  cmd->add_option("--contact-radius", o->contact_radius, "Contact patch radius, metres")
      ->capture_default_str();
  cmd->add_option("--contact-surface", o->contact_surface, "Surface group the contact acts on")
      ->check(CLI::IsMember({"inner_wall", "outer_wall"}))
      ->capture_default_str();
  cmd->add_option("--gravity", o->gravity, "Gravity vector gx gy gz, m/s²")
      ->expected(3)
      ->capture_default_str();
  cmd->add_option("--bc", o->bc, "End conditions: auto, roller, clamped, clamped-inlet")
      ->check(CLI::IsMember({"auto", "roller", "clamped", "clamped-inlet"}))
      ->capture_default_str();
  cmd->add_option("--solver", o->solver,
                  "Linear solver: auto (direct up to --direct-max-dofs, else CG with algebraic "
                  "multigrid), direct (CHOLMOD; UMFPACK for the mixed system), cg-amg (Trilinos ML)")
      ->check(CLI::IsMember({"auto", "direct", "cg-amg"}))
      ->capture_default_str();
  cmd->add_option("--direct-max-dofs", o->direct_max_dofs,
                  "auto: direct solver up to this many DoFs")
      ->capture_default_str();
  cmd->add_option("--tolerance", o->tolerance, "CG relative residual tolerance")
      ->capture_default_str();
  cmd->add_option("--max-iterations", o->max_iterations, "CG iteration limit")
      ->capture_default_str();
  cmd->add_flag("--curved", o->curved,
                "Quadratic elements: put the P2 geometry nodes on the exact cylinders (straight "
                "tube), so the wall is curved (O(h³) geometry instead of straight-sided O(h²))");
  cmd->add_option("--modes", o->modes,
                  "Also compute this many lowest natural frequencies and mode shapes (consistent "
                  "mass, on the same end conditions; e.g. 10)")
      ->check(CLI::Range(0, 100));
  cmd->add_flag(
      "--distributed", o->distributed,
      "Solve in parallel over the MPI ranks (run under 'mpirun -np N'): fully distributed "
      "mesh, Trilinos CG with ML AMG; P1/P2 displacement formulation only (no mixed, "
      "--curved, --modes or --transient). Rank 0 prints and writes the files; --vtu gets the "
      "nodal displacement only");
  cmd->add_flag("--transient", o->transient,
                "Also run the step response: the loads applied at t = 0 to the body at rest, "
                "Newmark average acceleration with the consistent mass; prints the contact "
                "point's displacement over time (sampled) and the timings");
  cmd->add_option("--dt", o->dt, "Transient time step, s")->capture_default_str();
  cmd->add_option("--steps", o->steps, "Transient number of steps")->capture_default_str();
  cmd->add_option("--mass-damping", o->mass_damping,
                  "Transient mass-proportional damping alpha (C = alpha M), 1/s")
      ->capture_default_str();
  cmd->add_option("--history-csv", o->history_csv,
                  "Transient: write the contact point's displacement (mm) and the energies (mJ) "
                  "at every step as CSV");
  cmd->add_option("--vtu", o->vtu,
                  "Write displacement and mode shapes (nodes), strain and stress (tets) as VTU");
  cmd->add_option("--json", o->json, "Write a JSON summary");
  cmd->callback([o] { run(*o); });
}

}  // namespace vessel::cli
