#include "verification/scene_problems.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "meshes/foundation/errors.hpp"
#include "meshes/mesh_cache.hpp"
#include "msm/fem/corotational_tet.hpp"
#include "msm/fem/stable_neo_hookean.hpp"
#include "msm/formats/network_file.hpp"
#include "msm/terms/edge_pair_term.hpp"
#include "msm/terms/spring_model.hpp"
#include "verification/calibration_file.hpp"
#include "verification/guidewire/guidewire_load.hpp"

namespace vessel {

Vec3 default_contact_point(const VesselParams& v, const std::string& surface_group) {
  if (!v.parametric()) {
    throw InputError(describe(v) + ": no default contact point on a vessel from a file; expected "
                     "the point to be given (it is moved onto the wall)");
  }
  const double r = surface_group == group_names::outer_wall ? v.outer_radius() : v.inner_radius;
  if (v.kind == VesselKind::straight) return {r, 0.0, 0.5 * v.length};
  return {0.0, v.bend_radius + r, 0.0};
}

namespace {

/// A guidewire load has its point and magnitude only once solved (solve_guidewire_load); a
/// problem built before that would put the load nowhere.
void require_solved(const LoadSpec& load) {
  if (load.guidewire && !load.wire) {
    throw std::logic_error(
        "the scene's guidewire is not solved yet: call solve_guidewire_load "
        "(verification/scene_problems.hpp) before building its problems");
  }
}

}  // namespace

Vec3 qoi_point(const Scene& s) {
  require_solved(s.load);
  if (s.load.kind == LoadKind::contact || !s.vessel.parametric()) return s.load.contact.point;
  return default_contact_point(s.vessel, std::string(group_names::inner_wall));
}

std::size_t nearest_node(const std::vector<Vec3>& nodes, const Vec3& point) {
  std::size_t best = 0;
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const double di = (nodes[i] - point).squaredNorm();
    if (di < d) {
      d = di;
      best = i;
    }
  }
  return best;
}

TetMesh scene_mesh(const Scene& s, int level, const std::filesystem::path& cache_dir) {
  VesselParams p = s.vessel;
  p.level = level;
  return load_or_generate_vessel(p, cache_dir, {});
}

Scene resolve_file_vessel(Scene s, const TetMesh& mesh) {
  if (s.vessel.parametric()) return s;
  const std::string source = s.source.string() + ": " + describe(s.vessel);
  const auto project = [&](LoadSpec& l) {
    l.contact.point = nearest_point_on_group(mesh, l.contact.surface_group, l.contact.point, source);
  };
  if (s.load.kind == LoadKind::contact) {
    project(s.load);
  } else {
    Vec3 centroid = Vec3::Zero();
    for (const Vec3& x : mesh.nodes) centroid += x;
    centroid /= static_cast<double>(mesh.nodes.size());
    s.load.contact.point =
        nearest_point_on_group(mesh, std::string(group_names::inner_wall), centroid, source);
  }
  for (LoadSpec& l : s.constant_loads) {
    if (l.kind == LoadKind::contact) project(l);
  }
  return s;
}

Supports scene_supports(const Scene& s) {
  return end_supports(s.vessel, s.boundary, s.source.string());
}

TractionPatch scene_contact_patch(const LoadSpec& load, const TetMesh& mesh, double force) {
  require_solved(load);
  ContactPatchSpec spec = load.contact;
  spec.force = force;
  return contact_patch(mesh, spec);
}

namespace {

/// The swept load at `magnitude`, then each constant load at its own; loads of magnitude 0 are
/// left out (nothing is built for an absent load).
std::vector<std::pair<const LoadSpec*, double>> applied_loads(const Scene& s, double magnitude) {
  std::vector<std::pair<const LoadSpec*, double>> out;
  if (magnitude != 0.0) out.emplace_back(&s.load, magnitude);
  for (const LoadSpec& l : s.constant_loads) {
    if (!l.magnitudes.empty() && l.magnitudes.front() != 0.0) {
      out.emplace_back(&l, l.magnitudes.front());
    }
  }
  return out;
}

void add_fem_supports(const Scene& s, fem::ElasticityProblem& prob) {
  const Supports supports = scene_supports(s);
  if (supports.holds_nothing()) {
    throw InputError(s.source.string() +
                     ": [boundary] leaves both ends free; expected at least one clamped or roller "
                     "end (a free body has rigid motions and no static answer)");
  }
  for (const auto& g : supports.clamped) {
    prob.dirichlet.push_back(fem::DirichletCondition::clamped(g));
  }
  for (const auto& g : supports.rollers) {
    prob.dirichlet.push_back(fem::DirichletCondition::roller(g, Supports::kRollerComponent));
  }
  prob.point_constraints.insert(prob.point_constraints.end(), supports.pins.begin(),
                                supports.pins.end());
}

}  // namespace

fem::ElasticityProblem wall_problem(const Scene& s, double nu, int degree) {
  fem::ElasticityProblem prob;
  prob.material.youngs_modulus = s.youngs_modulus;
  prob.material.poisson_ratio = nu;
  prob.material.density = s.density;
  prob.options.degree = degree;
  add_fem_supports(s, prob);
  return prob;
}

fem::ElasticityProblem fem_problem(const Scene& s, const TetMesh& mesh, double nu, int degree,
                                   double magnitude) {
  fem::ElasticityProblem prob = wall_problem(s, nu, degree);
  for (const auto& [load, m] : applied_loads(s, magnitude)) {
    switch (load->kind) {
      case LoadKind::contact:
        prob.patches.push_back(scene_contact_patch(*load, mesh, m));
        break;
      case LoadKind::pressure:
        prob.pressures.push_back({load->contact.surface_group, m});
        break;
      case LoadKind::gravity:
        prob.gravity += m * kStandardGravity * load->gravity_direction;
        break;
    }
  }
  return prob;
}

msm::NetworkOptions network_options(const Scene& s, const ModelSpec& model, double nu) {
  msm::NetworkOptions o;
  o.model = model.kind == ModelKind::volume_msm ? msm::ModelType::volume : msm::ModelType::surface;
  o.surface = model.surface;
  o.topology = model.topology;
  o.stiffness = model.stiffness;
  o.volume_term = model.volume_term;
  o.volume_moduli = model.volume_moduli;
  o.bending = model.bending;
  o.edge_pairs = model.edge_pairs;
  o.stiffness_params.youngs_modulus = s.youngs_modulus;
  o.stiffness_params.poisson_ratio = nu;
  o.mass = model.mass;
  o.density = s.density;
  return o;
}

msm::BuiltNetwork scene_network(const Scene& s, const ModelSpec& model, const TetMesh& mesh,
                                const VesselParams& vessel, double nu) {
  if (model.kind == ModelKind::network) {
    const std::string source = model.network_file.string();
    return msm::network_on_mesh(msm::read_network_file(model.network_file), mesh, source);
  }
  VesselParams v = vessel;
  if (v.kind == VesselKind::mesh_file && v.wall_thickness <= 0.0) {
    v.wall_thickness = estimate_wall_thickness(mesh, v.file.string());
  }
  msm::BuiltNetwork built = msm::build_network(mesh, v, network_options(s, model, nu));
  if (!model.calibration.empty()) {
    const std::string source = s.source.string() + ": model " + model.name + ": calibration " +
                               model.calibration.string();
    apply_calibration(read_calibration(model.calibration), source, built, mesh, v, model,
                      s.youngs_modulus, nu, model.calibration_transfer);
  }
  return built;
}

std::vector<Vec3> surface_nodal_loads(const Scene& s, const TetMesh& mesh, double magnitude) {
  std::vector<Vec3> loads(mesh.nodes.size(), Vec3::Zero());
  for (const auto& [load, m] : applied_loads(s, magnitude)) {
    std::vector<Vec3> f;
    if (load->kind == LoadKind::contact) {
      f = traction_nodal_loads(mesh, scene_contact_patch(*load, mesh, m));
    } else if (load->kind == LoadKind::pressure) {
      f = pressure_nodal_loads(mesh, load->contact.surface_group, m);
    }
    for (std::size_t i = 0; i < f.size(); ++i) loads[i] += f[i];
  }
  return loads;
}

std::vector<char> file_network_held_dofs(const Scene& s, const TetMesh& mesh,
                                         const msm::BuiltNetwork& built) {
  const msm::NetworkSupports& file = *built.file_supports;
  const auto& follow = file.follow_groups;
  const auto followed = [&](const std::string& g) {
    return std::find(follow.begin(), follow.end(), g) != follow.end();
  };
  Supports supports = scene_supports(s);
  std::erase_if(supports.clamped, [&](const std::string& g) { return !followed(g); });
  std::erase_if(supports.rollers, [&](const std::string& g) { return !followed(g); });
  if (supports.rollers.empty()) supports.pins.clear();
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& x : mesh.nodes) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const double tolerance = msm::kNodeMatchTolerance * (hi - lo).norm();
  std::vector<char> held;
  try {
    held = held_dofs_by_position(mesh, built.network.nodes, supports, tolerance);
  } catch (const InputError& e) {
    throw InputError(built.file + ": follow_groups: " + e.what());
  }
  for (const int i : file.fixed_nodes) {
    for (int c = 0; c < 3; ++c) held[3 * static_cast<std::size_t>(i) + c] = 1;
  }
  if (std::find(held.begin(), held.end(), 1) == held.end()) {
    std::string groups;
    for (const auto& g : follow) groups += (groups.empty() ? "" : ", ") + g;
    throw InputError(built.file + ": no node of the network is held: fixed.nodes is empty and "
                     "follow_groups [" + groups + "] hold no node under the scene's [boundary] "
                     "(a node follows a group when it lies on the group's surface); expected "
                     "fixed nodes, or nodes on a clamped or roller end");
  }
  return held;
}

msm::Problem msm_problem(const Scene& s, const msm::Form& form, const msm::BuiltNetwork& built,
                         const TetMesh& mesh, double magnitude) {
  msm::Problem problem = msm::make_problem(form, built.network, built.masses, mesh,
                                           surface_nodal_loads(s, mesh, magnitude), {});
  Vec3 g = Vec3::Zero();
  for (const auto& [load, m] : applied_loads(s, magnitude)) {
    if (load->kind == LoadKind::gravity) g += m * kStandardGravity * load->gravity_direction;
  }
  for (Eigen::Index i = 0; i < problem.num_dofs(); i += 3) {
    problem.external_force.segment<3>(i) += problem.mass[i] * g;
  }
  problem.fixed = built.file_supports
                      ? file_network_held_dofs(s, mesh, built)
                      : held_dofs(mesh, built.network.nodes, built.network.source_node,
                                  scene_supports(s));
  return problem;
}

msm::Problem tet_mesh_problem(const Scene& s, const msm::TetTerm& term, const TetMesh& mesh,
                              double magnitude) {
  msm::Problem p;
  p.form = &term;
  const auto n = static_cast<Eigen::Index>(mesh.nodes.size());
  p.rest.resize(3 * n);
  p.external_force.resize(3 * n);
  const std::vector<Vec3> loads = surface_nodal_loads(s, mesh, magnitude);
  for (Eigen::Index i = 0; i < n; ++i) {
    p.rest.segment<3>(3 * i) = mesh.nodes[static_cast<std::size_t>(i)];
    p.external_force.segment<3>(3 * i) = loads[static_cast<std::size_t>(i)];
  }
  p.mass = Eigen::VectorXd::Zero(3 * n);
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    for (const int v : mesh.tets[e]) {
      p.mass.segment<3>(3 * v).array() += s.density * term.rest_shapes()[e].volume / 4.0;
    }
  }
  Vec3 g = Vec3::Zero();
  for (const auto& [load, m] : applied_loads(s, magnitude)) {
    if (load->kind == LoadKind::gravity) g += m * kStandardGravity * load->gravity_direction;
  }
  for (Eigen::Index i = 0; i < 3 * n; i += 3) p.external_force.segment<3>(i) += p.mass[i] * g;
  std::vector<int> source(mesh.nodes.size());
  for (std::size_t i = 0; i < source.size(); ++i) source[i] = static_cast<int>(i);
  p.fixed = held_dofs(mesh, mesh.nodes, source, scene_supports(s));
  return p;
}

void solve_guidewire_load(Scene& scene) {
  LoadSpec& load = scene.load;
  if (!load.guidewire || load.wire) return;
  const std::string file = scene.source.string();
  GuidewireSolution wire;
  try {
    GuidewireSolver solver(scene.vessel, *load.guidewire);
    wire = solver.solve_rigid();
  } catch (const InputError& e) {
    throw InputError(file + ": " + e.what());
  } catch (const std::runtime_error& e) {
    throw InputError(file + ": load: the guidewire's solve failed: " + e.what());
  }
  if (wire.force <= 0.0) {
    throw InputError(file + ": load.insertion: the wire of " +
                     std::to_string(load.guidewire->insertion) +
                     " m does not reach the wall; expected an insertion that makes it touch");
  }
  load.wire = wire;
  load.magnitudes = {wire.force};
  load.contact.point = wire.wall_point;
  load.contact.direction = wire.normal;  // the wire's push, along the exact lumen's normal
}

std::unique_ptr<msm::TetTerm> tet_fem_term(const ModelSpec& spec, const TetMesh& mesh, double E,
                                           double nu) {
  const msm::LameParameters linear = msm::lame_parameters(E, nu);
  if (spec.kind == ModelKind::corotational_fem) {
    return std::make_unique<msm::CorotationalTetTerm>(mesh.nodes, mesh.tets, linear,
                                                      msm::CorotationalStiffness::consistent);
  }
  if (spec.kind == ModelKind::xpbd_fem) {
    const msm::LameParameters snh{msm::snh_lambda_for_linear(linear), linear.mu};
    return std::make_unique<msm::StableNeoHookeanTerm>(mesh.nodes, mesh.tets, snh);
  }
  throw InputError("model " + spec.name + ": not a P1 tet model (corotational_fem or xpbd_fem)");
}

}  // namespace vessel
