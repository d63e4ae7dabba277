// Corotational P1's and XPBD FEM's critical steps (tet_steps.hpp).
#include "verification/studies/stability/tet_steps.hpp"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "msm/fem/corotational_tet.hpp"
#include "msm/fem/linear_tet.hpp"
#include "msm/fem/stable_neo_hookean.hpp"
#include "msm/fem/xpbd_fem.hpp"
#include "msm/solvers/critical_step.hpp"
#include "msm/stability/stability_search.hpp"
#include "verification/harness/outcome_cache.hpp"
#include "verification/harness/parallel.hpp"
#include "verification/harness/timing.hpp"
#include "verification/scene_problems.hpp"
#include "verification/studies/stability/study_models.hpp"

namespace vessel::stability_study {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kBlowup = 1e3;  // as the other rows: energy beyond 1000× its start diverged
constexpr double kTolerance = 5e-3;
constexpr int kMaxTrials = 60;

TetStepRow base_row(const char* model, const char* integrator, int level, const TetMesh& mesh,
                    double load) {
  TetStepRow row;
  row.model = model;
  row.integrator = integrator;
  row.level = level;
  row.nodes = static_cast<int>(mesh.nodes.size());
  row.tets = static_cast<int>(mesh.tets.size());
  row.nu = kTetStepPoisson;
  row.load = load;
  row.omega_lanczos = row.omega_power = row.predicted_dt = row.power_dt = kNaN;
  row.found_dt = row.unstable_dt = kNaN;
  return row;
}

/// 2/ω_max of the problem's M⁻¹K at rest by Lanczos and by power iteration, into the row.
void estimate(const msm::Problem& p, TetStepRow& row) {
  const msm::Spectrum s = msm::analyse_spectrum(p, {.lowest = false});
  row.omega_lanczos = s.omega_max;
  row.predicted_dt = 2.0 / s.omega_max;
  row.omega_power = msm::power_iteration_omega_max(p);
  row.power_dt = 2.0 / row.omega_power;
}

/// The trials' initial velocity amplitude, m/s: displacements of ~1e-9 of the model's size over
/// one period at the guess (as msm::find_stable_step's).
double trial_speed(const msm::Problem& p, double guess) {
  return 1e-9 * std::max(p.rest.cwiseAbs().maxCoeff(), 1e-3) / guess;
}

msm::DynamicOptions implicit_euler(msm::ImplicitMatrix matrix, double dt, int steps) {
  msm::DynamicOptions d;
  d.integrator = msm::Integrator::implicit_euler;
  d.implicit_matrix = matrix;
  d.dt = dt;
  d.steps = steps;
  return d;
}

/// Corotational P1 under the load from rest by implicit Euler with `matrix`: the ladder, and where
/// a step diverged the largest bounded step below it, bisected.
TetStepRow corotational_implicit_row(const msm::Problem& loaded, msm::ImplicitMatrix matrix,
                                     const char* integrator, int level, const TetMesh& mesh,
                                     int steps) {
  Stopwatch clock;
  TetStepRow row = base_row("corotational-p1", integrator, level, mesh, kTetStepLoad);
  row.steps_per_trial = steps;
  const auto bounded = [&](double dt) {
    try {
      msm::integrate(loaded, implicit_euler(matrix, dt, steps));
      return true;
    } catch (const msm::DivergenceError& e) {
      if (row.failure.empty()) row.failure = "dt " + fmt(dt) + " s: " + short_error(e.what());
      return false;
    }
  };
  double last_bounded = 0.0, first_unbounded = 0.0;
  for (const double dt : {1e-4, 1e-3, 1e-2, 1.0 / 30.0}) {
    const bool ok = bounded(dt);
    row.steps_tried.push_back(dt);
    row.bounded.push_back(ok);
    ++row.trials;
    if (ok && first_unbounded == 0.0) last_bounded = dt;
    if (!ok && first_unbounded == 0.0) first_unbounded = dt;
  }
  if (first_unbounded > 0.0) {
    const double guess =
        last_bounded > 0.0 ? std::sqrt(last_bounded * first_unbounded) : first_unbounded / 10.0;
    const msm::StabilitySearchResult r = msm::bisect_stable_step(guess, 2e-2, kMaxTrials, bounded);
    row.found_dt = r.stable_dt;
    row.unstable_dt = r.unstable_dt;
    row.trials += r.trials;
  }
  row.seconds = clock.seconds();
  return row;
}

/// XPBD FEM at its scene defaults: from rest with the small random velocity, `steps` steps, no
/// load; unbounded when a position turns non-finite or the energy (the stable neo-Hookean energy
/// above its rest value plus ½vᵀMv) exceeds 1000× its start.
bool xpbd_bounded(const TetMesh& mesh, const msm::LameParameters& snh, const msm::Problem& p,
                  const Eigen::VectorXd& v0, double dt, int steps) {
  msm::XpbdFem xpbd(mesh.nodes, mesh.tets, snh, p.mass, p.fixed);
  xpbd.set_velocity(v0);
  const msm::StableNeoHookeanTerm& energy = xpbd.energy_model();
  const double rest_energy = energy.energy(p.rest);
  const auto total = [&] {
    const Eigen::VectorXd& v = xpbd.velocity();
    return energy.energy(xpbd.state()) - rest_energy + 0.5 * v.dot(p.mass.cwiseProduct(v));
  };
  const double start = total();
  const Eigen::VectorXd none = Eigen::VectorXd::Zero(p.num_dofs());
  try {
    for (int k = 1; k <= steps; ++k) {
      xpbd.step(dt, none);
      if (k % 10 == 0 || k == steps) {
        const double e = total();
        if (!std::isfinite(e) || e > (1.0 + kBlowup) * start) return false;
      }
    }
  } catch (const msm::DivergenceError&) {
    return false;
  }
  return true;
}

}  // namespace

std::vector<TetStepRow> tet_step_rows(const Scene& scene, const TetMesh& mesh, int level,
                                      int study_steps, std::ostream& log, std::mutex& log_mutex) {
  std::vector<TetStepRow> rows;
  // Fewer steps per trial than the springs' rows: a step here costs a P1 tet pass (an SVD per
  // tet) or, implicitly, a factorisation.
  const int steps = std::min(study_steps, kTetTrialSteps);
  const msm::LameParameters lame = msm::lame_parameters(scene.youngs_modulus, kTetStepPoisson);
  // Corotational P1: explicit rows at rest (its Hessian there is linear P1's stiffness).
  {
    const msm::CorotationalTetTerm term(mesh.nodes, mesh.tets, lame);
    const msm::Problem p = tet_mesh_problem(scene, term, mesh, 0.0);
    for (const msm::Integrator in : {msm::Integrator::symplectic_euler, msm::Integrator::verlet}) {
      Stopwatch clock;
      TetStepRow row = base_row("corotational-p1", msm::to_string(in).c_str(), level, mesh, 0.0);
      estimate(p, row);
      msm::StabilitySearchOptions so;
      so.integrator = in;
      so.steps = steps;
      so.tolerance = kTolerance;
      const msm::StabilitySearchResult r = msm::find_stable_step(p, row.predicted_dt, so);
      row.found_dt = r.stable_dt;
      row.unstable_dt = r.unstable_dt;
      row.trials = r.trials;
      row.steps_per_trial = steps;
      row.seconds = clock.seconds();
      rows.push_back(row);
    }
  }
  // Corotational P1 by implicit Euler under the load.
  {
    Scene loaded_scene = scene;
    loaded_scene.load.magnitudes = {kTetStepLoad};
    const msm::CorotationalTetTerm warped(mesh.nodes, mesh.tets, lame,
                                          msm::CorotationalStiffness::warped);
    const msm::Problem p = tet_mesh_problem(loaded_scene, warped, mesh, kTetStepLoad);
    const int implicit_steps = std::min(study_steps, kTetImplicitSteps);
    rows.push_back(corotational_implicit_row(p, msm::ImplicitMatrix::current_state,
                                             "implicit-euler", level, mesh, implicit_steps));
    rows.push_back(corotational_implicit_row(p, msm::ImplicitMatrix::rest_prefactored,
                                             "implicit-euler-rest", level, mesh, implicit_steps));
  }
  // XPBD FEM: the estimate from linear P1's shear stiffness (λ = −2μ/3), the step by bisection.
  {
    Stopwatch clock;
    TetStepRow row = base_row("xpbd-fem", "xpbd", level, mesh, 0.0);
    const msm::LinearTetTerm shear(mesh.nodes, mesh.tets, {-2.0 * lame.mu / 3.0, lame.mu});
    const msm::Problem p = tet_mesh_problem(scene, shear, mesh, 0.0);
    estimate(p, row);
    const msm::LameParameters snh{msm::snh_lambda_for_linear(lame), lame.mu};
    const Eigen::VectorXd v0 = msm::random_velocity(p, trial_speed(p, row.predicted_dt), 12345);
    const msm::StabilitySearchResult r = msm::bisect_stable_step(
        row.predicted_dt, kTolerance, kMaxTrials,
        [&](double dt) { return xpbd_bounded(mesh, snh, p, v0, dt, steps); });
    row.found_dt = r.stable_dt;
    row.unstable_dt = r.unstable_dt;
    row.trials = r.trials;
    row.steps_per_trial = steps;
    row.seconds = clock.seconds();
    rows.push_back(row);
  }
  const std::lock_guard lock(log_mutex);
  for (const TetStepRow& r : rows) {
    log << "  L" << level << " " << r.model << ", " << r.integrator << ": ";
    if (std::isfinite(r.predicted_dt)) {
      log << "2/ω_max " << fmt(r.predicted_dt) << " s (Lanczos), " << fmt(r.power_dt)
          << " s (power iteration), ";
    } else {
      int bounded = 0;
      for (const bool b : r.bounded) bounded += b;
      log << "under " << fmt(r.load * 1e3) << " mN bounded at " << bounded << "/"
          << r.bounded.size() << " steps up to " << fmt(r.steps_tried.back()) << " s, ";
    }
    if (std::isfinite(r.found_dt)) {
      log << "found " << fmt(r.found_dt) << " s";
      if (std::isfinite(r.predicted_dt)) log << " (×" << fmt(r.found_dt / r.predicted_dt) << ")";
      log << ", ";
    }
    log << r.trials << " trials, " << fmt(r.seconds, 2) << " s" << std::endl;
  }
  return rows;
}

namespace {

nlohmann::json number(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); }
double number(const nlohmann::json& j) { return j.is_null() ? kNaN : j.get<double>(); }

/// A level's rows as bytes for the outcome cache (CBOR: doubles bit for bit, NaN as null).
std::string serialise_rows(const std::vector<TetStepRow>& rows) {
  nlohmann::json j = nlohmann::json::array();
  for (const TetStepRow& r : rows) {
    j.push_back({r.model, r.integrator, r.level, r.nodes, r.tets, r.nu, r.load,
                 number(r.omega_lanczos), number(r.omega_power), number(r.predicted_dt),
                 number(r.power_dt), number(r.found_dt), number(r.unstable_dt), r.steps_tried,
                 r.bounded, r.failure, r.steps_per_trial, r.trials, r.seconds});
  }
  const std::vector<std::uint8_t> b = nlohmann::json::to_cbor(j);
  return {b.begin(), b.end()};
}

std::vector<TetStepRow> deserialise_rows(const std::string& bytes) {
  std::vector<TetStepRow> rows;
  for (const nlohmann::json& x : nlohmann::json::from_cbor(bytes.begin(), bytes.end())) {
    TetStepRow r;
    r.model = x.at(0);
    r.integrator = x.at(1);
    r.level = x.at(2);
    r.nodes = x.at(3);
    r.tets = x.at(4);
    r.nu = x.at(5);
    r.load = x.at(6);
    r.omega_lanczos = number(x.at(7));
    r.omega_power = number(x.at(8));
    r.predicted_dt = number(x.at(9));
    r.power_dt = number(x.at(10));
    r.found_dt = number(x.at(11));
    r.unstable_dt = number(x.at(12));
    x.at(13).get_to(r.steps_tried);
    x.at(14).get_to(r.bounded);
    r.failure = x.at(15);
    r.steps_per_trial = x.at(16);
    r.trials = x.at(17);
    r.seconds = x.at(18);
    rows.push_back(r);
  }
  return rows;
}

}  // namespace

std::vector<TetStepRow> tet_critical_steps(const StabilityOptions& o, int max_level, int steps,
                                           std::ostream& log,
                                           std::vector<TimingProvenance>& provenance) {
  std::vector<Scene> scenes;
  std::vector<TetMesh> meshes;
  for (int level = 0; level <= max_level; ++level) {  // gmsh on this thread
    VesselParams params;
    params.level = level;
    scenes.push_back(study_scene(params, 14.24e3, 0.0));
    meshes.push_back(case_mesh(scenes.back(), o));
  }
  const std::size_t n = scenes.size();
  std::vector<std::vector<TetStepRow>> rows_of(n);
  std::vector<TimingProvenance> level_provenance(n);
  std::mutex log_mutex;
  parallel_for(n, o.jobs, [&](std::size_t t) {
    const std::size_t level = n - 1 - t;
    const auto compute = [&] {
      return tet_step_rows(scenes[level], meshes[level], static_cast<int>(level), steps, log,
                           log_mutex);
    };
    if (!o.outcome_cache || !o.outcome_cache->enabled()) {
      rows_of[level] = compute();
      level_provenance[level] = {false, utc_now()};
      return;
    }
    const std::string key = "stability-tet-rows level=" + std::to_string(level) +
                            " steps=" + std::to_string(steps) + " mesh=" + mesh_key(meshes[level]);
    rows_of[level] = deserialise_rows(o.outcome_cache->get(
        key, [&] { return serialise_rows(compute()); }, level_provenance[level]));
    if (level_provenance[level].cached) {
      const std::lock_guard lock(log_mutex);
      log << "  L" << level << " P1 tet models: " << rows_of[level].size()
          << " rows from the outcome cache (measured " << level_provenance[level].measured_at << ")"
          << std::endl;
    }
  });
  std::vector<TetStepRow> rows;
  for (std::size_t level = 0; level < n; ++level) {
    rows.insert(rows.end(), rows_of[level].begin(), rows_of[level].end());
    provenance.push_back(level_provenance[level]);
  }
  return rows;
}

}  // namespace vessel::stability_study
