#include "verification/harness/harness.hpp"

#include <algorithm>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <sstream>

#include "fem_reference/cholmod_solve.hpp"
#include "meshes/foundation/atomic_file.hpp"
#include "verification/harness/guidewire_contact.hpp"
#include "verification/harness/guidewire_coupling.hpp"
#include "verification/harness/model_readout.hpp"
#include "verification/harness/model_runs.hpp"
#include "verification/harness/outcome_cache.hpp"
#include "verification/harness/progress.hpp"
#include "verification/harness/references.hpp"
#include "verification/harness/timing.hpp"
#include "verification/scene_problems.hpp"

namespace vessel {

Scene quick_variant(Scene s) {
  s.model_levels = {0};
  s.vessel.level = 0;
  const double mixed_threshold = fem::SolverOptions{}.mixed_threshold;
  const bool mixed = std::any_of(s.poisson_ratios.begin(), s.poisson_ratios.end(),
                                 [&](double nu) { return nu >= mixed_threshold; });
  s.reference_level = std::min(s.reference_level, mixed ? 0 : 1);
  if (s.load.magnitudes.size() > 2) {
    s.load.magnitudes = {s.load.magnitudes.front(), s.load.magnitudes.back()};
  }
  // The wire–wall contact solve is minutes on its own refined mesh: quick solves it at the scene
  // wire's EI alone, on a coarser contact mesh.
  if (s.load.guidewire && s.load.guidewire->coupling == GuidewireCoupling::contact) {
    s.load.guidewire->contact_at_own_stiffness_only = true;
    s.load.guidewire->contact_fine_size = std::max(s.load.guidewire->contact_fine_size, 0.12e-3);
  }
  return s;
}

namespace {

std::size_t model_cases(const Scene& s, const HarnessOptions& o) {
  const std::size_t loads = o.budget_load_only ? 1 : s.load.magnitudes.size();
  std::size_t cases = 0;
  for (const auto& m : s.models) cases += m.kind == ModelKind::fem ? 1 : loads;
  return s.poisson_ratios.size() * s.model_levels.size() * cases;
}

/// A FEM or mass-spring model at one ν and level: `run` (run_fem_model or run_msm_model into the
/// SceneResult it is given), or, with an outcome cache, the outcomes, natural frequencies and VTU
/// fields a run of the same model, scene, ν, level, loads, mesh, executable and machine stored.
/// Each outcome says whether its timings were measured now or read from the cache.
void run_through_cache(const Scene& s, const ModelSpec& spec, double nu, int level,
                       const TetMesh& mesh, const HarnessOptions& o, double ref_strain_unit,
                       Progress& progress, const std::string& fem_label, SceneResult& result,
                       const std::function<void(SceneResult&)>& run) {
  const auto measure = [&] {
    SceneResult part;
    part.scene = s;
    part.qoi_point = result.qoi_point;
    run(part);
    ModelRun measured{std::move(part.outcomes), std::move(part.model_modes), {}};
    for (const ModelOutcome& out : measured.outcomes) {
      if (!out.ok || !wants_fields(o, s, out.magnitude, ref_strain_unit)) continue;
      const std::filesystem::path file = fields_file(s, out);
      std::ifstream in(o.fields_dir / file, std::ios::binary);
      if (in) {
        measured.field_files.emplace_back(
            file.string(), std::string(std::istreambuf_iterator<char>(in), {}));
      }
    }
    return measured;
  };
  const auto keep = [&](ModelRun run_result, const TimingProvenance& timing) {
    for (ModelOutcome& out : run_result.outcomes) {
      out.timing = timing;
      const std::string file = fields_file(s, out).string();
      for (const auto& written : run_result.field_files) {
        if (written.first == file) out.fields_file = o.fields_dir / file;
      }
      result.outcomes.push_back(std::move(out));
    }
    for (ModalOutcome& m : run_result.modes) result.model_modes.push_back(std::move(m));
  };
  if (!o.outcome_cache || !o.outcome_cache->enabled()) {
    keep(measure(), {false, utc_now()});
    return;
  }
  bool measured_now = false;
  TimingProvenance timing;
  const std::string stored = o.outcome_cache->get(
      model_run_key(s, spec, nu, level, s.load.magnitudes, mesh, o),
      [&] {
        measured_now = true;
        return serialise(measure());
      },
      timing);
  ModelRun cached = deserialise_model_run(stored);
  if (!measured_now) {  // the progress lines and the fields a measurement would have written
    if (spec.kind == ModelKind::fem) {
      progress.begin(fem_label + ", from the outcome cache");
      progress.end();
    } else {
      for (const ModelOutcome& out : cached.outcomes) {
        std::ostringstream what;
        what << spec.name << " at " << out.magnitude << " (" << to_string(s.load.kind)
             << "), from the outcome cache";
        progress.begin(what.str());
        progress.end();
      }
    }
    for (const auto& [file, bytes] : cached.field_files) {
      const std::filesystem::path path = o.fields_dir / file;
      std::filesystem::create_directories(path.parent_path());
      write_file_atomically(path, [&](std::ostream& out) { out << bytes; }, true);
    }
  }
  keep(std::move(cached), timing);
}

/// The scene's models against its references (solved). `progress` counts one case per model,
/// level, ν and load; `solve_here` solves each ν's reference as the models reach it (serial runs).
SceneResult run_models(SceneReferences& r, const HarnessOptions& o, Progress& progress,
                       bool solve_here, std::ostream& log) {
  const Scene& s = r.scene;
  SceneResult result;
  result.scene = s;
  result.qoi_point = qoi_point(s);
  result.lumen_ends = r.lumen_ends;
  result.mesh_slivers = r.mesh_slivers;
  if (s.load.kind == LoadKind::contact) {
    result.contact_normal = scene_contact_patch(s.load, r.fine_mesh, 1.0).outward_normal;
  }
  for (std::size_t k = 0; k < s.poisson_ratios.size(); ++k) {
    const double nu = s.poisson_ratios[k];
    SceneReferences::AtNu& a = r.at_nu[k];
    if (solve_here) {
      progress.begin(reference_label(s, nu));
      solve_reference_at(s, r, k, o);
      fem::release_kept_factors();  // the timed models below run without gigabytes held
      progress.end();
      if (r.modal_reference_mesh) {
        progress.begin(modal_label(s, r, nu));
        solve_modal_reference_at(s, r, k);
        log_modal_failure(log, a);
        progress.end();
      }
    }
    result.references.push_back(a.info);
    if (a.modes) result.reference_modes.push_back(*a.modes);
    const fem::ElasticityResult& fine = a.ref.fine->result();
    Scene at_nu = s;  // the scene's loads for this ν (only the budget's, if asked)
    if (o.budget_load_only) at_nu.load.magnitudes = {a.info.budget_magnitude};

    for (const auto& [level, mesh] : r.model_meshes) {
      for (const auto& spec : s.models) {
        ModelOutcome base;
        base.model = spec.name;
        base.kind = to_string(spec.kind);
        base.poisson_ratio = nu;
        base.level = level;
        if (spec.kind == ModelKind::external || spec.kind == ModelKind::displacements) {
          run_outside_model(at_nu, spec, nu, mesh, a.ref, fine, o, progress, base, result);
          continue;
        }
        const std::string fem_label = spec.name + " (FEM P" + std::to_string(spec.degree) +
                                      ", level " + std::to_string(level) + ")";
        run_through_cache(at_nu, spec, nu, level, mesh, o, fine.max_abs_principal_strain, progress,
                          fem_label, result, [&](SceneResult& part) {
                            if (spec.kind == ModelKind::fem) {
                              progress.begin(fem_label);
                              run_fem_model(at_nu, spec, nu, mesh, a.ref, fine, o, base, part);
                              progress.end();
                            } else if (spec.kind == ModelKind::corotational_fem ||
                                       spec.kind == ModelKind::xpbd_fem) {
                              run_tet_fem_model(at_nu, spec, nu, mesh, a.ref, fine, o, progress,
                                                base, part);
                            } else {
                              run_msm_model(at_nu, spec, nu, mesh, a.ref, fine, o, progress, base,
                                            part);
                            }
                          });
      }
    }
  }
  if (s.load.guidewire) result.guidewire = couple_guidewire(s, result.outcomes);
  if (s.load.guidewire && s.load.guidewire->coupling == GuidewireCoupling::contact) {
    result.guidewire_contact =
        std::make_shared<const GuidewireContact>(solve_guidewire_contact(s, *result.guidewire, o));
    if (s.budget.quantity == BudgetQuantity::contact_force) {
      for (ModelOutcome& m : result.outcomes) {
        std::string why;
        m.budget_error = worst_contact_force_error_mN(*result.guidewire_contact, m.model, why)
                             .value_or(std::numeric_limits<double>::quiet_NaN());
      }
    }
  }
  return result;
}


void log_scene_header(std::ostream& log, const Scene& s, std::size_t i, std::size_t n) {
  log << "== scene " << i + 1 << "/" << n << ": " << s.name << " ==\n";
  log << "scene " << s.name << ": " << describe(s.vessel) << "\n";
}


}  // namespace

SceneResult run_scene(const Scene& s, const HarnessOptions& o) {
  std::ostream null_stream(nullptr);
  std::ostream& log = o.log ? *o.log : null_stream;
  Stopwatch total;
  log << "scene " << s.name << ": " << describe(s.vessel) << "\n";
  const std::unique_ptr<SceneReferences> refs = scene_meshes(s, o, log);
  const std::size_t reference_steps = s.poisson_ratios.size() * (s.modes.count > 0 ? 2 : 1);
  Progress progress(log, reference_steps + model_cases(s, o));
  SceneResult result = run_models(*refs, o, progress, true, log);
  result.seconds = total.seconds();
  return result;
}

std::vector<SceneResult> run_scenes(const std::vector<Scene>& scenes, const HarnessOptions& o) {
  std::ostream null_stream(nullptr);
  std::ostream& log = o.log ? *o.log : null_stream;
  std::vector<SceneResult> results;
  if (o.jobs <= 1) {
    for (std::size_t i = 0; i < scenes.size(); ++i) {
      log << "== scene " << i + 1 << "/" << scenes.size() << ": " << scenes[i].name << " ==\n";
      results.push_back(run_scene(scenes[i], o));
    }
    return results;
  }
  // The references first, in parallel (untimed), then each scene's models alone: their set-up
  // and update times are measurements and must not share the cores.
  std::vector<std::unique_ptr<SceneReferences>> refs;
  for (const Scene& s : scenes) refs.push_back(scene_meshes(s, o, log));
  solve_all_references(refs, o, log);
  fem::release_kept_factors();  // gigabytes at the reference levels; the models pass needs none
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    Stopwatch clock;
    log_scene_header(log, scenes[i], i, scenes.size());
    Progress progress(log, model_cases(scenes[i], o));
    results.push_back(run_models(*refs[i], o, progress, false, log));
    double solved = 0.0;
    for (const auto& a : refs[i]->at_nu) solved += a.seconds;
    results.back().seconds = clock.seconds() + solved;
    refs[i].reset();  // its solvers and meshes are no longer needed
  }
  return results;
}

}  // namespace vessel
