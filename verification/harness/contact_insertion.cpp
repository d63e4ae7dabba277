#include "verification/harness/contact_insertion.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "fem_reference/elasticity.hpp"
#include "meshes/foundation/content_hash.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/foundation/solver_threads.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "msm/rods/der_rod.hpp"
#include "verification/contact/condensed_wall_potential.hpp"
#include "verification/contact/wire_wall_potential.hpp"
#include "verification/contact_models/contact_models.hpp"
#include "verification/contact_models/model_walls.hpp"
#include "verification/guidewire/guidewire_load.hpp"
#include "verification/harness/outcome_cache.hpp"
#include "verification/scene_problems.hpp"

namespace vessel {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Pressed nodes closer than this to another of a zone belong to it.
constexpr double kZoneGap = 1.0e-3;

/// The pressed nodes grouped into zones (single linkage at kZoneGap), each with its force,
/// centroid and extent.
std::vector<ContactZone> contact_zones(const TetMesh& mesh,
                                       const contact::PotentialContactSolution& s) {
  const std::size_t n = s.pressed.size();
  std::vector<int> zone(n, -1);
  int zones = 0;
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (zone[seed] >= 0) continue;
    zone[seed] = zones;
    std::vector<std::size_t> stack{seed};
    while (!stack.empty()) {
      const std::size_t a = stack.back();
      stack.pop_back();
      for (std::size_t b = 0; b < n; ++b) {
        const Vec3& pa = mesh.nodes[static_cast<std::size_t>(s.pressed[a])];
        const Vec3& pb = mesh.nodes[static_cast<std::size_t>(s.pressed[b])];
        if (zone[b] < 0 && (pa - pb).norm() < kZoneGap) {
          zone[b] = zones;
          stack.push_back(b);
        }
      }
    }
    ++zones;
  }
  std::vector<ContactZone> out(static_cast<std::size_t>(zones));
  std::vector<Vec3> total(out.size(), Vec3::Zero());
  std::vector<double> weight(out.size(), 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    const auto z = static_cast<std::size_t>(zone[j]);
    const Vec3& p = mesh.nodes[static_cast<std::size_t>(s.pressed[j])];
    total[z] += s.force[j] * s.direction[j];
    out[z].centroid += s.force[j] * p;
    weight[z] += s.force[j];
    ++out[z].nodes;
    for (std::size_t k = 0; k < n; ++k) {
      if (zone[k] == zone[j]) {
        const Vec3& q = mesh.nodes[static_cast<std::size_t>(s.pressed[k])];
        out[z].extent = std::max(out[z].extent, (p - q).norm());
      }
    }
  }
  for (std::size_t z = 0; z < out.size(); ++z) {
    out[z].force = total[z].norm();
    if (weight[z] > 0.0) out[z].centroid /= weight[z];
  }
  return out;
}

}  // namespace

Eigen::VectorXd fed_through_clamp(const Eigen::VectorXd& x, const msm::rods::RodLayout& layout,
                                  double from_length, const Vec3& tip_push) {
  const int first = layout.first_node, tip = layout.tip_node;
  const auto node = [&](int i) -> Vec3 { return x.segment<3>(3 * i); };
  // Rest arclength from the clamp at the new length; the sections scale with the length.
  const auto arclength = [&](int i) {
    return (layout.rest[static_cast<std::size_t>(i)] - layout.rest[static_cast<std::size_t>(first)])
        .norm();
  };
  const double shrink = from_length / layout.total_length();  // new arclength → old
  Vec3 tangent = (node(tip) - node(tip - 1)).normalized();
  const Vec3 push = tip_push.normalized();  // zero when nothing pushes
  const double into_wall = tangent.dot(push);
  if (into_wall < 0.0) {  // a pressed tip slides along the wall
    const Vec3 along = tangent - into_wall * push;
    if (along.norm() > 1e-6) tangent = along.normalized();
  }
  Eigen::VectorXd out = x;
  int k = first;  // the old edge [k, k + 1] that holds the new node's arclength
  for (int i = first + 1; i <= tip; ++i) {
    const double s = arclength(i);
    while (k < tip && arclength(k + 1) * shrink < s) ++k;
    Vec3 at;
    if (k == tip) {
      at = node(tip) + (s - arclength(tip) * shrink) * tangent;
    } else {
      const double a = arclength(k) * shrink, b = arclength(k + 1) * shrink;
      at = node(k) + (s - a) / (b - a) * (node(k + 1) - node(k));
    }
    out.segment<3>(3 * i) = at;
  }
  return out;
}

namespace {

/// The insertion's wall: deal.II's FEM (the reference) or one of the scene's models on the mesh,
/// with what keeps the model alive.
struct InsertionWall {
  std::unique_ptr<contact::WallPotential> potential;
  /// The potential when it is a linear wall condensed on a band (grown along the insertion).
  contact::CondensedLinearWall* condensed = nullptr;
  std::optional<contact::ModelWall> model;  ///< owns the form a FormWall refers to
  std::string detail;
};

/// A linear wall: condensed on a band of inner-wall nodes around `first_contact` (grown by the
/// solves), or, for a P2 wall (whose contact candidates include its mid-edge nodes, which a band
/// of mesh nodes does not hold) or with options.condense_linear_walls off, the whole wall.
void set_linear_wall(InsertionWall& w, fem::FreeDisplacementSystem system, const TetMesh& mesh,
                     const Vec3& first_contact, bool condense) {
  const bool vertices_only = system.free_index.size() == 3 * system.node_rows.size();  // P1
  if (!condense || !vertices_only) {
    w.potential = std::make_unique<contact::LinearWall>(std::move(system));
    return;
  }
  // The first band: contact-models' first candidates, the inner-wall nodes this near the contact.
  const double radius = contact::ContactModelsOptions{}.band_radius;
  std::vector<int> band;
  for (const int n : mesh.group_nodes(mesh.require_group("inner_wall", 2, "vessel"))) {
    if ((mesh.nodes[static_cast<std::size_t>(n)] - first_contact).norm() < radius) {
      band.push_back(n);
    }
  }
  auto condensed = std::make_unique<contact::CondensedLinearWall>(std::move(system), band);
  w.condensed = condensed.get();
  w.potential = std::move(condensed);
  w.detail += ", condensed on the contact's band";
}

InsertionWall make_wall(const Scene& scene, const TetMesh& mesh, const Vec3& first_contact,
                        const ContactInsertionOptions& o) {
  const double nu = scene.poisson_ratios.front();
  InsertionWall w;
  if (o.model.empty()) {
    const fem::ElasticityProblem problem = wall_problem(scene, nu, o.degree);
    w.detail = "FEM P" + std::to_string(o.degree) + " (deal.II), " + to_string(o.wall);
    if (o.wall == ContactWall::neo_hookean) {
      w.potential = std::make_unique<contact::NeoHookeanWall>(mesh, problem);
    } else {
      const fem::ElasticitySolver solver(mesh, problem);
      fem::FreeDisplacementSystem system = solver.free_displacement_system();
      if (o.degree > 1) solver.set_row_points(system);  // its mid-edge contact candidates
      set_linear_wall(w, std::move(system), mesh, first_contact, o.condense_linear_walls);
    }
    return w;
  }
  const auto spec = std::find_if(scene.models.begin(), scene.models.end(),
                                 [&](const ModelSpec& m) { return m.name == o.model; });
  if (spec == scene.models.end()) {
    std::string names;
    for (const ModelSpec& m : scene.models) names += (names.empty() ? "" : ", ") + m.name;
    throw InputError(scene.source.string() + ": insertion: no model \"" + o.model +
                     "\" in the scene; expected one of " + names);
  }
  VesselParams vessel = scene.vessel;
  vessel.style = MeshStyle::unstructured;  // the insertion's mesh is gmsh's
  try {
    w.model.emplace(contact::model_wall(scene, *spec, mesh, vessel, nu));
  } catch (const InputError& e) {
    throw InputError(scene.source.string() + ": insertion: model " + o.model + ": " + e.what());
  }
  const contact::ModelWall& m = *w.model;
  w.detail = m.detail;
  if (m.energy.form) {  // a mass-spring or tet model's own energy: its own equilibrium
    w.potential = std::make_unique<contact::FormWall>(*m.energy.form, m.energy.rest,
                                                      m.system.free_index, m.system.node_rows);
  } else {  // deal.II's FEM as a model: linear
    // (model_wall fills a P2 model's row points: its mid-edge candidates)
    set_linear_wall(w, m.system, mesh, first_contact, o.condense_linear_walls);
  }
  return w;
}

/// A failed insertion step is retried after one halfway, this many times deep: a long step feeds
/// the tip so far along its last edge that it starts beyond the wall.
constexpr int kMaxSplits = 3;

/// The equilibrium in hand along the insertion: the wire's dofs x at length x_length and the
/// wall's free rows u (a condensed wall's on its band, which a solve may grow: its whole field
/// kept beside them).
struct InsertionPath {
  const GuidewireSpec& spec;
  double EI;
  const contact::WallPotential& wall;
  contact::CondensedLinearWall* condensed;  ///< `wall`, when it is a condensed linear wall
  const TetMesh& mesh;
  const std::vector<int>& candidates;  ///< a whole wall's
  contact::PotentialContactOptions options{};
  Eigen::VectorXd x;
  Eigen::VectorXd u{};
  std::vector<Vec3> field;  ///< a condensed wall's displacement per mesh node, m
  double x_length = 0.0;
  int newton_steps = 0;                    ///< since the caller last reset it
  std::unique_ptr<msm::rods::DerRod> rod{};  ///< at x_length, prepared at x
  contact::PotentialContactSolution solution{};

  /// The wall's contact force on the tip's edge at the equilibrium in hand (N; zero before the
  /// first solve).
  [[nodiscard]] Vec3 tip_push() const {
    if (!rod || solution.force_on_wire.empty()) return Vec3::Zero();
    const auto tip = static_cast<std::size_t>(rod->layout().tip_node);
    return solution.force_on_wire[tip] + solution.force_on_wire[tip - 1];
  }

  /// Solves at length L from the equilibrium in hand (fed through the clamp to L);
  /// a failure (Newton, or a centreline through the wall) is retried via L's midpoint with the
  /// last length, up to kMaxSplits deep. Throws std::runtime_error beyond that.
  void advance_to(double L, int depth) {
    auto next =
        std::make_unique<msm::rods::DerRod>(msm::rods::make_layout(guidewire_rod_spec(spec, L)));
    options.force_scale = EI / (L * L);
    try {
      const Eigen::VectorXd from = fed_through_clamp(x, next->layout(), x_length, tip_push());
      const double radius = 0.5 * spec.diameter;
      int growths = 0;
      contact::PotentialContactSolution s =
          condensed ? contact::solve_on_growing_band(*next, radius, *condensed, mesh, from, field,
                                                     options, {}, growths)
                    : contact::solve_wire_wall_potential(*next, radius, wall, mesh, candidates,
                                                         from, options, u);
      newton_steps += s.newton_iterations;
      x = s.x;
      u = s.u;
      if (condensed) field = condensed->nodal(u);
      x_length = L;
      rod = std::move(next);
      solution = std::move(s);
    } catch (const std::runtime_error& e) {
      if (depth == kMaxSplits || L == x_length) throw;
      if (options.log) {
        *options.log << "insertion:   " << L * 1e3 << " mm from " << x_length * 1e3
                     << " mm: " << e.what() << "; split at " << 0.5 * (x_length + L) * 1e3 << " mm"
                     << std::endl;
      }
      advance_to(0.5 * (x_length + L), depth + 1);
      advance_to(L, depth + 1);
    }
  }

  /// The step's record at the equilibrium in hand.
  void describe(InsertionStep& step) const {
    const contact::PotentialContactSolution& s = solution;
    const std::vector<Vec3> displacement = wall.nodal(s.u);
    step.converged = true;
    step.force = s.total_force_on_wall().norm();
    step.pressed = static_cast<int>(s.pressed.size());
    step.zones = contact_zones(mesh, s);
    for (const int n : s.pressed) {
      step.dent = std::max(step.dent, displacement[static_cast<std::size_t>(n)].norm());
    }
    Vec3 reaction = Vec3::Zero(), moment = Vec3::Zero();
    for (const auto& [node, f] : contact::potential_clamp_forces(*rod, s)) {
      reaction += f;
      moment += (Vec3(s.x.segment<3>(3 * node)) - spec.clamp_point).cross(f);
    }
    step.clamp_axial = reaction.dot(spec.clamp_direction.normalized());
    step.clamp_moment = moment.norm();
    step.push = step.clamp_axial - step.clamp_moment * step.clamp_moment / (2.0 * EI);
    step.energy = rod->energy(s.x) + wall.evaluate(s.u, nullptr, nullptr);
    step.tip = s.x.segment<3>(3 * rod->layout().tip_node);
    for (int i = rod->layout().first_node; i <= rod->layout().tip_node; ++i) {
      step.centreline.emplace_back(s.x.segment<3>(3 * i));
    }
  }

  /// The inner wall where the wire bears at the equilibrium in hand (step `index`).
  [[nodiscard]] InsertionView view(int index) const {
    InsertionView v;
    v.step = index;
    const std::vector<Vec3> displacement = wall.nodal(solution.u);
    const auto near = [&](int n) {
      const Vec3& at = mesh.nodes[static_cast<std::size_t>(n)];
      return std::any_of(solution.pressed.begin(), solution.pressed.end(), [&](int p) {
        return (mesh.nodes[static_cast<std::size_t>(p)] - at).norm() < kInsertionViewReach;
      });
    };
    std::vector<int> drawn(mesh.nodes.size(), -1);
    const auto index_of = [&](int n) {
      int& d = drawn[static_cast<std::size_t>(n)];
      if (d < 0) {
        d = static_cast<int>(v.nodes.size());
        v.nodes.push_back(n);
        v.rest.push_back(mesh.nodes[static_cast<std::size_t>(n)]);
        v.displacement.push_back(displacement[static_cast<std::size_t>(n)]);
        v.force.push_back(0.0);
      }
      return d;
    };
    for (const Triangle& t : mesh.group_triangles(mesh.require_group("inner_wall", 2, "vessel"))) {
      if (near(t[0]) || near(t[1]) || near(t[2])) {
        v.triangles.push_back({index_of(t[0]), index_of(t[1]), index_of(t[2])});
      }
    }
    for (std::size_t j = 0; j < solution.pressed.size(); ++j) {
      const int d = drawn[static_cast<std::size_t>(solution.pressed[j])];
      if (d >= 0) v.force[static_cast<std::size_t>(d)] = solution.force[j];
    }
    return v;
  }
};

/// The points where the wire touches the rigid lumen from `first` to `last` (m), every quarter of
/// `radius` (so they follow the range, not the steps), as balls of `radius` (one within a quarter
/// radius of another is left out); `start` gets the rigid-lumen state at `first`. `rigid` has
/// solved the last length.
std::vector<RefinedBall> rigid_lumen_balls(GuidewireSolver& rigid, double first, double last,
                                           double radius, Eigen::VectorXd& start) {
  const int samples = static_cast<int>(std::ceil((last - first) / (0.25 * radius)));
  std::vector<RefinedBall> balls;
  for (int k = 0; k <= samples; ++k) {
    const GuidewireSolution s = rigid.solve_at_insertion(first + (last - first) * k / samples);
    if (k == 0) start = rigid.rod_state();
    if (s.force <= 0.0) continue;
    bool covered = false;
    for (const RefinedBall& b : balls)
      covered = covered || (b.centre - s.wall_point).norm() < 0.25 * b.radius;
    if (!covered) balls.push_back({s.wall_point, radius});
  }
  return balls;
}

/// Each step's dΠ/dL from its neighbours' energies (one-sided at the ends; NaN next to a failed
/// step).
void set_push_by_energy(std::vector<InsertionStep>& steps) {
  const std::size_t n = steps.size();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 == n ? k : k + 1;
    const InsertionStep &sa = steps[a], &sb = steps[b];
    steps[k].push_by_energy = sa.converged && sb.converged && b > a
                                  ? (sb.energy - sa.energy) / (sb.insertion - sa.insertion)
                                  : std::numeric_limits<double>::quiet_NaN();
  }
}

void log_step(std::ostream& log, const InsertionStep& step) {
  log << "insertion: L " << step.insertion * 1e3 << " mm: "
      << (step.converged ? "F " + std::to_string(step.force * 1e3) + " mN, " +
                               std::to_string(step.zones.size()) + " zone(s), push " +
                               std::to_string(step.push * 1e3) + " mN"
                         : "not converged: " + step.failure)
      << ", " << step.newton_steps << " Newton steps, " << step.seconds << " s" << std::endl;
}

void require_options(const std::string& file, const ContactInsertionOptions& o) {
  if (o.steps < 1 || !(o.first >= 0.0) || !(o.last >= 0.0) || !(o.fine_size > 0.0) ||
      !(o.refine_radius > 0.0) || (o.degree != 1 && o.degree != 2) || o.max_steps < 1 ||
      !(o.view_at >= 0.0) || o.reference_threads < 1) {
    throw InputError(file +
                     ": insertion options: expected steps ≥ 1, first and last ≥ 0 (0: the "
                     "defaults), a positive fine size and refined radius, degree 1 or 2, "
                     "Newton steps ≥ 1, a view length ≥ 0 (0: the last step) and reference "
                     "threads ≥ 1");
  }
}

/// The scene's wire at EI (DER) inserted to `last`, and the range [first, last] (m) from the
/// options; InputError naming the file for a scene without a guidewire, bad options or an empty
/// range.
GuidewireSpec insertion_spec(const Scene& scene, double EI, const ContactInsertionOptions& o,
                             double& first, double& last) {
  const std::string file = scene.source.string();
  if (!scene.load.guidewire) {
    throw InputError(file +
                     ": load: expected a guidewire load (type = \"guidewire\"); the "
                     "insertion pushes a wire into the vessel");
  }
  require_options(file, o);
  GuidewireSpec spec;
  try {
    spec = with_stiffness(*scene.load.guidewire, EI);
  } catch (const InputError& e) {
    throw InputError(file + ": " + e.what());
  }
  spec.model = WireModel::der;
  last = o.last > 0.0 ? o.last : spec.insertion;
  first = o.first > 0.0 ? o.first : 0.8 * last;
  if (!(first < last)) {
    throw InputError(file + ": insertion: the first length (" + std::to_string(first * 1e3) +
                     " mm) must be shorter than the last (" + std::to_string(last * 1e3) + " mm)");
  }
  spec.insertion = last;
  return spec;
}

/// The outcome cache's key of one insertion: everything it depends on besides the code and the
/// machine (OutcomeCache adds those): the scene file's bytes, EI, the wall, the options, the model.
std::string insertion_key(const Scene& scene, double EI, const ContactInsertionOptions& o) {
  ContentHash h;
  h.text(file_contents(scene.source)).real(EI).integer(static_cast<int>(o.wall));
  h.real(o.first).real(o.last).integer(o.steps).real(o.fine_size).real(o.refine_radius);
  h.integer(o.degree).integer(o.max_steps).text(o.model).real(o.view_at);
  h.integer(o.condense_linear_walls ? 1 : 0);
  h.integer(o.model.empty() ? o.reference_threads : 1);  // the times depend on it
  return "contact-insertion " + h.hex();
}

}  // namespace

ContactInsertion solve_contact_insertion(const Scene& scene, double EI,
                                         const ContactInsertionOptions& o) {
  const std::string file = scene.source.string();
  double first = 0.0, last = 0.0;
  const GuidewireSpec spec = insertion_spec(scene, EI, o, first, last);
  const ScopedSolverThreads threads(o.model.empty() ? o.reference_threads : 1);
  ContactInsertion out;
  out.scene = scene.name;
  out.bending_stiffness = EI;
  out.wall = o.wall;

  const auto t_mesh = Clock::now();
  GuidewireSolver rigid_solver(scene.vessel, spec);
  try {
    (void)rigid_solver.solve_rigid();
  } catch (const InputError& e) {
    throw InputError(file + ": " + e.what());
  }
  Eigen::VectorXd start;
  const std::vector<RefinedBall> balls =
      rigid_lumen_balls(rigid_solver, first, last, o.refine_radius, start);
  if (balls.empty()) {
    throw InputError(file + ": insertion: the wire touches the rigid lumen at no length from " +
                     std::to_string(first * 1e3) + " to " + std::to_string(last * 1e3) + " mm");
  }
  const TetMesh mesh = refined_balls_mesh(scene.vessel, balls, o.fine_size);
  const InsertionWall made = make_wall(scene, mesh, balls.front().centre, o);
  const contact::WallPotential* wall = made.potential.get();
  if (!o.model.empty()) out.model = o.model;
  out.model_detail = made.detail;
  const std::vector<int> candidates =
      mesh.group_nodes(mesh.require_group("inner_wall", 2, "vessel"));
  out.mesh_nodes = static_cast<int>(mesh.nodes.size());
  out.refined_balls = static_cast<int>(balls.size());
  out.mesh_seconds = seconds_since(t_mesh);
  out.wire_radius = 0.5 * spec.diameter;
  if (o.log) {
    *o.log << "insertion: " << scene.name << ", EI " << EI << " N·m², " << out.model << " ("
           << made.detail << "), " << mesh.nodes.size() << " nodes (" << o.fine_size * 1e3
           << " mm within " << o.refine_radius * 1e3 << " mm of " << balls.size()
           << " rigid-lumen wall points), " << out.mesh_seconds << " s" << std::endl;
  }

  std::vector<double> lengths;
  for (int k = 0; k <= o.steps; ++k) lengths.push_back(first + (last - first) * k / o.steps);
  InsertionPath path{.spec = spec,
                     .EI = EI,
                     .wall = *wall,
                     .condensed = made.condensed,
                     .mesh = mesh,
                     .candidates = candidates,
                     .x = start,
                     .field = std::vector<Vec3>(mesh.nodes.size(), Vec3::Zero()),
                     .x_length = first};
  path.options.tolerance = 1e-8;
  path.options.max_newton = o.max_steps;
  path.options.log = o.log;  // a round's line and one per 25 Newton steps: a step can take minutes
  for (const double L : lengths) {
    const auto t0 = Clock::now();
    InsertionStep step;
    step.insertion = L;
    path.newton_steps = 0;
    try {
      path.advance_to(L, 0);
      path.describe(step);
      if (o.view_at == 0.0 || out.view.step < 0 ||
          std::abs(L - o.view_at) <
              std::abs(out.steps[static_cast<std::size_t>(out.view.step)].insertion - o.view_at)) {
        out.view = path.view(static_cast<int>(out.steps.size()));
      }
    } catch (const std::runtime_error& e) {
      step.failure = e.what();
    }
    step.newton_steps = path.newton_steps;
    step.seconds = seconds_since(t0);
    if (o.log) log_step(*o.log, step);
    out.steps.push_back(step);
  }

  set_push_by_energy(out.steps);
  return out;
}

std::string contact_insertion_entry(const ContactInsertion& r) {
  using nlohmann::json;
  const auto vec = [](const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); };
  const auto points = [](const std::vector<Vec3>& p) {  // flat: x, y, z per point
    json out = json::array();
    for (const Vec3& v : p) out.insert(out.end(), {v.x(), v.y(), v.z()});
    return out;
  };
  json steps = json::array();
  for (const InsertionStep& s : r.steps) {
    json zones = json::array();
    for (const ContactZone& z : s.zones) {
      zones.push_back({{"force_N", z.force},
                       {"centroid_m", vec(z.centroid)},
                       {"extent_m", z.extent},
                       {"nodes", z.nodes}});
    }
    steps.push_back({{"insertion_m", s.insertion},
                     {"converged", s.converged},
                     {"failure", s.failure},
                     {"force_N", s.force},
                     {"pressed", s.pressed},
                     {"zones", zones},
                     {"clamp_axial_N", s.clamp_axial},
                     {"clamp_moment_Nm", s.clamp_moment},
                     {"push_N", s.push},
                     {"push_by_energy_N",
                      std::isfinite(s.push_by_energy) ? json(s.push_by_energy) : json(nullptr)},
                     {"energy_J", s.energy},
                     {"tip_m", vec(s.tip)},
                     {"dent_m", s.dent},
                     {"centreline_m", points(s.centreline)},
                     {"newton_steps", s.newton_steps},
                     {"seconds", s.seconds}});
  }
  json entry{{"scene", r.scene},
             {"model", r.model},
             {"model_detail", r.model_detail},
             {"bending_stiffness_Nm2", r.bending_stiffness},
             {"wall", to_string(r.wall)},
             {"mesh_nodes", r.mesh_nodes},
             {"refined_balls", r.refined_balls},
             {"mesh_seconds", r.mesh_seconds},
             {"wire_radius_m", r.wire_radius},
             {"steps", steps}};
  if (r.view.step >= 0) {
    json triangles = json::array();
    for (const auto& t : r.view.triangles) triangles.insert(triangles.end(), {t[0], t[1], t[2]});
    entry["view"] = {
        {"step", r.view.step},           {"nodes", r.view.nodes},
        {"rest_m", points(r.view.rest)}, {"displacement_m", points(r.view.displacement)},
        {"force_N", r.view.force},       {"triangles", triangles}};
  }
  return entry.dump();
}

std::vector<std::string> insertion_walls(const Scene& scene,
                                         const std::vector<std::string>& names) {
  std::vector<std::string> out;
  const auto add = [&](const std::string& wall) {
    if (std::find(out.begin(), out.end(), wall) == out.end()) out.push_back(wall);
  };
  for (const std::string& name : names) {
    if (name == "reference") {
      add("");
    } else if (name == "all") {
      add("");
      for (const ModelSpec& m : scene.models) {
        if (contact::has_contact_wall(m)) add(m.name);
      }
    } else {
      add(name);
    }
  }
  return out;
}

std::string contact_insertion_document(const Scene& scene, const std::vector<double>& stiffnesses,
                                       const ContactInsertionOptions& options,
                                       const std::string& command, OutcomeCache* cache,
                                       const std::vector<std::string>& models) {
  using nlohmann::json;
  const auto t0 = Clock::now();
  json all = json::array();
  for (const std::string& model : models) {
    ContactInsertionOptions o = options;
    o.model = model;
    for (const double EI : stiffnesses) {
      const auto solve = [&] {
        return contact_insertion_entry(solve_contact_insertion(scene, EI, o));
      };
      json entry;
      if (cache && cache->enabled()) {
        const std::string key = insertion_key(scene, EI, o);
        TimingProvenance provenance;
        entry = json::parse(cache->get(key, solve, provenance));
        if (provenance.cached) entry["cached_from"] = provenance.measured_at;
      } else {
        entry = json::parse(solve());
      }
      all.push_back(entry);
    }
  }
  const json j{{"schema", "vesselverify.insertion"},
               {"schema_version", 1},
               {"command", command},
               {"total_seconds", seconds_since(t0)},
               {"insertions", all}};
  return j.dump(2) + "\n";
}

}  // namespace vessel
