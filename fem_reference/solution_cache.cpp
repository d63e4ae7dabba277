#include "fem_reference/solution_cache.hpp"

#include <array>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "fem_reference/reference_code_version.hpp"
#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/content_hash.hpp"

namespace vessel::fem {

namespace fs = std::filesystem;

namespace {

/// Two FNV-1a streams fed the same bytes from different starting states: a 128-bit key.
struct KeyHash {
  ContentHash a, b;
  KeyHash() { b.text("second stream"); }
  KeyHash& text(std::string_view s) { return a.text(s), b.text(s), *this; }
  KeyHash& real(double x) { return a.real(x), b.real(x), *this; }
  KeyHash& integer(std::int64_t i) { return a.integer(i), b.integer(i), *this; }
  KeyHash& point(const Vec3& p) { return real(p.x()).real(p.y()).real(p.z()); }
  template <class Range>
  KeyHash& indices(const Range& r) {
    integer(static_cast<std::int64_t>(std::size(r)));
    for (const auto i : r) integer(i);
    return *this;
  }
};

void hash_mesh(KeyHash& h, const TetMesh& mesh) {
  h.text("nodes").integer(static_cast<std::int64_t>(mesh.nodes.size()));
  for (const Vec3& p : mesh.nodes) h.point(p);
  h.text("tets");
  for (const Tet& t : mesh.tets) h.indices(t);
  h.text("triangles");
  for (const Triangle& t : mesh.triangles) h.indices(t);
  h.text("groups");
  for (const PhysicalGroup& g : mesh.groups) {
    h.text(g.name).integer(g.dim).integer(g.tag).indices(g.elements);
  }
}

/// The points a curved wall's projection moves (P2 geometry nodes on the wall's triangle edges),
/// keyed by their images.
void hash_curved_surface(KeyHash& h, const TetMesh& mesh, const CurvedSurface& c) {
  h.text(c.group);
  const PhysicalGroup* g = mesh.find_group(c.group, 2);
  if (!g || !c.project) return;  // the solver's own validation reports it
  for (const Triangle& t : mesh.group_triangles(*g)) {
    for (int e = 0; e < 3; ++e) {
      h.point(c.project(0.5 * (mesh.nodes[t[e]] + mesh.nodes[t[(e + 1) % 3]])));
    }
  }
}

void hash_options(KeyHash& h, const SolverOptions& o) {
  h.integer(o.degree).integer(static_cast<int>(o.formulation)).real(o.mixed_threshold);
  h.integer(static_cast<int>(o.solver)).integer(static_cast<std::int64_t>(o.direct_max_dofs));
  h.integer(static_cast<std::int64_t>(o.direct_max_mixed_dofs)).integer(o.amg_rigid_body_modes);
  h.real(o.cg_relative_tolerance).integer(o.gmres_restart).integer(o.max_iterations);
}

// Binary (de)serialisation of a result and its DoF values, native byte order: the cache is a
// machine's own, keyed by its build's code version.
class Writer {
 public:
  template <class T>
  void pod(const T& x) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.append(reinterpret_cast<const char*>(&x), sizeof x);
  }
  void text(const std::string& s) {
    pod(static_cast<std::uint64_t>(s.size()));
    out_ += s;
  }
  template <class T>
  void pods(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    pod(static_cast<std::uint64_t>(v.size()));
    out_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  void point(const Vec3& p) { pod(std::array<double, 3>{p.x(), p.y(), p.z()}); }
  void points(const std::vector<Vec3>& v) {
    pod(static_cast<std::uint64_t>(v.size()));
    for (const Vec3& p : v) point(p);
  }
  [[nodiscard]] const std::string& bytes() const { return out_; }

 private:
  std::string out_;
};

struct Truncated : std::runtime_error {
  Truncated() : std::runtime_error("truncated") {}
};

class Reader {
 public:
  explicit Reader(std::string_view in) : in_(in) {}
  template <class T>
  T pod() {
    T x;
    take(&x, sizeof x);
    return x;
  }
  std::string text() {
    const auto n = pod<std::uint64_t>();
    if (n > in_.size()) throw Truncated();
    std::string s(in_.substr(0, n));
    in_.remove_prefix(n);
    return s;
  }
  template <class T>
  std::vector<T> pods() {
    const auto n = pod<std::uint64_t>();
    if (n > in_.size() / sizeof(T)) throw Truncated();
    std::vector<T> v(n);
    take(v.data(), n * sizeof(T));
    return v;
  }
  Vec3 point() {
    const auto a = pod<std::array<double, 3>>();
    return {a[0], a[1], a[2]};
  }
  std::vector<Vec3> points() {
    const auto n = pod<std::uint64_t>();
    if (n > in_.size() / (3 * sizeof(double))) throw Truncated();
    std::vector<Vec3> v(n);
    for (Vec3& p : v) p = point();
    return v;
  }
  [[nodiscard]] bool done() const { return in_.empty(); }

 private:
  void take(void* out, std::size_t n) {
    if (n > in_.size()) throw Truncated();
    std::memcpy(out, in_.data(), n);
    in_.remove_prefix(n);
  }
  std::string_view in_;
};

std::string serialise(const ElasticityResult& r, const std::vector<double>& dofs) {
  Writer w;
  w.text(r.element);
  w.pod(r.curved);
  w.pod(r.formulation);
  w.pod(r.solver);
  w.text(r.solver_reason);
  w.pod(r.iterations);
  w.pod(r.inner_iterations);
  w.pod(static_cast<std::uint64_t>(r.n_dofs));
  w.pod(static_cast<std::uint64_t>(r.n_pressure_dofs));
  w.points(r.nodal_displacement);
  w.pod(static_cast<std::uint64_t>(r.reactions.size()));
  for (const GroupReaction& g : r.reactions) {
    w.text(g.group);
    w.point(g.force);
  }
  w.point(r.applied_load);
  w.pod(r.strain_energy);
  w.pod(r.max_principal_strain);
  w.pod(r.max_abs_principal_strain);
  w.pods(r.tet_strain);
  w.pods(r.tet_stress);
  w.pod(r.timings);
  w.pods(dofs);
  return w.bytes();
}

std::pair<ElasticityResult, std::vector<double>> deserialise(std::string_view bytes) {
  Reader in(bytes);
  ElasticityResult r;
  r.element = in.text();
  r.curved = in.pod<bool>();
  r.formulation = in.pod<Formulation>();
  r.solver = in.pod<LinearSolver>();
  r.solver_reason = in.text();
  r.iterations = in.pod<unsigned>();
  r.inner_iterations = in.pod<double>();
  r.n_dofs = in.pod<std::uint64_t>();
  r.n_pressure_dofs = in.pod<std::uint64_t>();
  r.nodal_displacement = in.points();
  const auto reactions = in.pod<std::uint64_t>();
  if (reactions > bytes.size()) throw Truncated();
  for (std::uint64_t i = 0; i < reactions; ++i) {
    GroupReaction g;
    g.group = in.text();
    g.force = in.point();
    r.reactions.push_back(std::move(g));
  }
  r.applied_load = in.point();
  r.strain_energy = in.pod<double>();
  r.max_principal_strain = in.pod<double>();
  r.max_abs_principal_strain = in.pod<double>();
  r.tet_strain = in.pods<std::array<double, 6>>();
  r.tet_stress = in.pods<std::array<double, 6>>();
  r.timings = in.pod<PhaseTimings>();
  std::vector<double> dofs = in.pods<double>();
  if (!in.done()) throw Truncated();
  return {std::move(r), std::move(dofs)};
}

std::string serialise_transient(const TransientResult& r) {
  Writer w;
  w.pods(r.time);
  w.pod(static_cast<std::uint64_t>(r.probe_displacement.size()));
  for (const auto& step : r.probe_displacement) w.points(step);
  w.points(r.final_nodal_displacement);
  w.pod(r.setup_seconds);
  w.pod(r.seconds_per_step);
  w.pod(static_cast<std::uint64_t>(r.n_dofs));
  w.pods(r.kinetic_energy);
  w.pods(r.strain_energy);
  w.pods(r.load_work);
  return w.bytes();
}

TransientResult deserialise_transient(std::string_view bytes) {
  Reader in(bytes);
  TransientResult r;
  r.time = in.pods<double>();
  const auto steps = in.pod<std::uint64_t>();
  if (steps > bytes.size()) throw Truncated();
  for (std::uint64_t k = 0; k < steps; ++k) r.probe_displacement.push_back(in.points());
  r.final_nodal_displacement = in.points();
  r.setup_seconds = in.pod<double>();
  r.seconds_per_step = in.pod<double>();
  r.n_dofs = in.pod<std::uint64_t>();
  r.kinetic_energy = in.pods<double>();
  r.strain_energy = in.pods<double>();
  r.load_work = in.pods<double>();
  if (!in.done() || r.time.empty()) throw Truncated();
  return r;
}

}  // namespace

std::optional<std::string> solution_cache_key(const TetMesh& mesh, const ElasticityProblem& p) {
  if (p.body_force) return std::nullopt;
  for (const DirichletCondition& d : p.dirichlet) {
    if (d.value) return std::nullopt;
  }
  KeyHash h;
  hash_mesh(h, mesh);
  const Material& m = p.material;
  h.text("material").real(m.youngs_modulus).real(m.poisson_ratio).real(m.density);
  h.text("dirichlet");
  for (const DirichletCondition& d : p.dirichlet) {
    h.text(d.group).integer(static_cast<int>(d.kind)).integer(d.component);
  }
  h.text("pins");
  for (const PointConstraint& c : p.point_constraints) h.point(c.point).integer(c.component);
  h.text("pressures");
  for (const PressureLoad& l : p.pressures) h.text(l.group).real(l.pressure);
  h.text("patches");
  for (const TractionPatch& t : p.patches) {
    h.point(t.traction).indices(t.triangles);
    for (const SurfacePoint& q : t.points)
      h.integer(q.triangle).point(q.barycentric).real(q.weight);
  }
  h.text("curved");
  for (const CurvedSurface& c : p.curved_surfaces) hash_curved_surface(h, mesh, c);
  h.text("gravity").point(p.gravity);
  h.text("options");
  hash_options(h, p.options);
  return "fem-solution code=" + std::string(kReferenceCodeVersion) + " key=" + h.a.hex() +
         h.b.hex();
}

SolutionCache::SolutionCache(fs::path dir, std::ostream* log, std::string name)
    : store_(std::move(dir), log, std::move(name)) {}

std::optional<std::string> SolutionCache::key_or_count(const TetMesh& mesh,
                                                       const ElasticityProblem& problem) {
  if (!enabled()) return std::nullopt;
  std::optional<std::string> key = solution_cache_key(mesh, problem);
  if (!key) store_.count_uncacheable();
  return key;
}

const ElasticityResult& SolutionCache::solve(ElasticitySolver& solver, const TetMesh& mesh,
                                             const ElasticityProblem& problem) {
  const std::optional<std::string> key = key_or_count(mesh, problem);
  if (!key) return solver.solve();
  store_.lookup(
      *key,
      [&](std::string_view payload) {
        auto [result, dofs] = deserialise(payload);
        const double original = result.timings.assembly + result.timings.solve;
        solver.restore(std::move(result), dofs);
        return original;
      },
      [&] {
        const ElasticityResult& solved = solver.solve();  // before solution_dofs()
        return serialise(solved, solver.solution_dofs());
      });
  return solver.result();
}

bool SolutionCache::contains(const TetMesh& mesh, const ElasticityProblem& problem) {
  const std::optional<std::string> key = key_or_count(mesh, problem);
  if (!key) return false;
  struct NotStored {};
  try {
    store_.lookup(
        *key,
        [](std::string_view payload) {
          const auto [result, dofs] = deserialise(payload);  // throws for an unreadable entry
          return result.timings.assembly + result.timings.solve;
        },
        []() -> std::string { throw NotStored{}; });
  } catch (const NotStored&) {
    return false;
  }
  return true;
}

void SolutionCache::store(const TetMesh& mesh, const ElasticityProblem& problem,
                          const ElasticityResult& result, const std::vector<double>& dofs) {
  const std::optional<std::string> key = key_or_count(mesh, problem);
  if (!key) return;
  store_.lookup(
      *key, [](std::string_view) { return 0.0; }, [&] { return serialise(result, dofs); }, true);
}

TransientResult SolutionCache::transient(const ElasticitySolver& solver, const TetMesh& mesh,
                                         const ElasticityProblem& problem,
                                         const TransientOptions& options) {
  const std::optional<std::string> solution_key = key_or_count(mesh, problem);
  if (!solution_key) return solver.transient(options);
  KeyHash h;
  h.real(options.dt).integer(options.steps).real(options.mass_damping);
  h.real(options.outside_tolerance);
  for (const Vec3& p : options.probe_points) h.point(p);
  TransientResult result;
  store_.lookup(
      *solution_key + " transient=" + h.a.hex() + h.b.hex(),
      [&](std::string_view payload) {
        result = deserialise_transient(payload);
        return result.setup_seconds +
               result.seconds_per_step * static_cast<double>(result.time.size() - 1);
      },
      [&] {
        result = solver.transient(options);
        return serialise_transient(result);
      });
  return result;
}

std::optional<std::string> continuation_cache_key(const TetMesh& mesh,
                                                  const ElasticityProblem& problem,
                                                  const HyperelasticOptions& o,
                                                  std::string_view what) {
  const std::optional<std::string> base = solution_cache_key(mesh, problem);
  if (!base) return std::nullopt;
  KeyHash h;
  h.text("hyperelastic").real(o.target_load_factor).real(o.initial_step).real(o.min_step);
  h.real(o.max_step).real(o.growth).integer(o.fast_iterations).integer(o.max_newton_iterations);
  h.integer(o.max_line_search).real(o.residual_tolerance).integer(o.follower_pressure ? 1 : 0);
  h.text("self-contact").integer(o.stop_at_self_contact ? 1 : 0);
  h.text("checkpoints").integer(static_cast<std::int64_t>(o.checkpoints.size()));
  for (const double c : o.checkpoints) h.real(c);
  h.text("what").text(what);
  return *base + " continuation=" + h.a.hex() + h.b.hex();
}

const ElasticityResult& solve_with(SolutionCache* cache, ElasticitySolver& solver,
                                   const TetMesh& mesh, const ElasticityProblem& problem) {
  return cache ? cache->solve(solver, mesh, problem) : solver.solve();
}

}  // namespace vessel::fem
