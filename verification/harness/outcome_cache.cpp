#include "verification/harness/outcome_cache.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "meshes/foundation/content_store.hpp"
#include "meshes/foundation/content_hash.hpp"
#include "reports/results_file.hpp"
#include "verification/harness/timing.hpp"

namespace vessel {

namespace {

using Json = nlohmann::json;

/// CBOR keeps doubles bit for bit, NaN and infinities included (JSON text would not).
std::string to_bytes(const Json& j) {
  const std::vector<std::uint8_t> v = Json::to_cbor(j);
  return {v.begin(), v.end()};
}
Json from_bytes(std::string_view b) { return Json::from_cbor(b.begin(), b.end()); }

Json error_json(const ErrorStatistics& e) {
  return {e.max_mm, e.mean_mm, e.stddev_mm, e.rms_mm, e.relative_l2, e.points,
          e.model_l2_over_reference};
}
ErrorStatistics error_from(const Json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>(),
          j.at(3).get<double>(), j.at(4).get<double>(), j.at(5).get<std::size_t>(),
          j.at(6).get<double>()};
}

Json optional_json(const std::optional<double>& v) { return v ? Json(*v) : Json(nullptr); }
std::optional<double> optional_from(const Json& j) {
  if (j.is_null()) return std::nullopt;
  return j.get<double>();
}

Json outcome_json(const ModelOutcome& o) {
  const QuantityErrors& q = o.quantities;
  return {{"model", o.model},
          {"kind", o.kind},
          {"detail", o.detail},
          {"nu", o.poisson_ratio},
          {"magnitude", o.magnitude},
          {"level", o.level},
          {"ok", o.ok},
          {"failure", o.failure},
          {"nodes", o.nodes},
          {"unknowns", o.unknowns},
          {"setup_s", o.setup_seconds},
          {"solve_s", o.solve_seconds},
          {"updates", o.updates},
          {"iterations", o.iterations_per_update},
          {"factorisations", o.factorisations_per_update},
          {"memory", o.memory_mib},
          {"timing_source", o.timing_source},
          {"error", error_json(o.error)},
          {"uncertainty", error_json(o.reference_uncertainty)},
          {"has_uncertainty", o.has_reference_uncertainty},
          {"qoi", o.qoi_displacement_mm},
          {"qoi_ref", o.qoi_reference_mm},
          {"max_strain", o.max_strain},
          {"beyond", o.beyond_linear_regime},
          {"reference", o.reference},
          {"wall", {o.wall_profile.s_mm, o.wall_profile.model_mm, o.wall_profile.reference_mm}},
          {"history",
           {o.history.time_s, o.history.model_mm, o.history.reference_mm, o.history.max_error_mm,
            o.history.steps, o.history.simulated_s, o.history.mass_damping}},
          {"roi", o.roi_radius},
          {"quantities",
           {q.contact_point_mm, q.field_mm, optional_json(q.patch_mm), optional_json(q.indentation_mm),
            optional_json(q.indentation_reference_mm), optional_json(q.reaction_mN)}},
          {"budget_error", o.budget_error},
          {"update_s", o.update_seconds},
          {"steps_per_update", o.steps_per_update}};
}

ModelOutcome outcome_from(const Json& j) {
  ModelOutcome o;
  o.model = j.at("model");
  o.kind = j.at("kind");
  o.detail = j.at("detail");
  o.poisson_ratio = j.at("nu");
  o.magnitude = j.at("magnitude");
  o.level = j.at("level");
  o.ok = j.at("ok");
  o.failure = j.at("failure");
  o.nodes = j.at("nodes");
  o.unknowns = j.at("unknowns");
  o.setup_seconds = j.at("setup_s");
  o.solve_seconds = j.at("solve_s");
  o.updates = j.at("updates");
  o.iterations_per_update = j.at("iterations");
  o.factorisations_per_update = j.at("factorisations");
  o.memory_mib = j.at("memory");
  o.timing_source = j.at("timing_source");
  o.error = error_from(j.at("error"));
  o.reference_uncertainty = error_from(j.at("uncertainty"));
  o.has_reference_uncertainty = j.at("has_uncertainty");
  o.qoi_displacement_mm = j.at("qoi");
  o.qoi_reference_mm = j.at("qoi_ref");
  o.max_strain = j.at("max_strain");
  o.beyond_linear_regime = j.at("beyond");
  o.reference = j.at("reference");
  const Json& w = j.at("wall");
  w.at(0).get_to(o.wall_profile.s_mm);
  w.at(1).get_to(o.wall_profile.model_mm);
  w.at(2).get_to(o.wall_profile.reference_mm);
  const Json& h = j.at("history");
  h.at(0).get_to(o.history.time_s);
  h.at(1).get_to(o.history.model_mm);
  h.at(2).get_to(o.history.reference_mm);
  o.history.max_error_mm = h.at(3);
  o.history.steps = h.at(4);
  o.history.simulated_s = h.at(5);
  o.history.mass_damping = h.at(6);
  o.roi_radius = j.at("roi");
  const Json& q = j.at("quantities");
  o.quantities.contact_point_mm = q.at(0);
  o.quantities.field_mm = q.at(1);
  o.quantities.patch_mm = optional_from(q.at(2));
  o.quantities.indentation_mm = optional_from(q.at(3));
  o.quantities.indentation_reference_mm = optional_from(q.at(4));
  o.quantities.reaction_mN = optional_from(q.at(5));
  o.budget_error = j.at("budget_error");
  o.update_seconds = j.at("update_s");
  o.steps_per_update = j.at("steps_per_update");
  return o;
}

Json modes_json(const ModalOutcome& m) {
  return {m.model, m.kind,           m.detail,     m.poisson_ratio, m.level, m.ok,
          m.failure, m.frequencies_hz, m.mechanisms, m.dofs,          m.seconds};
}
ModalOutcome modes_from(const Json& j) {
  ModalOutcome m;
  m.model = j.at(0);
  m.kind = j.at(1);
  m.detail = j.at(2);
  m.poisson_ratio = j.at(3);
  m.level = j.at(4);
  m.ok = j.at(5);
  m.failure = j.at(6);
  j.at(7).get_to(m.frequencies_hz);
  m.mechanisms = j.at(8);
  m.dofs = j.at(9);
  m.seconds = j.at(10);
  return m;
}

void hash_point(ContentHash& h, const Vec3& p) { h.real(p.x()).real(p.y()).real(p.z()); }

void hash_load(ContentHash& h, const LoadSpec& l, bool with_magnitudes) {
  h.text("load").integer(static_cast<int>(l.kind));
  if (with_magnitudes) {
    for (const double m : l.magnitudes) h.real(m);
  }
  hash_point(h, l.contact.point);
  h.real(l.contact.radius).real(l.contact.force).text(l.contact.surface_group);
  hash_point(h, l.gravity_direction);
}

void hash_solver(ContentHash& h, const msm::SolverSpec& s) {
  h.text("solver").integer(static_cast<int>(s.kind)).integer(static_cast<int>(s.integrator));
  h.integer(static_cast<int>(s.implicit_matrix));
  h.real(s.pcg.tolerance).integer(s.pcg.max_iterations).integer(static_cast<int>(s.pcg.preconditioner));
  h.real(s.dt).integer(s.steps);
  const msm::StaticOptions& st = s.static_options;
  h.real(st.tolerance).real(st.force_scale).integer(st.max_iterations).integer(st.project_psd);
  h.integer(st.load_steps).integer(static_cast<int>(st.globalisation));
  h.integer(st.curvature_iterations).integer(st.exact_backoff).real(st.curvature_shift);
  h.integer(s.pbd.iterations).real(s.pbd.velocity_damping).real(s.pbd.bending_compliance);
  h.integer(s.pbd.dihedral).integer(s.pbd.angle);
  h.integer(s.local_global.iterations).integer(s.local_global.max_iterations);
}

void hash_mesh(ContentHash& h, const TetMesh& mesh) {
  h.text("mesh").integer(static_cast<std::int64_t>(mesh.nodes.size()));
  for (const Vec3& p : mesh.nodes) hash_point(h, p);
  h.integer(static_cast<std::int64_t>(mesh.tets.size()));
  for (const auto& t : mesh.tets) h.bytes(t.data(), sizeof t);
  h.integer(static_cast<std::int64_t>(mesh.triangles.size()));
  for (const auto& t : mesh.triangles) h.bytes(t.data(), sizeof t);
  for (const PhysicalGroup& g : mesh.groups) {
    h.text(g.name).integer(g.dim).bytes(g.elements.data(), g.elements.size() * sizeof(int));
  }
}

std::string read_cpu_model() {
  std::ifstream f("/proc/cpuinfo");
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) {
        std::string name = line.substr(colon + 1);
        name.erase(0, name.find_first_not_of(' '));
        return name;
      }
    }
  }
  return "unknown CPU";
}

}  // namespace

const std::string& executable_identity() {
  static const std::string identity = [] {
    std::ifstream f("/proc/self/exe", std::ios::binary);
    if (!f) return std::string("unknown executable");
    ContentHash h;
    std::vector<char> buf(1 << 20);
    while (f) {
      f.read(buf.data(), static_cast<std::streamsize>(buf.size()));
      h.bytes(buf.data(), static_cast<std::size_t>(f.gcount()));
    }
    return h.hex();
  }();
  return identity;
}

const std::string& machine_identity() {
  static const std::string identity =
      read_cpu_model() + "; " + std::to_string(std::thread::hardware_concurrency()) + " cores";
  return identity;
}

OutcomeCache::OutcomeCache(std::filesystem::path dir, bool retime, std::ostream* log)
    : store_(std::make_unique<ContentStore>(std::move(dir), log, "model outcome cache")),
      retime_(retime) {}

OutcomeCache::~OutcomeCache() = default;

bool OutcomeCache::enabled() const { return store_->enabled(); }

OutcomeCacheStatistics OutcomeCache::statistics() const {
  const ContentStoreStatistics s = store_->statistics();
  return {s.hits, s.misses, s.corrupt, s.seconds_saved};
}

std::string OutcomeCache::get(const std::string& key, const std::function<std::string()>& compute,
                              TimingProvenance& provenance) {
  provenance = {};
  bool computed = false;
  const std::string full_key =
      "measured-outcome executable=" + executable_identity() + " machine=" + machine_identity() +
      " " + key;
  const std::string entry = store_->payload(
      full_key,
      [&] {
        computed = true;
        Stopwatch clock;
        const std::string data = compute();
        const Json j{{"measured_at", utc_now()}, {"seconds", clock.seconds()},
                     {"data", Json::binary({data.begin(), data.end()})}};
        return to_bytes(j);
      },
      [](std::string_view stored) { return from_bytes(stored).at("seconds").get<double>(); },
      retime_);
  const Json j = from_bytes(entry);
  provenance.cached = !computed;
  provenance.measured_at = j.at("measured_at").get<std::string>();
  const auto& data = j.at("data").get_binary();
  return {data.begin(), data.end()};
}

std::string OutcomeCache::summary() const {
  std::string s = store_->summary();
  if (retime_ && enabled()) s += " (--retime: every outcome measured again)";
  return s;
}

std::string timing_provenance_line(const std::vector<ModelOutcome>& outcomes) {
  std::size_t total = 0;
  std::vector<std::string> cached_at;
  for (const ModelOutcome& o : outcomes) {
    if (o.timing.measured_at.empty()) continue;
    ++total;
    if (o.timing.cached) cached_at.push_back(o.timing.measured_at);
  }
  return reports::timing_provenance_line(total, std::move(cached_at));
}

std::string serialise(const ModelRun& run) {
  Json outcomes = Json::array(), modes = Json::array(), files = Json::array();
  for (const ModelOutcome& o : run.outcomes) outcomes.push_back(outcome_json(o));
  for (const ModalOutcome& m : run.modes) modes.push_back(modes_json(m));
  for (const auto& [path, bytes] : run.field_files) {
    files.push_back({path, Json::binary({bytes.begin(), bytes.end()})});
  }
  return to_bytes({{"outcomes", outcomes}, {"modes", modes}, {"fields", files}});
}

ModelRun deserialise_model_run(std::string_view bytes) {
  const Json j = from_bytes(bytes);
  ModelRun run;
  for (const Json& o : j.at("outcomes")) run.outcomes.push_back(outcome_from(o));
  for (const Json& m : j.at("modes")) run.modes.push_back(modes_from(m));
  for (const Json& f : j.at("fields")) {
    const auto& b = f.at(1).get_binary();
    run.field_files.emplace_back(f.at(0).get<std::string>(), std::string(b.begin(), b.end()));
  }
  return run;
}

std::string file_contents(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return "(unreadable)";
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

std::string mesh_key(const TetMesh& mesh) {
  ContentHash h;
  hash_mesh(h, mesh);
  return h.hex();
}

std::string model_run_key(const Scene& s, const ModelSpec& m, double nu, int level,
                          const std::vector<double>& magnitudes, const TetMesh& mesh,
                          const HarnessOptions& o) {
  ContentHash h;
  // The scene, apart from its other models and its sweeps (ν, level and magnitudes are this
  // run's own, below).
  h.text("scene").text(s.name);
  const VesselParams& v = s.vessel;
  h.integer(static_cast<int>(v.kind)).real(v.inner_radius).real(v.wall_thickness).real(v.length);
  h.real(v.bend_radius).integer(static_cast<int>(v.style)).real(v.file_scale);
  h.text(v.file.string()).text(v.file.empty() ? "" : file_contents(v.file));
  h.integer(s.reference_level).real(s.youngs_modulus).real(s.density);
  for (const auto& [group, condition] : s.boundary) h.text(group).integer(static_cast<int>(condition));
  hash_load(h, s.load, false);
  for (const LoadSpec& l : s.constant_loads) hash_load(h, l, true);
  h.real(s.tolerances.max_error_mm);
  const Budget& b = s.budget;
  h.text("budget").integer(b.stated).integer(static_cast<int>(b.quantity)).real(b.radius);
  h.real(b.tolerance).real(b.rate_hz).real(b.time_budget_s).real(b.magnitude);
  h.integer(s.modes.count).integer(s.modes.reference_level).integer(static_cast<int>(s.reference));
  h.integer(s.transient.reference_level);
  // The model.
  h.text("model").text(m.name).integer(static_cast<int>(m.kind)).integer(m.degree);
  h.integer(static_cast<int>(m.surface)).integer(static_cast<int>(m.topology));
  h.integer(static_cast<int>(m.stiffness)).integer(m.volume_term);
  h.integer(static_cast<int>(m.volume_moduli)).integer(static_cast<int>(m.bending));
  h.integer(m.edge_pairs);
  h.integer(static_cast<int>(m.mass));
  hash_solver(h, m.solver);
  const TetFemSpec& t = m.tet_fem;
  h.real(t.dt).integer(t.iterations).real(t.velocity_damping);
  h.text("settle relative").real(t.settle_relative_change);
  h.integer(t.max_steps);
  h.real(m.damping).real(m.roi_radius).integer(m.calibration_transfer);
  h.text(m.calibration.string()).text(m.calibration.empty() ? "" : file_contents(m.calibration));
  h.text(m.network_file.string())
      .text(m.network_file.empty() ? "" : file_contents(m.network_file));
  // This run.
  h.text("case").real(nu).integer(level);
  for (const double mag : magnitudes) h.real(mag);
  hash_mesh(h, mesh);
  h.text("harness").integer(o.repeats).integer(o.ramp_updates);
  h.integer(o.fields_dir.empty() ? 0 : (o.fields_every_load ? 2 : 1));
  return "model-run " + h.hex();
}

}  // namespace vessel
