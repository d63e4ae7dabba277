#include "verification/guidewire/guidewire_load.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <sstream>

#include "fem_reference/rod_theory/tube_contact.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/rods/corde_rod.hpp"
#include "msm/rods/der_rod.hpp"
#include "msm/rods/rigid_wall.hpp"
#include "msm/rods/xpbd_rod.hpp"
#include "verification/guidewire/wire_exchange.hpp"

namespace vessel {

namespace rods = msm::rods;

ContactWall parse_contact_wall(const std::string& name) {
  if (name == "linear") return ContactWall::linear;
  if (name == "neo-hookean") return ContactWall::neo_hookean;
  throw InputError("wall: expected \"linear\" or \"neo-hookean\", got \"" + name + "\"");
}

// XPBD's static solve is a damped dynamic run to rest, 30 % of the velocity removed per step,
// in steps of a haptic frame. Its steady state does not depend on the step (the same force to 8
// digits from 0.05 to 2 ms, N = 32, guidewire_straight; tests/rods/test_rigid_wall.cpp).
constexpr double kXpbdRelaxStep = 1e-3;
constexpr double kXpbdRelaxDamping = 0.3;
constexpr int kXpbdMaxRelaxSteps = 20000;  // ≤ 900 taken on the guidewire scenes

std::unique_ptr<rods::RigidLumen> rigid_lumen(const VesselParams& vessel, double offset) {
  if (vessel.kind == VesselKind::straight) {
    return std::make_unique<rods::StraightTube>(Vec3::Zero(), Vec3::UnitZ(), offset);
  }
  return std::make_unique<rods::TorusBend>(Vec3::Zero(), Vec3::UnitZ(), vessel.bend_radius, offset);
}

std::vector<Vec3> bearing_band(const VesselParams& vessel, const GuidewireSpec& spec,
                               const rods::RodLayout& layout, const Eigen::VectorXd& rigid_state,
                               double near_wall, double spacing) {
  const auto lumen = rigid_lumen(vessel, vessel.inner_radius);
  std::vector<Vec3> shape;  // the two shapes, sampled `spacing` apart, their ends included
  auto sample = [&](const Vec3& a, const Vec3& b) {
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / spacing)));
    for (int k = 0; k < n; ++k) shape.push_back(a + (b - a) * (static_cast<double>(k) / n));
  };
  for (int i = layout.first_node; i < layout.tip_node; ++i) {
    sample(rigid_state.segment<3>(3 * i), rigid_state.segment<3>(3 * i + 3));
  }
  shape.push_back(rigid_state.segment<3>(3 * layout.tip_node));
  const Vec3 clamp = spec.clamp_point, t = spec.clamp_direction.normalized();
  sample(clamp, clamp + spec.insertion * t);
  shape.push_back(clamp + spec.insertion * t);
  std::vector<Vec3> band;
  for (const Vec3& p : shape) {
    Vec3 gradient;
    const double g = lumen->gap(p, &gradient, nullptr);
    if (g > near_wall) continue;
    // g = a − the distance from the lumen's axis: ∇g, of unit length, points inward.
    const Vec3 on_wall = p - g * gradient;
    const bool near = std::any_of(band.begin(), band.end(),
                                  [&](const Vec3& q) { return (q - on_wall).norm() < spacing; });
    if (!near) band.push_back(on_wall);
  }
  return band;
}

struct GuidewireSolver::Impl {
  VesselParams vessel;
  GuidewireSpec spec;
  std::string prefix;
  rods::RodMaterial material;
  double EI = 0.0;
  double offset = 0.0;  ///< the centreline's allowed distance from the vessel's: a − r_wire
  Eigen::VectorXd state;  ///< the last solution's rod state (empty before the first solve)
  double state_length = 0.0;
  std::filesystem::path case_dir;  ///< model external: its case folder (made on first use)
  /// model xpbd: the last solve's rod and the lumen it is held in (step() advances them).
  std::unique_ptr<rods::XpbdRod> xpbd;
  std::unique_ptr<rods::RigidLumen> xpbd_wall;

  [[nodiscard]] std::unique_ptr<rods::RigidLumen> lumen(double give) const {
    return rigid_lumen(vessel, offset + give);
  }

  /// The wire of length L against the lumen grown by `give`, from the last state (scaled about
  /// the clamp to L) or straight.
  GuidewireSolution solve(double L, double give) {
    const rods::RodSpec rs = guidewire_rod_spec(spec, L);
    switch (spec.model) {
      case WireModel::external: return solve_external(L, give);
      case WireModel::xpbd: return solve_xpbd(rods::make_layout(rs), rs.origin, L, give);
      case WireModel::corde: {
        rods::CordeRod rod(rods::make_layout(rs));
        return solve_rod(rod, rs.origin, L, give);
      }
      case WireModel::der: break;
    }
    rods::DerRod rod(rods::make_layout(rs));
    return solve_rod(rod, rs.origin, L, give);
  }

  /// The user's program on the wire of length L (verification/guidewire/wire_exchange.hpp), in a folder of
  /// its own that the solver removes.
  GuidewireSolution solve_external(double L, double give) {
    if (case_dir.empty()) {
      std::string pattern =
          (std::filesystem::temp_directory_path() / "vesselverify-wire-XXXXXX").string();
      if (!mkdtemp(pattern.data())) throw std::runtime_error("guidewire: cannot make a case folder");
      case_dir = pattern;
    }
    const WireLumen l{vessel.kind != VesselKind::straight, vessel.bend_radius, offset + give};
    write_wire_case(case_dir, "", spec, L, l);
    const WireAnswer a = run_wire_case(spec, case_dir, spec.segments + 1);
    GuidewireSolution s;
    s.bending_stiffness = EI;
    s.centreline = a.centreline;
    s.clamp_force.setConstant(std::numeric_limits<double>::quiet_NaN());  // not reported
    if (a.force > 0.0) {
      const auto wall = lumen(give);
      const Vec3 p = a.centreline[static_cast<std::size_t>(a.node)];
      Vec3 grad;
      wall->gap(p, &grad, nullptr);
      s.force = a.force;
      s.contact_nodes = 1;
      s.contact_point = p;
      s.normal = -grad.normalized();
      s.wall_point = p + 0.5 * spec.diameter * s.normal;
    }
    return s;
  }

  /// XPBD's steady state against the lumen: the damped dynamic run (kXpbdRelaxStep) until a
  /// step moves no node by more than 1e-14 L, from the last state scaled to L. The rod stays in
  /// `xpbd` for step().
  GuidewireSolution solve_xpbd(const rods::RodLayout& layout, const Vec3& origin, double L,
                               double give) {
    rods::XpbdOptions options;  // direct, 2 iterations, warm-started multipliers
    options.damping = kXpbdRelaxDamping;
    auto rod = std::make_unique<rods::XpbdRod>(layout, 0.0, options);
    if (state.size() == rod->state().size()) {
      rod->set_state(scaled_state(origin, L, rod->energy_model().num_nodes()));
    }
    auto wall = lumen(give);  // kept with the rod only once it has settled
    rod->set_wall(wall.get(), 2, rod->tip_node());
    const int steps = rod->relax(kXpbdRelaxStep, Eigen::VectorXd::Zero(rod->state().size()),
                                 1e-14, kXpbdMaxRelaxSteps);
    if (steps == kXpbdMaxRelaxSteps) {
      throw std::runtime_error("guidewire: the XPBD wire did not settle in " +
                               std::to_string(kXpbdMaxRelaxSteps) + " steps");
    }
    xpbd = std::move(rod);
    xpbd_wall = std::move(wall);
    state = xpbd->state();
    state_length = L;
    return xpbd_solution();
  }

  /// The XPBD rod's current state as a solution: its wall forces from the carried contact
  /// multipliers; the clamp's force is ∇Π at the held nodes (its constraints are compliant
  /// energy terms, so at a steady state the held nodes' internal force is the clamp's).
  GuidewireSolution xpbd_solution() const {
    const rods::CordeRod& model = xpbd->energy_model();
    const Eigen::VectorXd& x = xpbd->state();
    const std::vector<double> f = xpbd->wall_forces();
    rods::ContactSolution c;
    c.x = x;
    for (int i = 0; i < static_cast<int>(f.size()); ++i) {
      if (f[i] > 0.0) {
        c.nodes.push_back(i);
        c.forces.push_back(f[i]);
      }
    }
    Eigen::VectorXd g;
    model.gradient(x, g);
    return solution_from(model, c, g, *xpbd_wall);
  }

  ~Impl() {
    std::error_code ec;
    if (!case_dir.empty()) std::filesystem::remove_all(case_dir, ec);
  }

  /// `rod` (DER, or CORDE with its constraints) against the lumen, from the last state (readied
  /// by the rod's prepare hook) or its rest state.
  GuidewireSolution solve_rod(rods::Rod& rod, const Vec3& origin, double L, double give) {
    Eigen::VectorXd x = rod.rest_state();
    if (state.size() == x.size()) {
      x = scaled_state(origin, L, rod.num_nodes());
      rod.prepare(x);
    }
    rods::ConstrainedOptions options;
    options.force_scale = EI / (L * L);
    const auto wall = lumen(give);
    const int tip = rod.layout().tip_node;
    const msm::EqualityConstraints* constraints = rod.constraints();
    const rods::ContactSolution c =
        rods::solve_wall_contact(rod, constraints, rod.clamp_fixed(), x, *wall, 2, tip, options);
    state = c.x;
    state_length = L;
    // The clamp's force on the wire: the internal force at the held nodes (no load acts there),
    // ∇Π plus, for CORDE, its inextensibility constraints' force Jᵀλ there.
    Eigen::VectorXd g;
    rod.gradient(c.x, g);
    if (constraints) {
      msm::SparseMatrix J;
      constraints->jacobian(c.x, J);
      g += J.transpose() * c.rod_multipliers;
    }
    return solution_from(rod, c, g, *wall);
  }

  /// The last state's positions scaled about the clamp to length L (the frames' directions are
  /// unchanged by it).
  Eigen::VectorXd scaled_state(const Vec3& origin, double L, int nodes) const {
    Eigen::VectorXd x = state;
    for (int i = 0; i < nodes; ++i) {
      x.segment<3>(3 * i) = origin + (L / state_length) * (state.segment<3>(3 * i) - origin);
    }
    return x;
  }

  /// The solution record of a rod's contact solution `c`, with `internal` its internal force
  /// (whose sum over the held nodes is the clamp's force on the wire).
  GuidewireSolution solution_from(const rods::Rod& rod, const rods::ContactSolution& c,
                                  const Eigen::VectorXd& internal, const rods::RigidLumen& wall) const {
    GuidewireSolution s;
    s.bending_stiffness = EI;
    s.contact_nodes = static_cast<int>(c.nodes.size());
    const int tip = rod.layout().tip_node;
    for (int i = rod.layout().first_node; i <= tip; ++i) s.centreline.push_back(c.x.segment<3>(3 * i));
    if (!c.nodes.empty()) {
      const int k = c.nodes.front();
      const Vec3 p = c.x.segment<3>(3 * k);
      Vec3 grad;
      wall.gap(p, &grad, nullptr);
      s.force = c.forces.front();
      s.contact_point = p;
      s.normal = -grad.normalized();  // the gap grows towards the centreline
      s.wall_point = p + 0.5 * spec.diameter * s.normal;
    }
    const std::vector<char> fixed = rod.clamp_fixed();
    for (int i = 0; i < rod.num_nodes(); ++i) {
      if (fixed[3 * i]) s.clamp_force += internal.segment<3>(3 * i);
    }
    return s;
  }
};

rods::RodSpec guidewire_rod_spec(const GuidewireSpec& spec, double length) {
  rods::RodSpec rs = rods::uniform_rod({spec.young, spec.shear, spec.density}, length,
                                       spec.diameter, spec.segments);
  rs.origin = spec.clamp_point;
  rs.direction = spec.clamp_direction;
  return rs;
}

GuidewireSpec with_stiffness(GuidewireSpec spec, double EI) {
  if (!(EI > 0.0) || !std::isfinite(EI)) {
    throw InputError("the wire's bending stiffness EI: found " + std::to_string(EI) +
                     " N·m², expected a positive finite value");
  }
  const double I = M_PI * std::pow(spec.diameter, 4) / 64.0;
  const double scale = EI / (spec.young * I);
  spec.young *= scale;
  spec.shear *= scale;
  return spec;
}

GuidewireSolver::GuidewireSolver(const VesselParams& vessel, const GuidewireSpec& spec,
                                 const std::string& key_prefix)
    : impl_(std::make_unique<Impl>()) {
  check_guidewire(vessel, spec, key_prefix);
  Impl& m = *impl_;
  m.vessel = vessel;
  m.spec = spec;
  m.prefix = key_prefix;
  m.material = {spec.young, spec.shear, spec.density};
  m.EI = rods::solid_section(m.material, spec.diameter).EI;
  m.offset = vessel.inner_radius - 0.5 * spec.diameter;
}

void check_guidewire(const VesselParams& vessel, const GuidewireSpec& spec,
                     const std::string& key_prefix) {
  require_parametric(vessel, "a guidewire load (its lumen is the vessel's centreline offset)");
  const double offset = vessel.inner_radius - 0.5 * spec.diameter;
  if (offset <= 0.0) {
    throw InputError(key_prefix + "diameter: found " + std::to_string(spec.diameter) +
                     " m, expected less than the lumen's diameter " +
                     std::to_string(2.0 * vessel.inner_radius) + " m");
  }
  if (rigid_lumen(vessel, offset)->gap(spec.clamp_point, nullptr, nullptr) < 0.0) {
    throw InputError(key_prefix + "clamp_point: the clamp is outside the lumen (its distance "
                     "from the vessel's centreline exceeds the lumen radius less the wire's)");
  }
}

GuidewireSolver::~GuidewireSolver() = default;

GuidewireSolution GuidewireSolver::solve_rigid() {
  Impl& m = *impl_;
  m.state.resize(0);
  // Insertion in steps of at most half the lumen radius, each from the last shape.
  const double step = m.vessel.inner_radius / 2.0;
  const int n = std::max(2, static_cast<int>(std::ceil(m.spec.insertion / step)));
  GuidewireSolution s;
  // The user's program solves the whole insertion itself.
  for (int k = m.spec.model == WireModel::external ? n : 1; k <= n; ++k) {
    s = m.solve(m.spec.insertion * k / n, 0.0);
  }
  if (s.contact_nodes > 1) {
    throw InputError(m.prefix + "insertion: the wire of " + std::to_string(m.spec.insertion) +
                     " m touches the wall at " + std::to_string(s.contact_nodes) +
                     " nodes; expected a single contact (a shorter insertion or another tilt)");
  }
  rigid_ = s;
  last_ = s;
  compliance_ = 0.0;
  return s;
}

const Eigen::VectorXd& GuidewireSolver::rod_state() const { return impl_->state; }

GuidewireSolution GuidewireSolver::solve_with_give(double give) {
  Impl& m = *impl_;
  last_ = m.solve(m.spec.insertion, give);
  return last_;
}

GuidewireSolution GuidewireSolver::solve_at_insertion(double insertion) {
  last_ = impl_->solve(insertion, 0.0);
  return last_;
}

GuidewireSolution GuidewireSolver::step(double h) {
  Impl& m = *impl_;
  if (!m.xpbd) throw std::logic_error("GuidewireSolver::step: no XPBD wire solved yet");
  m.xpbd->step(h, Eigen::VectorXd::Zero(m.xpbd->state().size()));
  last_ = m.xpbd_solution();
  return last_;
}

double GuidewireSolver::compliance() {
  if (compliance_ > 0.0) return compliance_;
  const double d = 1e-4 * impl_->offset;
  const double f_plus = solve_with_give(d).force;
  const double f_minus = solve_with_give(-d).force;
  solve_with_give(0.0);
  compliance_ = -2.0 * d / (f_plus - f_minus);
  return compliance_;
}

double GuidewireSolver::coupled_force(double C) {
  const double F0 = rigid_.force;
  if (F0 <= 0.0 || C <= 0.0) return F0;
  const auto h = [&](double F) { return F - solve_with_give(C * F).force; };
  // Start from the rigid force and the series-spring estimate with the wire's own compliance.
  double a = F0, ha = h(a);
  const double Cr = compliance();
  double b = F0 * Cr / (Cr + C), hb = h(b);
  for (int it = 0; it < 40 && std::abs(hb) > 1e-12 * F0; ++it) {
    const double c = b - hb * (b - a) / (hb - ha);
    a = b;
    ha = hb;
    b = std::max(c, 0.0);
    hb = h(b);
  }
  if (std::abs(hb) > 1e-9 * F0) {
    std::ostringstream msg;
    msg << "guidewire: the coupling with a wall of compliance " << C
        << " m/N did not converge (residual " << hb << " N)";
    throw std::runtime_error(msg.str());
  }
  solve_with_give(C * b);
  return b;
}

namespace {

std::string number(double v) {
  std::ostringstream s;
  s.precision(7);
  s << v;
  return s.str();
}

/// The straight tube's continuum wire: clamp on the axis at the inlet (z = 0), tilted by θ from
/// it; the tip touches at axial distance z_c, c = a − r_wire off the axis, in the tilt's plane.
std::optional<WireReference> straight_reference(const VesselParams& v, const GuidewireSpec& w,
                                                std::string& why) {
  if (w.clamp_point.norm() > 1e-12) {
    why = "the straight tube's continuum wire is clamped on the axis at the inlet; this clamp is "
          "elsewhere";
    return std::nullopt;
  }
  const Vec3 d = w.clamp_direction.normalized();
  const Vec3 across(d.x(), d.y(), 0.0);
  if (across.norm() < 1e-9 || d.z() <= 0.0) {
    why = "the straight tube's continuum wire is tilted from the axis into the tube; this one is not";
    return std::nullopt;
  }
  const double theta = std::atan2(across.norm(), d.z());
  const double c = v.inner_radius - 0.5 * w.diameter;
  const double z = rod_theory::straight_tube_contact_distance(theta, c, w.insertion);
  const rod_theory::StraightTubeContact s = rod_theory::straight_tube_contact(theta, c / z);
  const double EI = msm::rods::solid_section({w.young, w.shear, w.density}, w.diameter).EI;
  WireReference r;
  r.force = s.force * EI / (z * z);
  r.contact_point = Vec3(0.0, 0.0, z) + c * across.normalized();
  r.what = "Kirchhoff shooting, straight tube: θ_in = " + number(theta) + " rad, F·z²/EI = " +
           number(s.force) + ", L/z = " + number(s.length) + " at z = " + number(z * 1e3) + " mm";
  return r;
}

/// The arch's continuum wire: clamped tangentially on the centreline at the inlet, its tip on
/// the outer wall (less the wire's radius) at the apex, a quarter turn on.
std::optional<WireReference> arch_reference(const VesselParams& v, const GuidewireSpec& w,
                                            std::string& why) {
  const double R = v.bend_radius;
  if ((w.clamp_point - Vec3(R, 0.0, 0.0)).norm() > 1e-12 * R ||
      (w.clamp_direction.normalized() - Vec3::UnitY()).norm() > 1e-9) {
    why = "the arch's continuum wire is clamped tangentially on the centreline at the inlet; "
          "this clamp is not";
    return std::nullopt;
  }
  const double outer = R + v.inner_radius - 0.5 * w.diameter;
  const rod_theory::ArchApexContact a = rod_theory::arch_apex_contact(outer / R);
  if (std::abs(w.insertion / (a.length * R) - 1.0) > 1e-3) {
    why = "the arch's continuum wire touches at the apex at insertion " + number(a.length * R * 1e3) +
          " mm; this wire is inserted " + number(w.insertion * 1e3) + " mm";
    return std::nullopt;
  }
  const double EI = msm::rods::solid_section({w.young, w.shear, w.density}, w.diameter).EI;
  WireReference r;
  r.force = a.force * EI / (R * R);
  r.contact_point = Vec3(0.0, outer, 0.0);
  r.what = "quarter-wave elastica at the arch's apex: k = " + number(a.modulus) +
           ", F·R²/EI = " + number(a.force) + ", L/R = " + number(a.length);
  return r;
}

}  // namespace

std::optional<WireReference> continuum_wire(const VesselParams& vessel, const GuidewireSpec& spec,
                                            std::string& why) {
  try {
    if (vessel.kind == VesselKind::straight) return straight_reference(vessel, spec, why);
    if (vessel.kind == VesselKind::arch) return arch_reference(vessel, spec, why);
  } catch (const std::exception& e) {  // e.g. shooting without convergence: a wire short of the wall
    why = std::string("the continuum wire could not be solved: ") + e.what();
    return std::nullopt;
  }
  why = "no continuum wire for this vessel";
  return std::nullopt;
}

void set_tilted_clamp(const VesselParams& vessel, double tilt, const Vec3& towards,
                      GuidewireSpec& spec) {
  require_parametric(vessel, "a guidewire clamped at the inlet");
  Vec3 tangent = Vec3::UnitZ();
  spec.clamp_point = Vec3::Zero();
  if (vessel.kind == VesselKind::arch) {
    spec.clamp_point = Vec3(vessel.bend_radius, 0.0, 0.0);
    tangent = Vec3::UnitY();
  }
  Vec3 normal = towards - towards.dot(tangent) * tangent;
  if (normal.norm() < 1e-12 * std::max(1.0, towards.norm())) {
    throw InputError("found a direction along the inlet's tangent; expected one "
                     "with a part normal to it");
  }
  normal.normalize();
  spec.clamp_direction = std::cos(tilt) * tangent + std::sin(tilt) * normal;
}

std::string describe_guidewire_solve(const GuidewireSpec& spec) {
  std::ostringstream s;
  if (spec.model == WireModel::external) {
    s << "external program `";
    for (std::size_t i = 0; i < spec.command.size(); ++i) s << (i ? " " : "") << spec.command[i];
    s << " <manifest>` (in " << (spec.working_dir.empty() ? "." : spec.working_dir.string())
      << ", time limit " << spec.timeout_s
      << " s) would be run by `vesselverify run` (and the other commands that solve the "
         "scene); not run now";
  } else {
    s << "the " << to_string(spec.model) << " rod (" << spec.segments << " segments, EI = "
      << rods::solid_section({spec.young, spec.shear, spec.density}, spec.diameter).EI
      << " N·m²) against the rigid lumen would be solved by `vesselverify run` (and the other "
         "commands that solve the scene); not solved now";
  }
  if (spec.coupling == GuidewireCoupling::contact) {
    s << "; coupling contact: `vesselverify run` would then press each model's wall and the FEM "
         "P2 wall"
      << (spec.contact_wall == ContactWall::neo_hookean
              ? std::string(" (at finite strain: the neo-Hookean reference") +
                    (spec.contact_p1_start ? " from P1's equilibrium" : "") +
                    ", each model at its own equilibrium)"
              : std::string(" (linearised at rest)"))
      << " with the wire in a contact solve at the wire's EI and each of stiffness_sweep on a "
         "mesh refined to "
      << spec.contact_fine_size * 1e3 << " mm within " << spec.contact_fine_radius * 1e3
      << " mm of its contact (minutes; --quick at the wire's EI alone)";
  }
  return s.str();
}

}  // namespace vessel
