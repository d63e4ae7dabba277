// The guidewire's critical steps: explicit DER found by bisection against the closed forms, the
// implicit rod integrators run at large steps (rod_steps.hpp).
#include "verification/studies/stability/rod_steps.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <utility>

#include "msm/rods/corde_rod.hpp"
#include "msm/rods/der_rod.hpp"
#include "msm/rods/rod_dynamics.hpp"
#include "msm/rods/xpbd_rod.hpp"
#include "msm/solvers/critical_step.hpp"
#include "msm/stability/stability_search.hpp"
#include "verification/guidewire/guidewire_spec.hpp"
#include "verification/harness/timing.hpp"
#include "verification/studies/stability/study_models.hpp"

namespace vessel::stability_study {

namespace rods = msm::rods;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kBlowup = 1e3;  // as the vessel rows: energy beyond 1000× its start diverged
/// The implicit trials' initial speed, m/s: the same at every step (a speed that scales with 1/dt,
/// as the explicit trials', would fall below Newton's tolerance at a 30 Hz step and move nothing).
constexpr double kImplicitSpeed = 1e-3;

RodStepRow base_row(const rods::RodLayout& layout, WireModel model, const char* integrator) {
  RodStepRow row;
  row.model = to_string(model);
  row.integrator = integrator;
  int material = 0;
  for (const char g : layout.ghost) material += g ? 0 : 1;
  row.segments = material;
  row.h = layout.total_length() / material;
  const RodStepClosedForm cf = rod_step_closed_form(layout.section.at(1), row.h);
  row.axial_dt = cf.axial_dt;
  row.twist_dt = cf.twist_dt;
  row.bending_dt = cf.bending_dt;
  row.closed_form_dt = cf.dt;
  row.omega_max = row.predicted_dt = row.found_dt = row.unstable_dt = kNaN;
  return row;
}

msm::Problem der_problem(const rods::DerRod& rod) {
  msm::Problem p;
  p.form = &rod;
  p.rest = rod.rest_state();
  p.external_force = Eigen::VectorXd::Zero(rod.num_dofs());
  p.mass = rod.lumped_mass();
  p.fixed = rod.clamp_fixed();
  return p;
}

/// Random velocity of amplitude `speed` on the free position dofs (frames at rest).
Eigen::VectorXd position_velocity(int nodes, int dofs, const std::vector<char>& fixed,
                                  double speed) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd v = Eigen::VectorXd::Zero(dofs);
  for (int i = 0; i < 3 * nodes; ++i) v[i] = fixed[i] ? 0.0 : speed * u(rng);
  return v;
}

/// Runs `trial(dt)` (bounded or not, or throws) at each step; records the outcomes.
template <class Trial>
void run_ladder(RodStepRow& row, const std::vector<double>& dts, int steps, Trial&& trial) {
  Stopwatch clock;
  row.steps_per_trial = steps;
  for (const double dt : dts) {
    bool ok = false;
    try {
      ok = trial(dt);
    } catch (const std::exception& e) {
      if (row.failure.empty()) row.failure = "dt " + fmt(dt) + " s: " + short_error(e.what());
    }
    row.steps_tried.push_back(dt);
    row.bounded.push_back(ok);
    ++row.trials;
  }
  row.seconds = clock.seconds();
}

}  // namespace

RodStepClosedForm rod_step_closed_form(const rods::SectionStiffness& s, double h) {
  RodStepClosedForm cf;
  cf.h = h;
  cf.axial_dt = h / std::sqrt(s.EA / s.rhoA);                 // 2/ω, ω = (2/h)√(EA/ρA)
  cf.twist_dt = h / std::sqrt(s.GJ / s.rhoJ);                 // 2/ω, ω = (2/h)√(GJ/ρJ)
  cf.bending_dt = h * h / (2.0 * std::sqrt(s.EI / s.rhoA));   // 2/ω, ω = (4/h²)√(EI/ρA)
  cf.dt = std::min({cf.axial_dt, cf.twist_dt, cf.bending_dt});
  return cf;
}

RodStepRow der_explicit_row(const rods::RodLayout& layout, msm::Integrator integrator,
                            int steps) {
  Stopwatch clock;
  RodStepRow row = base_row(layout, WireModel::der, msm::to_string(integrator).c_str());
  const rods::DerRod rod(layout);
  const msm::Problem p = der_problem(rod);
  const msm::Spectrum s = msm::analyse_spectrum(p, {.lowest = false});
  row.omega_max = s.omega_max;
  row.predicted_dt = msm::predicted_critical_step(integrator, s);
  msm::StabilitySearchOptions so;
  so.integrator = integrator;
  so.steps = steps;
  so.tolerance = 5e-3;
  const msm::StabilitySearchResult r = msm::find_stable_step(p, row.closed_form_dt, so);
  row.found_dt = r.stable_dt;
  row.unstable_dt = r.unstable_dt;
  row.trials = r.trials;
  row.steps_per_trial = steps;
  row.seconds = clock.seconds();
  return row;
}

RodStepRow implicit_row(rods::Rod& rod, WireModel model, const std::vector<double>& dts,
                        int steps) {
  RodStepRow row = base_row(rod.layout(), model, "implicit-euler");
  const std::vector<char> fixed = rod.clamp_fixed();
  const Eigen::VectorXd mass = rod.lumped_mass();
  run_ladder(row, dts, steps, [&](double dt) {
    Eigen::VectorXd x = rod.rest_state();
    Eigen::VectorXd v = position_velocity(rod.num_nodes(), rod.num_dofs(), fixed, kImplicitSpeed);
    rod.prepare(x);
    const auto energy = [&] { return rod.energy(x) + 0.5 * v.dot(mass.cwiseProduct(v)); };
    const double start = energy();
    for (int k = 0; k < steps; ++k) {
      rods::RodStep next = rods::rod_implicit_euler_step(rod, x, v, Eigen::VectorXd(), dt, fixed);
      x = std::move(next.x);
      v = std::move(next.v);
      const double e = energy();
      if (!std::isfinite(e) || e > start * (1.0 + kBlowup)) return false;
    }
    return true;
  });
  return row;
}

RodStepRow xpbd_row(const rods::RodLayout& layout, const std::vector<double>& dts, int steps) {
  RodStepRow row = base_row(layout, WireModel::xpbd, "xpbd");
  run_ladder(row, dts, steps, [&](double dt) {
    rods::XpbdRod rod(layout);
    const rods::CordeRod& model = rod.energy_model();
    const Eigen::VectorXd rest = rod.state();
    // A transverse tip load held 5 steps, then released: small (a static deflection of 1e-4 L on
    // the linear cantilever, 3EI/L³ per metre), so that what follows is the linear response.
    Eigen::VectorXd force = Eigen::VectorXd::Zero(rest.size());
    const double L = layout.total_length();
    force[3 * rod.tip_node() + 1] = 3e-4 * layout.section.at(1).EI / (L * L);
    // Energy: the rod's potential (CordeRod's, the XPBD rod's energy) plus the nodes' kinetic
    // energy from the step's displacement; unbounded when it grows 1000× after the release.
    double released = 0.0;
    Eigen::VectorXd previous = rest;
    for (int k = 0; k < steps; ++k) {
      if (k == 5) force.setZero();
      rod.step(dt, force);
      const Eigen::VectorXd& x = rod.state();
      double e = model.energy(x), moved = 0.0;
      for (int i = 0; i < model.num_nodes(); ++i) {
        const Eigen::Vector3d v = (x.segment<3>(3 * i) - previous.segment<3>(3 * i)) / dt;
        e += 0.5 * layout.node_mass(i) * v.squaredNorm();
        moved = std::max(moved, (x.segment<3>(3 * i) - rest.segment<3>(3 * i)).norm());
      }
      previous = x;
      if (k == 4) released = e;
      if (!x.allFinite() || (k >= 5 && e > (1.0 + kBlowup) * released)) {
        std::ostringstream why;
        why << "step " << k << ": largest displacement " << moved << " m, energy " << e
            << " J against " << released << " J at release";
        throw std::runtime_error(why.str());
      }
    }
    return true;
  });
  return row;
}

std::vector<RodStepRow> rod_critical_steps(const RodWire& w, int steps, std::ostream& log) {
  std::vector<RodStepRow> rows;
  // The implicit ones at steps from 1 µs to a 30 Hz frame; fewer steps per trial (each step
  // factorises): 100, or the explicit trials' count if smaller.
  const std::vector<double> dts{1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1.0 / 30.0};
  const int implicit_steps = std::min(steps, 100);
  for (const int n : w.segments) {
    const rods::RodLayout layout = rods::make_layout(
        rods::uniform_rod({w.young, w.shear, w.density}, w.length, w.diameter, n));
    for (const msm::Integrator i : {msm::Integrator::symplectic_euler, msm::Integrator::verlet}) {
      rows.push_back(der_explicit_row(layout, i, steps));
    }
    rods::DerRod der(layout);
    rows.push_back(implicit_row(der, WireModel::der, dts, implicit_steps));
    rods::CordeRod corde(layout);
    rows.push_back(implicit_row(corde, WireModel::corde, dts, implicit_steps));
    rows.push_back(xpbd_row(layout, dts, implicit_steps));
    for (std::size_t k = rows.size() - 5; k < rows.size(); ++k) {
      const RodStepRow& r = rows[k];
      log << "  rod N " << n << " " << r.model << ", " << r.integrator << ": closed form "
          << fmt(r.closed_form_dt) << " s";
      if (std::isfinite(r.found_dt)) {
        log << ", found " << fmt(r.found_dt) << " s (×" << fmt(r.found_dt / r.closed_form_dt, 4)
            << ")";
      } else {
        int bounded = 0;
        for (const bool b : r.bounded) bounded += b;
        log << ", bounded at " << bounded << "/" << r.bounded.size() << " steps up to "
            << fmt(r.steps_tried.back()) << " s" << (r.failure.empty() ? "" : " (" + r.failure + ")");
      }
      log << ", " << fmt(r.seconds, 2) << " s" << std::endl;
    }
  }
  return rows;
}

}  // namespace vessel::stability_study
