#include "verification/harness/contact_reference.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include "fem_reference/elasticity.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/foundation/solver_threads.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "msm/rods/der_rod.hpp"
#include "verification/contact/wall_crossing.hpp"
#include "verification/contact/wire_wall_contact.hpp"
#include "verification/contact/wire_wall_potential.hpp"
#include "verification/guidewire/guidewire_load.hpp"
#include "verification/scene_problems.hpp"

namespace vessel {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

/// A bending stiffness to three significant digits, N·m²: "1.26e-05 N·m²".
std::string stiffness_text(double EI) {
  std::ostringstream s;
  s.precision(3);
  s << EI << " N·m²";
  return s.str();
}

/// The wire: DER at the scene's segments, at the rigid-wall state.
struct ReferenceWire {
  GuidewireSpec spec;
  msm::rods::DerRod rod;
  Eigen::VectorXd rigid_state;
  double radius = 0.0;
  double bending_stiffness = 0.0;  ///< EI, N·m²
  explicit ReferenceWire(const GuidewireSpec& s, const Eigen::VectorXd& state)
      : spec(s),
        rod(msm::rods::make_layout(guidewire_rod_spec(s, s.insertion))),
        rigid_state(state),
        radius(0.5 * s.diameter),
        bending_stiffness(msm::rods::solid_section({s.young, s.shear, s.density}, s.diameter).EI) {
    rod.prepare(rigid_state);
  }
  /// The same wire with its E and G scaled to bending stiffness EI (N·m²). Its rigid-lumen shape
  /// is the same at every EI: the rod's whole energy scales with E, the lumen is geometric.
  [[nodiscard]] ReferenceWire with_bending_stiffness(double EI) const {
    return ReferenceWire(with_stiffness(spec, EI), rigid_state);
  }
  [[nodiscard]] contact::ContactWire contact() const { return contact::contact_wire(rod, radius); }
};

/// Inner-wall nodes within `radius` of `centre` and within `band` of the wire's surface at x.
std::vector<int> candidates(const TetMesh& mesh, const contact::ContactWire& wire,
                            const Eigen::VectorXd& x, const Vec3& centre, double radius,
                            double band) {
  std::vector<int> out;
  const PhysicalGroup& inner = mesh.require_group("inner_wall", 2, "vessel");
  for (const int n : mesh.group_nodes(inner)) {
    const Vec3& p = mesh.nodes[static_cast<std::size_t>(n)];
    if ((p - centre).norm() <= radius && contact::capsule_gap(wire, x, p) <= band) out.push_back(n);
  }
  return out;
}

/// A solved wire that passed between the wall's nodes, with where to refine the wall next.
struct WallCrossed : std::runtime_error {
  using std::runtime_error::runtime_error;
  /// Where the wall bears the wire, at rest (crossed_wire_refinement), m.
  std::vector<Vec3> near_wall;
};

/// The crossing named `what` of a wire whose centreline nodes are `centreline` through the
/// inner-wall triangle `through` (if known), with where to refine (crossed_wire_refinement).
WallCrossed wall_crossed(const TetMesh& mesh, const std::string& what,
                         const std::vector<Vec3>& centreline, const Triangle* through = nullptr) {
  WallCrossed crossed(what);
  crossed.near_wall = crossed_wire_refinement(mesh, centreline, through);
  return crossed;
}

/// Throws WallCrossed when the solved wire's centreline (rod dofs x) crosses the inner wall
/// displaced by u (per mesh node): the capsule passed between the wall's nodes, which the
/// nodes' gaps cannot see (verification/contact/wall_crossing.hpp).
void require_wire_inside_lumen(const TetMesh& mesh, const msm::rods::Rod& rod,
                               const Eigen::VectorXd& x, const std::vector<Vec3>& u) {
  std::vector<Vec3> centreline;
  for (int i = rod.layout().first_node; i <= rod.layout().tip_node; ++i) {
    centreline.emplace_back(x.segment<3>(3 * i));
  }
  if (const auto failure = contact::describe_wall_crossing(mesh, u, centreline)) {
    throw wall_crossed(mesh, *failure, centreline);
  }
}

bool inside_any(const std::vector<RefinedBall>& balls, const Vec3& p) {
  return std::any_of(balls.begin(), balls.end(),
                     [&](const RefinedBall& b) { return (p - b.centre).norm() <= b.radius; });
}

/// The zone of a solved contact: the pressed nodes (mesh indices) with their forces, the wall's
/// displacement at every mesh node.
void describe_zone(const TetMesh& mesh, const std::vector<int>& pressed,
                   const std::vector<double>& force, const std::vector<Vec3>& u,
                   const std::vector<RefinedBall>& balls, ContactLevel& out) {
  double weight = 0.0;
  out.pressed = static_cast<int>(pressed.size());
  for (std::size_t j = 0; j < pressed.size(); ++j) {
    const auto n = static_cast<std::size_t>(pressed[j]);
    out.centroid += force[j] * mesh.nodes[n];
    weight += force[j];
    out.dent = std::max(out.dent, u[n].norm());
    out.zone_inside_patch = out.zone_inside_patch && inside_any(balls, mesh.nodes[n]);
    for (const int k : pressed) {
      const auto m = static_cast<std::size_t>(k);
      const double d = (mesh.nodes[n] - mesh.nodes[m]).norm();
      if (d >= out.extent) {
        out.extent = d;
        out.middle = 0.5 * (mesh.nodes[n] + mesh.nodes[m]);
      }
    }
  }
  if (weight > 0.0) out.centroid /= weight;
  for (const int j : pressed) {
    out.reach = std::max(out.reach, (mesh.nodes[static_cast<std::size_t>(j)] - out.middle).norm());
  }
}

/// The linear wall: condensed on the candidates, Signorini's conditions by an active set
/// (solve_wire_wall_contact_growing).
void solve_linear_wall(const Scene& scene, const ReferenceWire& wire, double nu,
                       const TetMesh& mesh, const std::vector<int>& nodes, const Vec3& wall_point,
                       const std::vector<RefinedBall>& balls, double force_scale,
                       const ContactReferenceOptions& o, ContactLevel& out) {
  int first = 0;
  for (int j = 1; j < static_cast<int>(nodes.size()); ++j) {
    if ((mesh.nodes[nodes[j]] - wall_point).norm() < (mesh.nodes[nodes[first]] - wall_point).norm())
      first = j;
  }
  const fem::ElasticitySolver solver(mesh, wall_problem(scene, nu, o.degree));
  contact::WireWallOptions wo;
  wo.force_scale = force_scale;
  wo.max_newton = o.max_steps;
  contact::BandGrowth growth;
  growth.margin = 0.25 * wire.radius;
  const contact::GrownContact grown =
      contact::solve_wire_wall_contact_growing(wire.contact(), solver.free_displacement_system(),
                                               mesh, nodes, wire.rigid_state, {first}, wo, growth);
  const contact::WireWallSolution& s = grown.solution;
  out.converged = true;
  out.candidates = static_cast<int>(grown.nodes.size());
  out.steps = s.newton_iterations;
  out.force = s.total_force_on_wall().norm();
  const std::vector<Vec3> u = grown.wall->displacement(s.wall_loads());
  require_wire_inside_lumen(mesh, wire.rod, s.x, u);
  std::vector<int> pressed;
  std::vector<double> force;
  grown.pressed(pressed, force);
  describe_zone(mesh, pressed, force, u, balls, out);
  out.strain = contact::largest_strain(mesh, u).small;
}

/// A level's solved finite-strain equilibrium, where the next level starts: the wire's state, and
/// the wall (kept for its elements' shape functions) with its free rows and its nodes'
/// displacement (m).
struct LevelEquilibrium {
  std::shared_ptr<const contact::NeoHookeanWall> wall;
  Eigen::VectorXd u;
  TetMesh mesh;
  std::vector<Vec3> displacement;
  Eigen::VectorXd wire;
};

/// Barycentric tolerance of the coarser mesh's tet holding a finer mesh's point: the two
/// meshes' chords of the curved walls differ, so a point on one's surface may lie just outside
/// the other's.
constexpr double kOutsideTolerance = 0.25;

/// `from`'s displacement at x: its wall's field (P1 or P2) there, the nearest node's where x
/// lies outside its tets.
Vec3 displacement_at(const LevelEquilibrium& from, const Vec3& x) {
  try {
    return from.wall->displacement_at(from.u, {x}, kOutsideTolerance).front();
  } catch (const InputError&) {
    std::size_t nearest = 0;
    for (std::size_t n = 1; n < from.mesh.nodes.size(); ++n) {
      if ((from.mesh.nodes[n] - x).squaredNorm() < (from.mesh.nodes[nearest] - x).squaredNorm())
        nearest = n;
    }
    return from.displacement[nearest];
  }
}

/// `from`'s displacement interpolated onto `wall`'s rows: a start, not a projection. (Points it
/// puts inside the wire are left there: moved out to its surface, they bent a P2 wall's edges
/// until every trial step of the first Newton step inverted an element.)
Eigen::VectorXd wall_start_from(const LevelEquilibrium& from, const contact::NeoHookeanWall& wall) {
  Vec3 at = Vec3::Constant(std::numeric_limits<double>::quiet_NaN()), value = Vec3::Zero();
  return fem::interpolate_rows(wall.dofs(), [&](const Vec3& x) -> Vec3 {
    if (x != at) {  // a point's three rows are asked in turn
      at = x;
      value = displacement_at(from, x);
    }
    return value;
  });
}

/// The wire at its own EI on `wall` from the solve before's equilibrium `from`, its wall
/// interpolated onto this mesh (wall_start_from) and unfolded where that inverts elements
/// (NeoHookeanWall::untangled); nothing, the reason logged, if that start or solve fails.
std::optional<contact::PotentialContactSolution> solve_from_previous(
    const ReferenceWire& wire, const contact::NeoHookeanWall& wall, const TetMesh& mesh,
    const std::vector<int>& nodes, const LevelEquilibrium& from,
    contact::PotentialContactOptions po, double force_scale, std::ostream* log) {
  const Eigen::VectorXd carried = wall_start_from(from, wall);
  const std::size_t folded = wall.inverted_cells(carried).size();
  const std::optional<Eigen::VectorXd> start = wall.untangled(carried);
  if (log && folded > 0) {
    *log << "contact:   the solve before's field inverts " << folded << " cells of this mesh: "
         << (start ? "smoothed out" : "smoothing does not unfold them; the EI rungs from rest")
         << std::endl;
  }
  if (!start) return std::nullopt;
  // The wire's own copy: the solve leaves its rod prepared at the solution.
  ReferenceWire at_target = wire.with_bending_stiffness(wire.bending_stiffness);
  po.force_scale = force_scale;
  try {
    return contact::solve_wire_wall_potential(at_target.rod, wire.radius, wall, mesh, nodes,
                                              from.wire, po, *start);
  } catch (const std::runtime_error& e) {
    if (log) {
      *log << "contact:   from the solve before's equilibrium: " << e.what()
           << "; the EI rungs from the wall at rest" << std::endl;
    }
    return std::nullopt;
  }
}

/// The largest displacement of a node the wire presses in `s` (m).
double pressed_dent(const contact::NeoHookeanWall& wall,
                    const contact::PotentialContactSolution& s) {
  const std::vector<Vec3> u = wall.nodal(s.u);
  double dent = 0.0;
  for (const int n : s.pressed) dent = std::max(dent, u[static_cast<std::size_t>(n)].norm());
  return dent;
}

/// The wire's stiffness raised in rungs (continuation_rungs) to its own EI, each solved from the
/// last rung's equilibrium, the first from the rigid-lumen state with the wall at rest (the wire's
/// rigid-lumen shape holds at every EI). A rung that fails is split at its geometric mean with the
/// last converged one, up to 3 times. Counts the steps and rungs in `out`. A rung below the
/// wire's EI whose dent is already wider than the lumen (2 × lumen_radius, m) ends the climb:
/// nothing is returned, and `out` says at which EI the wall gave way (ContactLevel::gave_way_at).
std::optional<contact::PotentialContactSolution> climb_rungs(
    const ReferenceWire& wire, const contact::NeoHookeanWall& wall, const TetMesh& mesh,
    const std::vector<int>& nodes, contact::PotentialContactOptions po, double force_scale,
    double lumen_radius, const ContactReferenceOptions& o, ContactLevel& out) {
  const double target = wire.bending_stiffness;
  std::vector<double> rungs =
      contact::continuation_rungs(o.continuation_from, o.continuation_ratio, target);
  Eigen::VectorXd x = wire.rigid_state, u;
  double done = 0.0;  // the EI of the equilibrium in hand (0: the rigid-lumen state, wall at rest)
  int splits = 0;
  contact::PotentialContactSolution s;
  for (std::size_t k = 0; k < rungs.size();) {
    ReferenceWire rung = wire.with_bending_stiffness(rungs[k]);
    po.force_scale = force_scale * rungs[k] / target;
    try {
      s = contact::solve_wire_wall_potential(rung.rod, wire.radius, wall, mesh, nodes, x, po, u);
    } catch (const contact::WireThroughWall& e) {  // the mesh, not the rung, is at fault
      throw wall_crossed(mesh, e.what(), e.centreline, &e.triangle);
    } catch (const std::runtime_error& e) {
      if (splits == 3 || done == 0.0) throw;
      ++splits;
      if (o.log) {
        *o.log << "contact:   EI " << rungs[k] << " N·m² failed (" << e.what()
               << "); the rung split at " << std::sqrt(done * rungs[k]) << " N·m²" << std::endl;
      }
      rungs.insert(rungs.begin() + static_cast<std::ptrdiff_t>(k), std::sqrt(done * rungs[k]));
      continue;
    }
    out.steps += s.newton_iterations;
    ++out.rungs;
    const double dent = pressed_dent(wall, s);
    if (o.log && rungs.size() > 1) {
      *o.log << "contact:   EI " << rungs[k] << " N·m²: F " << s.total_force_on_wall().norm() * 1e3
             << " mN, " << s.pressed.size() << " pressed, dent " << dent * 1e3 << " mm, "
             << s.newton_iterations << " steps" << std::endl;
    }
    if (rungs[k] < target && dent > 2.0 * lumen_radius) {
      out.gave_way_at = rungs[k];
      out.dent = dent;
      out.strain = wall.largest_strain(mesh, s.u);
      out.failure = "the wall gave way at EI " + stiffness_text(rungs[k]) +
                    ", a softer wire than this one: its dent " + fixed(dent * 1e3, 2) +
                    " mm is wider than the lumen";
      return std::nullopt;
    }
    x = s.x;
    u = s.u;
    done = rungs[k];
    ++k;
  }
  return s;
}

/// The P2 wall's equilibrium from P1's on the same mesh (ContactReferenceOptions::p1_start): P1
/// reached as climb_rungs reaches it, its field interpolated onto P2's rows (linear_field_rows),
/// then P2 at the wire's EI from there. Counts both solves' steps and P1's rungs in `out`;
/// nothing if either fails or P1's wall gives way (the log says which).
std::optional<contact::PotentialContactSolution> solve_from_p1(
    const Scene& scene, const ReferenceWire& wire, double nu, const contact::NeoHookeanWall& p2,
    const TetMesh& mesh, const std::vector<int>& nodes, contact::PotentialContactOptions po,
    double force_scale, const ContactReferenceOptions& o, ContactLevel& out) {
  const contact::NeoHookeanWall p1(mesh, wall_problem(scene, nu, 1));
  ContactLevel p1_level;
  std::optional<contact::PotentialContactSolution> s1;
  try {
    s1 =
        climb_rungs(wire, p1, mesh, nodes, po, force_scale, scene.vessel.inner_radius, o, p1_level);
  } catch (const std::runtime_error& e) {
    if (o.log) *o.log << "contact:   P1 failed (" << e.what() << "); P2 alone" << std::endl;
    return std::nullopt;
  }
  if (!s1) {
    if (o.log) *o.log << "contact:   P1's wall gave way; P2 alone" << std::endl;
    return std::nullopt;
  }
  if (o.log) {
    *o.log << "contact:   P1's equilibrium: F " << s1->total_force_on_wall().norm() * 1e3 << " mN, "
           << p1_level.steps << " steps; P2 from there" << std::endl;
  }
  ReferenceWire at_target = wire.with_bending_stiffness(wire.bending_stiffness);
  po.force_scale = force_scale;
  try {
    contact::PotentialContactSolution s =
        contact::solve_wire_wall_potential(at_target.rod, wire.radius, p2, mesh, nodes, s1->x, po,
                                           contact::linear_field_rows(p2, mesh, p1.nodal(s1->u)));
    out.steps = p1_level.steps + s.newton_iterations;
    out.rungs = p1_level.rungs;
    out.from_p1 = true;
    return s;
  } catch (const std::runtime_error& e) {
    if (o.log) {
      *o.log << "contact:   P2 from P1's equilibrium failed (" << e.what() << "); P2 alone"
             << std::endl;
    }
    return std::nullopt;
  }
}

/// The finite-strain wall: the wire and the neo-Hookean wall as one potential
/// (solve_wire_wall_potential), every inner-wall node a candidate. A stiff wire dents the wall
/// by millimetres, and Newton's method from the rigid-lumen state (the wall at rest) does not
/// reach that equilibrium: with options.p1_start on a P2 wall it is solved from P1's
/// (solve_from_p1); else, or if that fails, with `from` (the solve before's equilibrium) the
/// wire's EI is solved from there (solve_from_previous); else, or if that fails, reached in rungs
/// (climb_rungs).
/// The equilibrium reached is left in `reached`; false if a softer rung's wall gave way (`out`
/// says where) and none was reached.
bool solve_neo_hookean_wall(const Scene& scene, const ReferenceWire& wire, double nu,
                            const TetMesh& mesh, const std::vector<RefinedBall>& balls,
                            double force_scale, const ContactReferenceOptions& o,
                            const LevelEquilibrium* from, ContactLevel& out,
                            LevelEquilibrium& reached) {
  const auto shared =
      std::make_shared<const contact::NeoHookeanWall>(mesh, wall_problem(scene, nu, o.degree));
  const contact::NeoHookeanWall& wall = *shared;
  const std::vector<int> nodes = mesh.group_nodes(mesh.require_group("inner_wall", 2, "vessel"));
  contact::PotentialContactOptions po;
  // ‖∇Π‖ to 1e-8 of the rigid-wall force: the force to ~1e-8 of itself, short of the
  // neo-Hookean energy's round-off floor where the line search stalls.
  po.tolerance = 1e-8;
  po.max_newton = o.max_steps;
  po.log = o.log;
  // On the straight scene's scout refined along the stiff wire (13 239 nodes) the 1.26e-5 N·m²
  // rung converged in 45 damped steps; undamped it oscillated for 175 (residual 5e-4-2.6e-3 N).
  po.damped_newton = true;
  std::optional<contact::PotentialContactSolution> s;
  if (o.p1_start && o.degree == 2) {
    s = solve_from_p1(scene, wire, nu, wall, mesh, nodes, po, force_scale, o, out);
  }
  if (!s && from != nullptr) {
    s = solve_from_previous(wire, wall, mesh, nodes, *from, po, force_scale, o.log);
    if (s) {
      out.steps = s->newton_iterations;
      out.rungs = 1;
      out.from_previous_solve = true;
    }
  }
  if (!s) {
    s = climb_rungs(wire, wall, mesh, nodes, po, force_scale, scene.vessel.inner_radius, o, out);
    if (!s) return false;
  }
  const std::vector<Vec3> displacement = wall.nodal(s->u);
  out.converged = true;
  out.candidates = static_cast<int>(nodes.size());
  out.force = s->total_force_on_wall().norm();
  describe_zone(mesh, s->pressed, s->force, displacement, balls, out);
  out.strain = wall.largest_strain(mesh, s->u);
  reached = {shared, s->u, mesh, displacement, s->x};
  return true;
}

/// One contact solve on a mesh refined to `fine` within the balls (the first: the zone; its
/// candidates for the linear wall). The finite-strain wall starts from `last` where it holds a
/// coarser solve's equilibrium, and leaves its own there. A wire that crossed the wall leaves its
/// centreline nodes near the wall in `near_wall`.
ContactLevel solve_level(const Scene& scene, const ReferenceWire& wire, double nu, double fine,
                         const std::vector<RefinedBall>& balls, const Vec3& wall_point,
                         double force_scale, const ContactReferenceOptions& o,
                         std::optional<LevelEquilibrium>& last,
                         std::vector<Vec3>* near_wall = nullptr) {
  const auto t0 = Clock::now();
  ContactLevel out;
  out.fine_size = fine;
  const Vec3& centre = balls.front().centre;
  const double radius = balls.front().radius;
  const TetMesh mesh = refined_balls_mesh(scene.vessel, balls, fine);
  out.mesh_nodes = static_cast<int>(mesh.nodes.size());
  // The linear wall's candidates: near the rigid-lumen wire in the zone's ball. (The
  // finite-strain wall's are every inner-wall node: its wire may have moved far from that shape.)
  std::vector<int> nodes;
  if (o.wall == ContactWall::linear) {
    nodes = candidates(mesh, wire.contact(), wire.rigid_state, centre, radius, o.band);
    if (nodes.empty()) {
      out.failure = "no inner-wall node within the band of the wire's surface";
      out.seconds = seconds_since(t0);
      return out;
    }
  }
  if (o.log) {
    *o.log << "contact: fine " << fine * 1e3 << " mm within " << radius * 1e3 << " mm"
           << (balls.size() > 1 ? " and " + std::to_string(balls.size() - 1) + " balls more" : "")
           << ", " << mesh.nodes.size() << " nodes, "
           << (nodes.empty() ? std::string("every inner-wall node a candidate")
                             : std::to_string(nodes.size()) + " candidates")
           << ", " << to_string(o.wall) << " wall" << std::endl;
  }
  try {
    if (o.wall == ContactWall::linear) {
      solve_linear_wall(scene, wire, nu, mesh, nodes, wall_point, balls, force_scale, o, out);
    } else {
      LevelEquilibrium reached;
      if (solve_neo_hookean_wall(scene, wire, nu, mesh, balls, force_scale, o,
                                 last && o.from_previous_solve ? &*last : nullptr, out, reached))
        last = std::move(reached);
    }
  } catch (const WallCrossed& e) {
    out.converged = false;
    out.failure = e.what();
    if (near_wall) *near_wall = e.near_wall;
  } catch (const std::runtime_error& e) {
    out.converged = false;
    out.failure = e.what();
  }
  out.seconds = seconds_since(t0);
  if (o.log) {
    *o.log << "contact:   "
           << (out.converged ? "F " + std::to_string(out.force * 1e3) + " mN, " +
                                   std::to_string(out.pressed) + " pressed"
                             : "not converged: " + out.failure)
           << ", " << out.candidates << " candidates, " << out.steps << " steps, " << out.seconds
           << " s" << std::endl;
  }
  return out;
}

void require_guidewire(const Scene& scene) {
  if (!scene.load.guidewire) {
    throw InputError(scene.source.string() +
                     ": load: expected a guidewire load (type = \"guidewire\"); the contact "
                     "commands (contact, insertion) solve the scene's wire against its wall");
  }
}

/// Scout solves at most this many times: each wire that passed between the wall's nodes adds
/// the balls on the inner wall along its centreline that the wall lacks (a stiff wire's body
/// straightens as the wall gives, and refined in one place it bears and crosses further along).
constexpr int kScoutSolves = 4;

/// The scout: the coarsest level refined at the rigid wall point finds the zone (r.scout,
/// r.patch_centre, r.patch_radius, r.refined_along_wire). A wire that passed between the wall's
/// nodes elsewhere (a stiff wire's body, straightened as the wall gives) is scouted again with
/// the wall also refined along the band it may bear on (bearing_band, its points half a ball
/// apart) and around the inner-wall nodes nearest its centreline nodes near the wall, up to
/// kScoutSolves solves in all. Returns the balls every level is refined in: the zone's first,
/// then those along the wire.
std::vector<RefinedBall> scout(const Scene& scene, const ReferenceWire& wire,
                               const Vec3& wall_point, double force_scale,
                               const ContactReferenceOptions& o, ContactReference& r,
                               std::optional<LevelEquilibrium>& last) {
  const double scout_radius = 1.0e-3;
  std::vector<RefinedBall> balls{{wall_point, scout_radius}};
  for (int solve = 1; solve <= kScoutSolves; ++solve) {
    std::vector<Vec3> near_wall;
    r.scout = solve_level(scene, wire, r.poisson_ratio, o.coarsest_size, balls, wall_point,
                          force_scale, o, last, &near_wall);
    const std::size_t before = balls.size();
    if (!near_wall.empty() && solve == 1) {
      const std::vector<Vec3> band =
          bearing_band(scene.vessel, wire.spec, wire.rod.layout(), wire.rigid_state,
                       kBearingBandNearWall, 0.5 * kBearingBandBallRadius);
      near_wall.insert(near_wall.end(), band.begin(), band.end());
    }
    for (const Vec3& p : near_wall) {
      if (!inside_any(balls, p)) balls.push_back({p, kBearingBandBallRadius});
    }
    if (r.scout.converged || balls.size() == before || solve == kScoutSolves) break;
  }
  r.refined_along_wire = static_cast<int>(balls.size()) - 1;
  r.patch_centre = wall_point;
  r.patch_radius = scout_radius;
  if (r.scout.converged && r.scout.pressed > 0) {
    r.patch_centre = r.scout.middle;
    r.patch_radius = r.scout.reach + o.margin;
  }
  balls.front() = {r.patch_centre, r.patch_radius};
  return balls;
}

/// A converged solve, or a softer rung of one (ContactLevel::gave_way_at), whose dent is wider
/// than the lumen: the wire no longer bears on a vessel's wall but pushes the wall ahead of it, so
/// no mesh or solver makes that force one a simulator's vessel would give.
bool wall_gives_way(const ContactLevel& l, double lumen_radius) {
  return (l.converged || l.gave_way_at) && l.dent > 2.0 * lumen_radius;
}

/// " (at EI … N·m², a softer wire)" for a level whose wall gave way below its EI.
std::string softer_rung(const ContactLevel& l) {
  return l.gave_way_at ? " (at EI " + stiffness_text(*l.gave_way_at) + ", a softer wire)"
                       : std::string();
}

/// A level's row of print_contact_reference's table.
void print_level_row(const ContactLevel& l, std::ostream& out) {
  out << "| " << l.level << " | " << fixed(l.fine_size * 1e3, 3) << " | " << l.mesh_nodes << " | "
      << l.candidates << " | ";
  if (l.gave_way_at) {
    out << "— | gave way" << softer_rung(l) << " | — | — | " << fixed(l.dent * 1e3, 3) << " | "
        << fixed(l.strain, 3) << " | " << l.steps << " in " << l.rungs << " EI rungs | "
        << fixed(l.seconds, 1) << " |\n";
    return;
  }
  if (!l.converged) {
    // The step count is in the failure's message (the solve throws without it).
    out << "— | did not converge | — | — | — | — | — | " << fixed(l.seconds, 1) << " |\n";
    return;
  }
  out << l.pressed << " | " << fixed(l.force * 1e3, 5) << " | (" << fixed(l.centroid.x() * 1e3, 2)
      << ", " << fixed(l.centroid.y() * 1e3, 2) << ", " << fixed(l.centroid.z() * 1e3, 2) << ") | "
      << fixed(l.extent * 1e3, 3) << (l.zone_inside_patch ? "" : " (leaves the patch)") << " | "
      << fixed(l.dent * 1e3, 3) << " | " << fixed(l.strain, 3) << " | " << l.steps
      << (l.rungs > 1 ? " in " + std::to_string(l.rungs) + " EI rungs" : std::string())
      << (l.from_previous_solve ? " from the solve before" : "")
      << (l.from_p1 ? " (P1's, then P2's from it)" : "") << " | " << fixed(l.seconds, 1) << " |\n";
}

}  // namespace

std::vector<Vec3> crossed_wire_refinement(const TetMesh& mesh, const std::vector<Vec3>& centreline,
                                          const Triangle* through) {
  std::vector<Vec3> out;
  if (through) {
    for (const int n : *through) out.push_back(mesh.nodes[static_cast<std::size_t>(n)]);
  }
  const std::vector<int> wall_nodes =
      mesh.group_nodes(mesh.require_group("inner_wall", 2, "vessel"));
  for (const Vec3& p : centreline) {
    double nearest = std::numeric_limits<double>::infinity();
    Vec3 at = p;
    for (const int n : wall_nodes) {
      const Vec3& node = mesh.nodes[static_cast<std::size_t>(n)];
      if ((node - p).norm() < nearest) {
        nearest = (node - p).norm();
        at = node;
      }
    }
    if (nearest <= kBearingBandNearWall) out.push_back(at);
  }
  return out;
}

void solve_contact_levels(const ContactReferenceOptions& o, double lumen_radius,
                          std::vector<RefinedBall> balls, const ContactLevelSolve& solve,
                          ContactReference& r) {
  const auto gives_way = [&](const ContactLevel& l, const std::string& which) {
    if (!wall_gives_way(l, lumen_radius)) return false;
    if (o.log) {
      *o.log << "contact:   " << which << "'s dent " << l.dent * 1e3 << " mm" << softer_rung(l)
             << " is wider than the lumen: the wall does not hold this wire; no finer level "
                "is solved"
             << std::endl;
    }
    return true;
  };
  r.levels.clear();
  if (gives_way(r.scout, "the scout")) return;
  for (int l = 0; l < o.levels; ++l) {
    ContactLevel level = solve(o.coarsest_size / std::pow(o.ratio, l), balls);
    level.level = l;
    if (gives_way(level, "level " + std::to_string(l))) {
      r.levels.push_back(level);
      return;
    }
    // A zone that leaves the patch (the scout's coarser wall under-reports a long line of
    // contact, and a finer wall's zone reaches further): the patch grown to this level's zone,
    // the old one kept, and the levels solved again from the first, so that all share one patch.
    if (level.converged && !level.zone_inside_patch && r.patch_growths < kContactPatchGrowths) {
      ++r.patch_growths;
      r.patch_centre = level.middle;
      r.patch_radius = level.reach + o.margin;
      balls.insert(balls.begin(), {r.patch_centre, r.patch_radius});
      if (o.log) {
        *o.log << "contact:   the zone (" << level.extent * 1e3
               << " mm) left the patch: refined within " << r.patch_radius * 1e3
               << " mm of its middle and the levels solved again from the first" << std::endl;
      }
      r.levels.clear();
      l = -1;
      continue;
    }
    r.levels.push_back(level);
  }
}

namespace {

/// "no reference: the wall does not hold this wire (...)" for the deepest solve, the scout's
/// included (when every level fails it may be the only converged one), whose wall gives way;
/// nothing if none does.
std::optional<std::string> gave_way_verdict(const ContactReference& r, double lumen_radius) {
  const ContactLevel* deepest = nullptr;
  auto consider = [&](const ContactLevel& l) {
    if (wall_gives_way(l, lumen_radius) && (!deepest || l.dent > deepest->dent)) deepest = &l;
  };
  consider(r.scout);
  for (const ContactLevel& l : r.levels) consider(l);
  if (!deepest) return std::nullopt;
  const std::string which =
      deepest == &r.scout ? "the scout" : "level " + std::to_string(deepest->level);
  return "no reference: the wall does not hold this wire (" + which + "'s dent " +
         fixed(deepest->dent * 1e3, 2) + " mm" + softer_rung(*deepest) +
         " is wider than the lumen, " + fixed(2e3 * lumen_radius, 2) + " mm; largest strain " +
         fixed(deepest->strain, 2) + ")";
}

/// Roache's order and the Richardson estimate of the force from the finest levels (two or
/// more, all converged).
void estimate_force(const ContactReferenceOptions& o, ContactReference& r) {
  const std::size_t n = r.levels.size();
  std::optional<std::vector<double>> three;
  if (n >= 3)
    three =
        std::vector<double>{r.levels[n - 3].force, r.levels[n - 2].force, r.levels[n - 1].force};
  // Assumed first order where three levels do not give one: a contact zone's edge cuts
  // elements, which limits the force's convergence.
  r.order = fem::gci_order(three, 1.0, o.ratio);
  r.estimate = fem::richardson(r.levels[n - 2].force, r.levels[n - 1].force, r.order->order,
                               o.ratio, r.order->safety_factor);
}

}  // namespace

void judge_contact_reference(const ContactReferenceOptions& o, double lumen_radius,
                             ContactReference& r) {
  r.order.reset();
  r.estimate.reset();
  if (const std::optional<std::string> gave_way = gave_way_verdict(r, lumen_radius)) {
    r.verdict = *gave_way;
    return;
  }
  if (r.levels.empty()) {
    r.verdict = "did not converge (no level solved)";
    return;
  }
  for (const ContactLevel& l : r.levels) {
    if (!l.converged) {
      r.verdict = "did not converge (level " + std::to_string(l.level) + ": " + l.failure + ")";
      return;
    }
  }
  if (r.levels.size() >= 2) estimate_force(o, r);
  double strain = 0.0;
  bool inside = true;
  for (const ContactLevel& l : r.levels) {
    strain = std::max(strain, l.strain);
    inside = inside && l.zone_inside_patch;
  }
  if (o.wall == ContactWall::linear && strain > o.strain_limit) {
    r.verdict = "beyond the linear wall's validity (largest strain " + fixed(strain, 3) + " > " +
                fixed(o.strain_limit, 3) + ")";
  } else if (!inside) {
    r.verdict = "not a reference: the contact zone leaves the refined patch";
  } else if (r.levels.size() < 2) {
    r.verdict = "one level: no estimate of its mesh error (two or more levels give a GCI)";
  } else if (r.estimate->gci_fine > o.gci_limit) {
    r.verdict = "not a reference: the levels' GCI " + fixed(100.0 * r.estimate->gci_fine, 2) +
                " % is above " + fixed(100.0 * o.gci_limit, 2) +
                " % (the levels are not in the asymptotic range: finer levels are needed)";
  } else {
    r.verdict = "reference";
  }
}

std::vector<double> contact_reference_stiffnesses(const Scene& scene) {
  require_guidewire(scene);
  const GuidewireSpec& g = *scene.load.guidewire;
  if (!g.stiffness_sweep.empty()) return g.stiffness_sweep;
  return {msm::rods::solid_section({g.young, g.shear, g.density}, g.diameter).EI};
}

ContactReference solve_contact_reference(const Scene& scene, double EI,
                                         const ContactReferenceOptions& o) {
  const std::string file = scene.source.string();
  require_guidewire(scene);
  if (o.levels < 1 || !(o.coarsest_size > 0.0) || !(o.ratio > 1.0) ||
      (o.degree != 1 && o.degree != 2) || !(o.margin >= 0.0) || !(o.band > 0.0) ||
      !(o.strain_limit > 0.0) || !(o.gci_limit > 0.0) || o.max_steps < 1 ||
      !(o.continuation_from > 0.0) || !(o.continuation_ratio > 1.0) || o.threads < 1) {
    throw InputError(
        "contact reference options: expected levels ≥ 1, a positive coarsest size, "
        "ratio > 1, degree 1 or 2, margin ≥ 0, band > 0, strain limit > 0, GCI limit > 0, "
        "steps ≥ 1, a positive continuation start, a continuation ratio > 1 and threads ≥ 1");
  }
  const ScopedSolverThreads threads(o.threads);
  GuidewireSpec spec;
  try {
    spec = with_stiffness(*scene.load.guidewire, EI);
  } catch (const InputError& e) {
    throw InputError(file + ": " + e.what());
  }
  spec.model = WireModel::der;  // the reference's wire: DER (verified against the elastica)
  ContactReference r;
  r.scene = scene.name;
  r.bending_stiffness = EI;
  r.wall_modulus = scene.youngs_modulus;
  r.poisson_ratio = scene.poisson_ratios.front();
  r.strain_limit = o.strain_limit;
  r.wall = o.wall;
  r.degree = o.degree;

  GuidewireSolver rigid_solver(scene.vessel, spec);
  GuidewireSolution rigid;
  try {
    rigid = rigid_solver.solve_rigid();
  } catch (const InputError& e) {
    throw InputError(file + ": " + e.what());
  }
  if (rigid.force <= 0.0) {
    throw InputError(file +
                     ": load.insertion: the wire does not reach the wall; expected an "
                     "insertion that makes it touch");
  }
  r.rigid_force = rigid.force;
  r.rigid_wall_point = rigid.wall_point;
  std::string why;
  if (const auto c = continuum_wire(scene.vessel, spec, why)) r.continuum_rigid_force = c->force;
  const ReferenceWire wire(spec, rigid_solver.rod_state());

  // The finite-strain wall's last equilibrium: each solve starts from the one before it.
  std::optional<LevelEquilibrium> last;
  std::vector<RefinedBall> balls = scout(scene, wire, rigid.wall_point, rigid.force, o, r, last);
  const auto solve = [&](double fine, const std::vector<RefinedBall>& refined) {
    return solve_level(scene, wire, r.poisson_ratio, fine, refined, rigid.wall_point, rigid.force,
                       o, last);
  };
  solve_contact_levels(o, scene.vessel.inner_radius, balls, solve, r);
  judge_contact_reference(o, scene.vessel.inner_radius, r);
  return r;
}

void print_contact_reference(const ContactReference& r, std::ostream& out) {
  out << "### " << r.scene << ", EI = " << r.bending_stiffness << " N·m²\n\n"
      << to_string(r.wall) << " P" << r.degree << " wall, E = " << r.wall_modulus
      << " Pa, ν = " << r.poisson_ratio << "; rigid wall: " << fixed(r.rigid_force * 1e3, 4)
      << " mN (discrete wire)";
  if (r.continuum_rigid_force)
    out << ", " << fixed(*r.continuum_rigid_force * 1e3, 4) << " mN (continuum)";
  out << "; refined within " << fixed(r.patch_radius * 1e3, 3) << " mm of ("
      << fixed(r.patch_centre.x() * 1e3, 3) << ", " << fixed(r.patch_centre.y() * 1e3, 3) << ", "
      << fixed(r.patch_centre.z() * 1e3, 3) << ") mm"
      << (r.refined_along_wire > 0 ? " and within " + fixed(kBearingBandBallRadius * 1e3, 1) +
                                         " mm of " + std::to_string(r.refined_along_wire) +
                                         " inner-wall points along the band the wire may bear "
                                         "on, after a scout wire crossed the wall"
                                   : std::string())
      << (r.patch_growths > 0 ? " (the patch grown " + std::to_string(r.patch_growths) +
                                    " time(s) to a level's zone that left it; the first patch: "
                              : std::string(" ("))
      << "the zone of a scout solve at " << fixed(r.scout.fine_size * 1e3, 3)
      << " mm within 1 mm of the rigid wall point: "
      << (r.scout.converged
              ? std::to_string(r.scout.pressed) + " pressed, " + fixed(r.scout.seconds, 1) + " s"
          : r.scout.gave_way_at ? "the wall gave way" + softer_rung(r.scout) + ", dent " +
                                      fixed(r.scout.dent * 1e3, 2) + " mm"
                                : std::string("did not converge"))
      << ").\n\n"
      << "| level | fine mm | nodes | candidates | pressed | F mN | zone centroid mm | extent mm | "
         "dent mm | largest strain | steps | s |\n"
      << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const ContactLevel& l : r.levels) print_level_row(l, out);
  for (const ContactLevel& l : r.levels) {
    if (!l.converged) {
      out << "\nLevel " << l.level << (l.gave_way_at ? " stopped: " : " did not converge: ")
          << l.failure << "\n";
    }
  }
  if (r.estimate && r.order) {
    out << "\nRichardson: F = " << fixed(r.estimate->extrapolated * 1e3, 5) << " mN ("
        << r.order->note << ", safety factor " << r.order->safety_factor << "), GCI of the finest "
        << fixed(100.0 * r.estimate->gci_fine, 2) << " %.\n";
    if (r.degree == 1) {
      // At ν near ½ linear tets lock: the P1 wall is stiffer than the continuum at every size, an
      // error the refinement of the zone does not see.
      out << "The GCI is the contact zone's mesh at P1; the element degree's own error is not in "
             "it (`--degree 2` measures it).\n";
    }
  }
  out << "\nVerdict: " << r.verdict << ".\n";
}

}  // namespace vessel
