// Part (a) of the stability study: predicted vs found critical steps per model, integrator and level, and how they shrink with refinement.
#include "verification/studies/stability/study_models.hpp"

#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <tuple>

#include "msm/solvers/critical_step.hpp"
#include "msm/stability/stability_search.hpp"
#include "verification/harness/outcome_cache.hpp"
#include "verification/harness/parallel.hpp"
#include "verification/harness/timing.hpp"

namespace vessel::stability_study {

constexpr IntegratorConfig kConfigs[] = {{Integrator::symplectic_euler, 0.0},
                                         {Integrator::verlet, 0.0},
                                         {Integrator::explicit_euler, 0.3},
                                         {Integrator::symplectic_euler, 0.3}};

namespace {

/// The rows of one model at one level: its spectrum at rest, then each integrator configuration's
/// predicted and found critical step. Each finished row is logged under `log_mutex`.
std::vector<CriticalStepRow> model_rows(const Scene& scene, const TetMesh& mesh,
                                        const ModelSpec& spec, int level, int steps,
                                        std::ostream& log, std::mutex& log_mutex) {
  std::vector<CriticalStepRow> rows;
  const auto base = build_model(scene, mesh, spec, 0.25);
  const msm::Spectrum s0 = msm::analyse_spectrum(base->problem, {.lowest = false});
  for (const IntegratorConfig& cfg : kConfigs) {
    Stopwatch clock;
    CriticalStepRow row;
    row.model = spec.name;
    row.integrator = msm::to_string(cfg.integrator);
    row.zeta = cfg.zeta;
    row.level = level;
    row.nodes = static_cast<int>(base->built.network.nodes.size());
    row.springs = static_cast<int>(base->built.network.springs.size());
    row.h_nominal = unstructured_mesh_size(scene.vessel);
    // Point damping c = 2ζ ω_max m̄ (seed 000 eq. 3.3): ζ on the top mode exactly for
    // uniform masses, approximately (Rayleigh quotient) for the consistent ones used here.
    row.point_damping = 2.0 * cfg.zeta * s0.omega_max * mean_mass(base->problem);
    std::unique_ptr<StudyModel> damped;
    const StudyModel* m = base.get();
    msm::Spectrum s = s0;
    if (cfg.zeta > 0) {
      damped = with_damping(*base, row.point_damping);
      m = damped.get();
      s = msm::analyse_spectrum(m->problem,
                                {.lowest = cfg.integrator == Integrator::explicit_euler});
    }
    row.omega_max = s.omega_max;
    row.omega_gershgorin = s.gershgorin;
    row.omega_min = s.omega_min;
    row.gamma_max = s.gamma_max;
    row.predicted_dt = msm::predicted_critical_step(cfg.integrator, s);
    row.guaranteed_dt = msm::guaranteed_critical_step(cfg.integrator, s);
    msm::StabilitySearchOptions so;
    so.integrator = cfg.integrator;
    so.steps = steps;
    so.tolerance = 5e-3;
    const msm::StabilitySearchResult r = msm::find_stable_step(m->problem, row.predicted_dt, so);
    row.found_dt = r.stable_dt;
    row.unstable_dt = r.unstable_dt;
    row.trials = r.trials;
    row.steps_per_trial = steps;
    row.seconds = clock.seconds();
    {
      const std::lock_guard lock(log_mutex);
      log << "  L" << level << " " << row.model << ", " << row.integrator
          << (cfg.zeta > 0 ? " (ζ " + fmt(cfg.zeta) + ")" : "") << ": predicted "
          << fmt(row.predicted_dt) << " s, found " << fmt(row.found_dt) << " s (×"
          << fmt(row.found_dt / row.predicted_dt, 4) << "; guaranteed " << fmt(row.guaranteed_dt)
          << " s), " << r.trials << " trials, " << fmt(row.seconds, 2) << " s" << std::endl;
    }
    rows.push_back(row);
  }
  return rows;
}

/// A (level, model)'s rows as bytes for the outcome cache (CBOR: doubles bit for bit, NaN too).
std::string serialise_rows(const std::vector<CriticalStepRow>& rows) {
  nlohmann::json j = nlohmann::json::array();
  for (const CriticalStepRow& r : rows) {
    j.push_back({r.model, r.integrator, r.zeta, r.point_damping, r.level, r.nodes, r.springs,
                 r.h_nominal, r.omega_max, r.omega_gershgorin, r.omega_min, r.gamma_max,
                 r.predicted_dt, r.guaranteed_dt, r.found_dt, r.unstable_dt, r.trials,
                 r.steps_per_trial, r.seconds});
  }
  const std::vector<std::uint8_t> b = nlohmann::json::to_cbor(j);
  return {b.begin(), b.end()};
}

std::vector<CriticalStepRow> deserialise_rows(const std::string& bytes) {
  std::vector<CriticalStepRow> rows;
  for (const nlohmann::json& x : nlohmann::json::from_cbor(bytes.begin(), bytes.end())) {
    CriticalStepRow r;
    r.model = x.at(0);
    r.integrator = x.at(1);
    r.zeta = x.at(2);
    r.point_damping = x.at(3);
    r.level = x.at(4);
    r.nodes = x.at(5);
    r.springs = x.at(6);
    r.h_nominal = x.at(7);
    r.omega_max = x.at(8);
    r.omega_gershgorin = x.at(9);
    r.omega_min = x.at(10);
    r.gamma_max = x.at(11);
    r.predicted_dt = x.at(12);
    r.guaranteed_dt = x.at(13);
    r.found_dt = x.at(14);
    r.unstable_dt = x.at(15);
    r.trials = x.at(16);
    r.steps_per_trial = x.at(17);
    r.seconds = x.at(18);
    rows.push_back(r);
  }
  return rows;
}

}  // namespace

std::vector<CriticalStepRow> critical_step_table(const StabilityOptions& o, int max_level,
                                                 int steps, std::ostream& log,
                                                 std::vector<TimingProvenance>& provenance) {
  const std::vector<ModelSpec> specs{surface_model(msm::StiffnessRule::seed000),
                                     volume_model(msm::StiffnessRule::seed001),
                                     volume_model(msm::StiffnessRule::van_gelder)};
  // The meshes first, on this thread (gmsh is not thread-safe); then each (level, model) on its
  // own thread: the table's numbers are critical steps, not timings.
  std::vector<Scene> scenes;
  std::vector<TetMesh> meshes;
  for (int level = 0; level <= max_level; ++level) {
    VesselParams params;
    params.level = level;
    scenes.push_back(study_scene(params, 14.24e3, 0.0));  // unloaded: the spectrum at rest
    meshes.push_back(case_mesh(scenes.back(), o));
  }
  const std::size_t n = scenes.size() * specs.size();
  std::vector<std::vector<CriticalStepRow>> rows_of(n);
  provenance.assign(n, {});
  std::mutex log_mutex;
  // The finer levels first: they take longest.
  parallel_for(n, o.jobs, [&](std::size_t t) {
    const std::size_t k = n - 1 - t;
    const std::size_t level = k / specs.size();
    const ModelSpec& spec = specs[k % specs.size()];
    const auto compute = [&] {
      return model_rows(scenes[level], meshes[level], spec, static_cast<int>(level), steps, log,
                        log_mutex);
    };
    if (!o.outcome_cache || !o.outcome_cache->enabled()) {
      rows_of[k] = compute();
      provenance[k] = {false, utc_now()};
      return;
    }
    // Everything else that shapes the rows (the configurations, the search's tolerance, the
    // model's rules) is code: the executable's identity is in the key.
    const std::string key = "stability-rows model=" + spec.name +
                            " level=" + std::to_string(level) + " steps=" + std::to_string(steps) +
                            " mesh=" + mesh_key(meshes[level]);
    rows_of[k] = deserialise_rows(
        o.outcome_cache->get(key, [&] { return serialise_rows(compute()); }, provenance[k]));
    if (provenance[k].cached) {
      const std::lock_guard lock(log_mutex);
      log << "  L" << level << " " << spec.name << ": " << rows_of[k].size()
          << " rows from the outcome cache (measured " << provenance[k].measured_at << ")"
          << std::endl;
    }
  });
  std::vector<CriticalStepRow> rows;  // in the order (level, model, configuration)
  for (auto& r : rows_of) rows.insert(rows.end(), r.begin(), r.end());
  return rows;
}

std::vector<RefinementFit> refinement_fits(const std::vector<CriticalStepRow>& rows) {
  std::vector<RefinementFit> fits;
  std::set<std::tuple<std::string, std::string, double>> keys;
  for (const auto& r : rows) keys.insert({r.model, r.integrator, r.zeta});
  for (const auto& [model, integrator, zeta] : keys) {
    RefinementFit f{model, integrator, zeta, {}, 0.0, 0.0};
    std::vector<double> h, found, predicted;
    for (const auto& r : rows) {
      if (r.model == model && r.integrator == integrator && r.zeta == zeta) {
        f.levels.push_back(r.level);
        h.push_back(r.h_nominal);
        found.push_back(r.found_dt);
        predicted.push_back(r.predicted_dt);
      }
    }
    if (h.size() < 2) continue;
    f.exponent = loglog_slope(h, found);
    f.predicted_exponent = loglog_slope(h, predicted);
    fits.push_back(f);
  }
  return fits;
}

}  // namespace vessel::stability_study
