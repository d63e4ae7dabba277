#include "verification/contact_models/contact_models.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>

#include "meshes/foundation/errors.hpp"
#include "meshes/foundation/solver_threads.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/vessel_geometry.hpp"
#include "msm/rods/der_rod.hpp"
#include "verification/contact/condensed_wall_potential.hpp"
#include "verification/contact/wire_wall_contact.hpp"
#include "verification/contact/wire_wall_potential.hpp"
#include "verification/guidewire/guidewire_load.hpp"
#include "verification/scene_problems.hpp"

namespace vessel::contact {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The scene's wire as a DER rod at bending stiffness EI (E and G scaled, the section kept),
/// clamped where the scene clamps it, with its state against the rigid lumen.
struct SceneWire {
  GuidewireSpec spec;
  msm::rods::RodLayout layout;
  msm::rods::DerRod rod;
  double radius = 0.0;
  double length = 0.0;
  SceneWire(const GuidewireSpec& scene_wire, double EI)
      : spec([&] {
          GuidewireSpec s = with_stiffness(scene_wire, EI);
          s.model = WireModel::der;
          return s;
        }()),
        layout(msm::rods::make_layout(guidewire_rod_spec(spec, spec.insertion))),
        rod(layout),
        radius(spec.diameter / 2),
        length(spec.insertion) {}
  [[nodiscard]] ContactWire contact() const { return contact_wire(rod, radius); }
};

/// The wire against the vessel's rigid lumen (GuidewireSolver: the straight tube or the arch).
struct RigidContact {
  Eigen::VectorXd x;
  double force = 0.0;
  Vec3 wall_point = Vec3::Zero();
};

RigidContact rigid_contact(const SceneWire& w, const VesselParams& vessel) {
  GuidewireSolver solver(vessel, w.spec);
  const GuidewireSolution s = solver.solve_rigid();
  if (!(s.force > 0.0)) {
    throw std::runtime_error("the wire does not touch the rigid lumen: no contact to solve");
  }
  return {solver.rod_state(), s.force, s.wall_point};
}

/// The balls the contact mesh is refined in: one of options.fine_radius at each distinct rigid
/// contact, and balls at options.bearing_band_size along the band the wire may bear on
/// (bearing_band). Against a rigid wall the wire's shape does not depend on EI: the EIs share one
/// mesh.
std::vector<RefinedBall> refined_balls(const std::vector<RigidContact>& rigid,
                                       const SceneWire& wire, const VesselParams& vessel,
                                       const ContactModelsOptions& options) {
  std::vector<RefinedBall> balls;
  for (const RigidContact& r : rigid) {
    const bool covered = std::any_of(balls.begin(), balls.end(), [&](const RefinedBall& b) {
      return (b.centre - r.wall_point).norm() < 0.25 * b.radius;
    });
    if (!covered) balls.push_back({r.wall_point, options.fine_radius});
  }
  if (options.bearing_band_size > 0.0) {
    for (const Vec3& p : bearing_band(vessel, wire.spec, wire.layout, rigid.front().x,
                                      kBearingBandNearWall, 0.5 * kBearingBandBallRadius)) {
      balls.push_back({p, kBearingBandBallRadius, options.bearing_band_size});
    }
  }
  return balls;
}

/// The contact problem's fixed parts, shared by every wall at one EI.
struct Problem {
  const TetMesh* mesh = nullptr;
  const VesselParams* vessel = nullptr;
  std::vector<int> nodes;  ///< the first candidates
  int first = 0;           ///< the candidate nearest the rigid wall point
};

/// The first candidates: the inner-wall nodes within `band` of the rigid contact's wall point,
/// and the one nearest it.
void set_first_candidates(Problem& p, const Vec3& wall_point, double band) {
  const TetMesh& mesh = *p.mesh;
  for (const int n : mesh.group_nodes(mesh.require_group("inner_wall", 2, "contact mesh"))) {
    if ((mesh.nodes[n] - wall_point).norm() < band) p.nodes.push_back(n);
  }
  if (p.nodes.empty()) {
    throw std::runtime_error("no inner-wall node within the band radius of the rigid contact");
  }
  const auto distance = [&](std::size_t j) { return (mesh.nodes[p.nodes[j]] - wall_point).norm(); };
  for (std::size_t j = 1; j < p.nodes.size(); ++j) {
    if (distance(j) < distance(static_cast<std::size_t>(p.first))) p.first = static_cast<int>(j);
  }
}

/// The pressed zone: its centroid, its spans along the vessel's centreline and around it (as arc
/// length at the lumen), the dent.
void describe_zone(const Problem& p, const std::vector<int>& pressed,
                   const std::vector<double>& force, const std::vector<Vec3>& u,
                   ModelContact& out) {
  double s_lo = std::numeric_limits<double>::infinity(), s_hi = -s_lo;
  double t_lo = s_lo, t_hi = s_hi, total = 0.0, theta0 = 0.0;
  out.pressed = static_cast<int>(pressed.size());
  for (std::size_t j = 0; j < pressed.size(); ++j) {
    const auto node = static_cast<std::size_t>(pressed[j]);
    const Vec3& X = p.mesh->nodes[node];
    out.centroid += force[j] * X;
    total += force[j];
    out.dent = std::max(out.dent, u[node].norm());
    const CentrelineCoordinates c = centreline_coordinates(*p.vessel, X);
    s_lo = std::min(s_lo, c.s);
    s_hi = std::max(s_hi, c.s);
    if (j == 0) theta0 = c.theta;  // angles about the first pressed node's: no wrap at ±π
    const double theta = std::remainder(c.theta - theta0, 2.0 * std::numbers::pi);
    t_lo = std::min(t_lo, theta);
    t_hi = std::max(t_hi, theta);
  }
  if (total > 0.0) {
    out.centroid /= total;
    out.axial_extent = s_hi - s_lo;
    out.circumferential_extent = p.vessel->inner_radius * (t_hi - t_lo);
  }
}

ModelContact solve_wall_active_set(const ModelWall& wall, const SceneWire& w,
                                   const RigidContact& rigid, const Problem& p, double EI,
                                   const ContactModelsOptions& options) {
  ModelContact out;
  out.name = wall.name;
  out.detail = wall.detail;
  out.linearisation = to_string(wall.linearisation);
  out.linear_wall = true;
  WireWallOptions o;
  o.force_scale = EI / (w.length * w.length);
  o.max_newton = options.max_newton;
  o.max_move = options.max_move;
  const auto t0 = std::chrono::steady_clock::now();
  const GrownContact grown = solve_wire_wall_contact_growing(w.contact(), wall.system, *p.mesh,
                                                             p.nodes, rigid.x, {p.first}, o);
  const WireWallSolution& s = grown.solution;
  out.solve_seconds = s.seconds;
  out.setup_seconds = wall.setup_seconds + seconds_since(t0) - s.seconds;
  out.force_on_wall = s.total_force_on_wall();
  out.force = out.force_on_wall.norm();
  out.candidates = static_cast<int>(grown.nodes.size());
  out.rounds = grown.rounds;
  out.steps = s.newton_iterations;
  out.tip = s.x.segment<3>(3 * w.layout.tip_node);
  const std::vector<Vec3> u = grown.wall->displacement(s.wall_loads());
  std::vector<int> pressed;
  std::vector<double> force;
  grown.pressed(pressed, force);
  describe_zone(p, pressed, force, u, out);
  out.strain = largest_strain(*p.mesh, u).small;
  std::vector<Vec3> loads(p.mesh->nodes.size(), Vec3::Zero());
  for (std::size_t j = 0; j < grown.nodes.size(); ++j) {
    loads[static_cast<std::size_t>(grown.nodes[j])] +=
        s.force[static_cast<Eigen::Index>(j)] * s.direction[j];
  }
  out.own_imbalance = own_imbalance(wall, u, loads);
  return out;
}

/// How a wall enters the contact solve: at its own equilibrium, or its linearisation at rest.
std::string wall_label(const ModelWall& wall, const ContactModelsOptions& options) {
  return options.own_equilibrium ? kOwnEquilibrium : to_string(wall.linearisation);
}

/// A wall's equilibrium with the wire at its own equilibrium: the wire's dofs and the wall's
/// free rows, where the next (stiffer) wire starts.
struct PotentialState {
  double bending_stiffness = 0.0;  ///< the wire's EI, N·m²
  Eigen::VectorXd x, u;
  /// A P2 reference's P1 start at the same EI (solve_p2_from_p1): its wire and wall; empty if none
  Eigen::VectorXd x_p1, u_p1;
};

/// The own-equilibrium solve of the wall under `w` (at bending stiffness EI, its rod `rod`).
/// From `start` (the softer wire's equilibrium) if given: in rungs of EI (continuation_rungs,
/// steps of kContinuationRatio), each solved from the last. Without a start, or if a rung fails
/// (the log says which and why), from the rigid-lumen state with the wall at rest. The solution's
/// time and Newton steps are the whole climb's (a failed rung's time counts, its steps do not).
PotentialContactSolution solve_own_equilibrium(
    msm::rods::DerRod& rod, const SceneWire& w, double EI, const WallPotential& wall,
    const TetMesh& mesh, const std::vector<int>& candidates, const RigidContact& rigid,
    const PotentialContactOptions& o, const PotentialState* start, bool& from_start) {
  from_start = false;
  const auto t0 = std::chrono::steady_clock::now();
  int climbed = 0;  // the converged softer rungs' Newton steps
  const auto whole_climb = [&](PotentialContactSolution s) {
    s.seconds = seconds_since(t0);
    s.newton_iterations += climbed;
    return s;
  };
  if (start != nullptr) {
    Eigen::VectorXd x = start->x, u = start->u;
    for (const double rung : continuation_rungs(start->bending_stiffness * kContinuationRatio,
                                                kContinuationRatio, EI)) {
      PotentialContactOptions ro = o;
      ro.force_scale = o.force_scale * rung / EI;
      try {
        std::optional<SceneWire> softer;
        msm::rods::DerRod& r = rung == EI ? rod : softer.emplace(w.spec, rung).rod;
        PotentialContactSolution s =
            solve_wire_wall_potential(r, w.radius, wall, mesh, candidates, x, ro, u);
        if (rung == EI) {
          from_start = true;
          return whole_climb(std::move(s));
        }
        if (o.log) {
          *o.log << "contact-models:   EI " << rung << " N·m² on the way: F "
                 << s.total_force_on_wall().norm() * 1e3 << " mN, " << s.newton_iterations
                 << " steps" << std::endl;
        }
        climbed += s.newton_iterations;
        x = s.x;
        u = s.u;
      } catch (const std::runtime_error& e) {
        if (o.log) {
          *o.log << "contact-models:   from the softer wire's equilibrium, EI " << rung
                 << " N·m² failed (" << e.what() << "); solved again from the wall at rest"
                 << std::endl;
        }
        break;
      }
    }
  }
  return whole_climb(solve_wire_wall_potential(rod, w.radius, wall, mesh, candidates, rigid.x, o));
}

/// A P2 reference's own equilibrium from P1's on the same mesh: P1's (solve_own_equilibrium,
/// from `start`'s P1 equilibrium where it has one), then P2's from P1's wire and P1's field at
/// P2's rows (linear_field_rows). P1 climbs the EI rungs at ~0.3 s per factorisation against
/// P2's 10–13 s; P2's Newton then starts where P1's locked tets stopped (measured in contact.md:
/// it pays in the arch, not on the straight tube's stiffer wires). If P2 fails from there, P2 as
/// without the start (solve_own_equilibrium). The solution's time and Newton steps include P1's.
/// P1's equilibrium is left in `reached`'s x_p1 and u_p1.
PotentialContactSolution solve_p2_from_p1(msm::rods::DerRod& rod, const SceneWire& w, double EI,
                                          const NeoHookeanWall& p2, const NeoHookeanWall& p1,
                                          const TetMesh& mesh, const std::vector<int>& candidates,
                                          const RigidContact& rigid,
                                          const PotentialContactOptions& o,
                                          const PotentialState* start, bool& from_start,
                                          PotentialState& reached) {
  const auto t0 = std::chrono::steady_clock::now();
  std::optional<PotentialState> p1_start;
  if (start != nullptr && start->x_p1.size() > 0) {
    p1_start = PotentialState{start->bending_stiffness, start->x_p1, start->u_p1, {}, {}};
  }
  msm::rods::DerRod p1_rod = rod;
  bool p1_from_start = false;
  const PotentialContactSolution s1 =
      solve_own_equilibrium(p1_rod, w, EI, p1, mesh, candidates, rigid, o,
                            p1_start ? &*p1_start : nullptr, p1_from_start);
  reached.x_p1 = s1.x;
  reached.u_p1 = s1.u;
  if (o.log) {
    *o.log << "contact-models:   P1's equilibrium: F " << s1.total_force_on_wall().norm() * 1e3
           << " mN, " << s1.newton_iterations << " steps, " << s1.seconds << " s; P2 from there"
           << std::endl;
  }
  const Eigen::VectorXd u = linear_field_rows(p2, mesh, p1.nodal(s1.u));
  PotentialContactSolution s;
  try {
    s = solve_wire_wall_potential(rod, w.radius, p2, mesh, candidates, s1.x, o, u);
    from_start = p1_from_start;
  } catch (const std::runtime_error& e) {
    if (o.log) {
      *o.log << "contact-models:   P2 from P1's equilibrium failed (" << e.what()
             << "); P2 without it" << std::endl;
    }
    s = solve_own_equilibrium(rod, w, EI, p2, mesh, candidates, rigid, o, start, from_start);
  }
  s.newton_iterations += s1.newton_iterations;
  s.seconds = seconds_since(t0);
  return s;
}

/// The wall and the wire as one potential: the wall linearised at rest (condensed on a band
/// grown from the first candidates, CondensedLinearWall) or, with options.own_equilibrium, at its
/// own equilibrium (a msm model's own energy, FormWall; deal.II's FEM as the neo-Hookean wall for
/// the reference, every inner-wall node a candidate; a linear FEM model stays condensed), from
/// `start` where given (solve_own_equilibrium). The own equilibrium reached is left in `reached`.
ModelContact solve_wall_potential(const Scene& scene, const ModelSpec& spec, const ModelWall& wall,
                                  SceneWire& w, const RigidContact& rigid, const Problem& p,
                                  double EI, double nu, bool reference,
                                  const ContactModelsOptions& options, const PotentialState* start,
                                  std::optional<PotentialState>& reached) {
  ModelContact out;
  out.name = wall.name;
  out.detail = wall.detail;
  out.linearisation = wall_label(wall, options);
  const auto t0 = std::chrono::steady_clock::now();
  PotentialContactOptions o;
  o.force_scale = EI / (w.length * w.length);
  o.max_newton = options.max_newton;
  o.max_move = options.max_move;
  msm::rods::DerRod rod = w.rod;
  std::unique_ptr<WallPotential> potential;
  PotentialContactSolution s;
  // A linear wall's own equilibrium is its linearisation at rest: condensed on a band.
  const bool linear = !options.own_equilibrium || (!wall.energy.form && !reference);
  out.linear_wall = linear;
  if (linear) {
    GrownPotentialContact grown =
        solve_wire_wall_potential_growing(rod, w.radius, wall.system, *p.mesh, p.nodes, rigid.x, o);
    s = std::move(grown.solution);
    out.candidates = static_cast<int>(grown.wall->band().size());
    out.rounds = grown.rounds;
    potential = std::move(grown.wall);
  } else {
    std::unique_ptr<NeoHookeanWall> p1;  // the P2 reference's start (solve_p2_from_p1)
    if (wall.energy.form) {
      potential = std::make_unique<FormWall>(*wall.energy.form, wall.energy.rest,
                                             wall.system.free_index, wall.system.node_rows);
    } else {
      potential = std::make_unique<NeoHookeanWall>(*p.mesh, wall_problem(scene, nu, spec.degree));
      out.detail += ", compressible neo-Hookean";
      if (reference && spec.degree == 2 && options.p2_from_p1) {
        p1 = std::make_unique<NeoHookeanWall>(*p.mesh, wall_problem(scene, nu, 1));
        out.detail += ", from P1's equilibrium";
      }
    }
    const std::vector<int> candidates =
        p.mesh->group_nodes(p.mesh->require_group("inner_wall", 2, "contact mesh"));
    o.log = options.log;  // an own-equilibrium solve takes minutes (the reference's, an hour)
    // Levenberg–Marquardt damping, as the contact reference's solve_neo_hookean_wall: undamped,
    // Newton on a soft wall dented by millimetres oscillated there (175 steps against 45). (The
    // P2 reference pressed at its vertices alone stalled at EI 4e-5 either way; contact.md.)
    o.damped_newton = true;
    PotentialState state;
    try {
      s = p1 ? solve_p2_from_p1(rod, w, EI, static_cast<const NeoHookeanWall&>(*potential), *p1,
                                *p.mesh, candidates, rigid, o, start, out.from_softer_wire, state)
             : solve_own_equilibrium(rod, w, EI, *potential, *p.mesh, candidates, rigid, o, start,
                                     out.from_softer_wire);
    } catch (const WireThroughWall& e) {
      throw with_inverted_tets(e, *potential, *p.mesh);
    }
    out.candidates = static_cast<int>(candidates.size());
    out.inverted_tets = potential->inverted_tets(*p.mesh, s.u);
    state.bending_stiffness = EI;
    state.x = s.x;
    state.u = s.u;
    reached = std::move(state);
  }
  out.solve_seconds = s.seconds;
  out.setup_seconds = wall.setup_seconds + seconds_since(t0) - s.seconds;
  out.force_on_wall = s.total_force_on_wall();
  out.force = out.force_on_wall.norm();
  out.steps = s.newton_iterations;
  out.tip = s.x.segment<3>(3 * w.layout.tip_node);
  const std::vector<Vec3> u = potential->nodal(s.u);
  describe_zone(p, s.pressed, s.force, u, out);
  out.strain = potential->largest_strain(*p.mesh, s.u);
  if (linear) {
    std::vector<Vec3> loads(p.mesh->nodes.size(), Vec3::Zero());
    for (std::size_t j = 0; j < s.pressed.size(); ++j) {
      loads[static_cast<std::size_t>(s.pressed[j])] += s.force[j] * s.direction[j];
    }
    out.own_imbalance = own_imbalance(wall, u, loads);
  }
  return out;
}

ModelContact failed(const ModelSpec& spec, const std::string& why) {
  ModelContact out;
  out.name = spec.name;
  out.failure = why;
  return out;
}

ModelSpec spec_of(std::string name, ModelKind kind) {
  ModelSpec s;
  s.name = std::move(name);
  s.kind = kind;
  return s;
}

}  // namespace

std::string folded_walls(const ContactModelsRun& run) {
  std::string folded;
  for (const ModelContact& m : run.models) {
    if (!m.failure.empty() || !m.inverted_tets || *m.inverted_tets == 0) continue;
    folded += (folded.empty() ? "" : ", ") + m.name + " (" + std::to_string(*m.inverted_tets) + ")";
  }
  return folded;
}

std::string linear_walls_dented_through(const ContactModelsRun& run, double wall_thickness) {
  std::ostringstream out;
  out.precision(3);
  bool first = true;
  const auto add = [&](const ModelContact& m) {
    if (!m.failure.empty() || !m.linear_wall || m.dent <= wall_thickness) return;
    out << (first ? "" : ", ") << m.name << " (" << m.dent * 1e3 << " mm)";
    first = false;
  };
  add(run.reference);
  for (const ModelContact& m : run.models) add(m);
  return out.str();
}

bool has_contact_wall(const ModelSpec& m) {
  return !(m.kind == ModelKind::network || m.kind == ModelKind::external ||
           m.kind == ModelKind::displacements ||
           (m.kind == ModelKind::surface_msm && m.surface == msm::WallSurface::outer));
}

std::vector<ModelSpec> contact_model_kinds(const Scene& scene) {
  std::vector<ModelSpec> out;
  for (const ModelSpec& m : scene.models) {
    if (has_contact_wall(m)) out.push_back(m);
  }
  std::vector<ModelSpec> extra;
  ModelSpec p1 = spec_of("fem_p1", ModelKind::fem);
  p1.degree = 1;
  extra.push_back(p1);
  ModelSpec mollemans = spec_of("volume_mollemans", ModelKind::volume_msm);
  mollemans.stiffness = msm::StiffnessRule::seed001;
  extra.push_back(mollemans);
  ModelSpec van_gelder = spec_of("volume_van_gelder", ModelKind::volume_msm);
  van_gelder.stiffness = msm::StiffnessRule::van_gelder;
  extra.push_back(van_gelder);
  ModelSpec hybrid = spec_of("volume_hybrid", ModelKind::volume_msm);
  hybrid.stiffness = msm::StiffnessRule::van_gelder;
  hybrid.volume_term = true;
  extra.push_back(hybrid);
  ModelSpec pairs = spec_of("volume_edge_pairs", ModelKind::volume_msm);
  pairs.edge_pairs = true;
  extra.push_back(pairs);
  extra.push_back(spec_of("corotational_fem", ModelKind::corotational_fem));
  extra.push_back(spec_of("xpbd_fem", ModelKind::xpbd_fem));
  ModelSpec mid = spec_of("surface_seed000", ModelKind::surface_msm);
  mid.surface = msm::WallSurface::mid;
  extra.push_back(mid);
  ModelSpec inner = spec_of("surface_seed000_inner", ModelKind::surface_msm);
  inner.surface = msm::WallSurface::inner;
  extra.push_back(inner);
  ModelSpec shells = spec_of("surface_shells", ModelKind::surface_msm);
  shells.surface = msm::WallSurface::mid;
  shells.stiffness = msm::StiffnessRule::van_gelder;
  shells.bending = msm::Bending::discrete_shells;
  extra.push_back(shells);
  // One of each: a scene model of the same name or the same kind and rules stands for it.
  const auto same = [](const ModelSpec& a, const ModelSpec& b) {
    return a.kind == b.kind && a.degree == b.degree && a.surface == b.surface &&
           a.stiffness == b.stiffness && a.volume_term == b.volume_term &&
           a.edge_pairs == b.edge_pairs && a.bending == b.bending && a.calibration.empty() &&
           b.calibration.empty();
  };
  for (const ModelSpec& e : extra) {
    const bool present = std::any_of(out.begin(), out.end(), [&](const ModelSpec& m) {
      return m.name == e.name || same(m, e) ||
             (m.kind == e.kind && (m.kind == ModelKind::corotational_fem ||
                                   m.kind == ModelKind::xpbd_fem || m.edge_pairs));
    });
    if (!present) out.push_back(e);
  }
  return out;
}

bool same_contact_wall(const ModelSpec& a, const ModelSpec& b) {
  const TetFemSpec &ta = a.tet_fem, &tb = b.tet_fem;
  return a.kind == b.kind && a.degree == b.degree && a.surface == b.surface &&
         a.topology == b.topology && a.stiffness == b.stiffness && a.volume_term == b.volume_term &&
         a.volume_moduli == b.volume_moduli && a.edge_pairs == b.edge_pairs &&
         a.bending == b.bending && a.mass == b.mass && a.calibration == b.calibration &&
         a.calibration_transfer == b.calibration_transfer && a.network_file == b.network_file &&
         ta.dt == tb.dt && ta.iterations == tb.iterations &&
         ta.velocity_damping == tb.velocity_damping &&
         ta.settle_relative_change == tb.settle_relative_change && ta.max_steps == tb.max_steps;
}

namespace {

/// The progress line of one wall's contact at one EI (a failed one: the seconds it took to fail).
void log_contact(std::ostream& log, const ModelSpec& wall, std::size_t index, std::size_t walls,
                 double EI, const ModelContact& c, double failed_after) {
  char line[160];
  if (c.failure.empty()) {
    std::snprintf(line, sizeof line, "F %.4f mN, %d pressed, %d steps%s, %.1f s", c.force * 1e3,
                  c.pressed, c.steps,
                  c.from_softer_wire ? " from the softer wire's equilibrium" : "",
                  c.setup_seconds + c.solve_seconds);
  } else {
    std::snprintf(line, sizeof line, "failed after %.1f s", failed_after);
  }
  char ei[32];
  std::snprintf(ei, sizeof ei, "%.3g", EI);
  log << "contact-models: " << wall.name << " (" << index + 1 << " of " << walls << "), EI " << ei
      << " N·m²: " << line << std::endl;
}

/// One wall (`spec`, the k-th of `walls`; k = 0 the reference) solved at each run's EI, at own
/// equilibrium each EI from the last one's equilibrium (ContactModelsOptions::from_softer_wire);
/// its failures recorded with their reasons.
void solve_wall_at_every_stiffness(const Scene& scene, const ModelSpec& spec, std::size_t k,
                                   std::size_t walls,
                                   const std::vector<std::unique_ptr<SceneWire>>& wires,
                                   const std::vector<RigidContact>& rigid, const Problem& p,
                                   const ContactModelsOptions& options, ContactModels& out) {
  std::optional<ModelWall> wall;
  std::string why;
  try {
    wall.emplace(model_wall(scene, spec, *p.mesh, *p.vessel, out.nu));
  } catch (const std::exception& ex) {
    why = ex.what();
  }
  std::optional<PotentialState> softer;  // this wall's equilibrium at the EI before
  for (std::size_t e = 0; e < out.runs.size(); ++e) {
    const double EI = out.runs[e].bending_stiffness;
    ModelContact c;
    const auto t0 = std::chrono::steady_clock::now();
    if (!wall) {
      c = failed(spec, why);
    } else {
      const bool chain = softer && options.from_softer_wire && softer->bending_stiffness < EI;
      std::optional<PotentialState> reached;
      try {
        c = options.own_equilibrium || !options.active_set
                ? solve_wall_potential(scene, spec, *wall, *wires[e], rigid[e], p, EI, out.nu,
                                       k == 0, options, chain ? &*softer : nullptr, reached)
                : solve_wall_active_set(*wall, *wires[e], rigid[e], p, EI, options);
        softer = std::move(reached);
      } catch (const std::exception& ex) {
        c = failed(spec, ex.what());
        c.detail = wall->detail;
        c.linearisation = wall_label(*wall, options);
      }
    }
    if (options.log) log_contact(*options.log, spec, k, walls, EI, c, seconds_since(t0));
    if (k == 0) {
      out.runs[e].reference = c;  // a failed reference leaves the run's errors undefined
    } else {
      out.runs[e].models.push_back(c);
    }
  }
}

/// Every wall once, solved at each run's EI: the reference first, then the models; a wall whose
/// solve fails is recorded with its reason. A model whose wall an earlier model has
/// (same_contact_wall) takes that model's contacts under its own name, without a solve.
void solve_every_wall(const Scene& scene, const std::vector<ModelSpec>& models,
                      const std::vector<std::unique_ptr<SceneWire>>& wires,
                      const std::vector<RigidContact>& rigid, const Problem& p,
                      const ContactModelsOptions& options, ContactModels& out) {
  ModelSpec reference;
  reference.name = "reference_fem_p" + std::to_string(options.reference_degree);
  reference.kind = ModelKind::fem;
  reference.degree = options.reference_degree;
  std::vector<const ModelSpec*> walls{&reference};
  for (const ModelSpec& m : models) walls.push_back(&m);
  for (std::size_t k = 0; k < walls.size(); ++k) {
    const auto here = walls.begin() + static_cast<std::ptrdiff_t>(k);
    const auto twin =
        k == 0 ? here : std::find_if(walls.begin() + 1, here, [&](const ModelSpec* w) {
          return same_contact_wall(*w, *walls[k]);
        });
    if (twin == here) {
      const ScopedSolverThreads threads(k == 0 ? options.reference_threads : 1);
      solve_wall_at_every_stiffness(scene, *walls[k], k, walls.size(), wires, rigid, p, options,
                                    out);
      continue;
    }
    const std::size_t j = static_cast<std::size_t>(twin - walls.begin()) - 1;
    for (ContactModelsRun& run : out.runs) {
      ModelContact c = run.models[j];
      c.name = walls[k]->name;
      run.models.push_back(c);
    }
    if (options.log) {
      *options.log << "contact-models: " << walls[k]->name << " (" << k + 1 << " of "
                   << walls.size() << "): the wall of " << (*twin)->name << ", its contacts"
                   << std::endl;
    }
  }
}

}  // namespace

ContactModels solve_contact_models(const Scene& scene, const std::vector<ModelSpec>& models,
                                   const ContactModelsOptions& options) {
  const std::string file = scene.source.string();
  if (!scene.load.guidewire) {
    throw InputError(file +
                     ": load: expected type = \"guidewire\" (the wire the walls are "
                     "pressed by)");
  }
  if (scene.vessel.kind != VesselKind::straight && scene.vessel.kind != VesselKind::arch) {
    throw InputError(file +
                     ": vessel.kind: the contact models' mesh is refined around the wire's "
                     "contact by gmsh; expected kind = \"straight\" or \"arch\"");
  }
  if (options.reference_threads < 1) {
    throw InputError("contact-models: reference_threads: expected at least 1, got " +
                     std::to_string(options.reference_threads));
  }
  const GuidewireSpec& spec = *scene.load.guidewire;
  ContactModels out;
  out.nu = scene.poisson_ratios.front();
  std::vector<double> EIs = options.bending_stiffness;
  if (EIs.empty()) {
    EIs = {msm::rods::solid_section({spec.young, spec.shear, spec.density}, spec.diameter).EI};
  }
  std::vector<std::unique_ptr<SceneWire>> wires;
  std::vector<RigidContact> rigid;
  for (const double EI : EIs) {
    wires.push_back(std::make_unique<SceneWire>(spec, EI));
    try {
      rigid.push_back(rigid_contact(*wires.back(), scene.vessel));
    } catch (const InputError& e) {
      throw InputError(file + ": " + e.what());
    }
  }
  VesselParams vessel = scene.vessel;
  vessel.style = MeshStyle::unstructured;
  const TetMesh mesh = refined_balls_mesh(
      vessel, refined_balls(rigid, *wires.front(), vessel, options), options.fine_size);
  out.mesh_nodes = mesh.nodes.size();
  out.mesh_tets = mesh.tets.size();
  Problem p;
  p.mesh = &mesh;
  p.vessel = &vessel;
  set_first_candidates(p, rigid.front().wall_point, options.band_radius);
  for (std::size_t e = 0; e < EIs.size(); ++e) {
    ContactModelsRun run;
    run.bending_stiffness = EIs[e];
    run.rigid_force = rigid[e].force;
    run.rigid_wall_point = rigid[e].wall_point;
    out.runs.push_back(run);
  }
  solve_every_wall(scene, models, wires, rigid, p, options, out);
  return out;
}

}  // namespace vessel::contact
