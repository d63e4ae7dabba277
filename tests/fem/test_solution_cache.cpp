// The FEM solution cache (issue 16): a hit restores exactly what a fresh solve computes, any
// changed input misses, and a corrupt or truncated entry is detected and recomputed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "../test_helpers.hpp"
#include "fem_reference/solution_cache.hpp"
#include "fem_test_meshes.hpp"
#include "lame_problem.hpp"

namespace vessel {
namespace {

namespace fs = std::filesystem;

/// Lamé's tube with curved P2 walls: the key must also see the walls' projection.
fem::ElasticityProblem curved_lame(double nu) {
  fem::ElasticityProblem p = test::lame_problem(nu, 2, fem::Formulation::displacement);
  p.curved_surfaces = fem::tube_curved_walls(3e-3, 4e-3);
  return p;
}

std::vector<fs::path> entries(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir)) files.push_back(e.path());
  return files;
}

/// Points inside the tube's wall where the restored and the fresh fields are compared.
std::vector<Vec3> probes() {
  return {{3.5e-3, 0.0, 0.5e-3}, {0.0, -3.2e-3, 0.2e-3}, {2.5e-3, 2.5e-3, 0.8e-3}};
}

void expect_same_solution(const fem::ElasticitySolver& a, const fem::ElasticitySolver& b) {
  EXPECT_EQ(a.solution_dofs(), b.solution_dofs());  // bitwise
  const fem::ElasticityResult &ra = a.result(), &rb = b.result();
  ASSERT_EQ(ra.nodal_displacement.size(), rb.nodal_displacement.size());
  for (std::size_t i = 0; i < ra.nodal_displacement.size(); ++i) {
    ASSERT_EQ(ra.nodal_displacement[i], rb.nodal_displacement[i]) << "node " << i;
  }
  EXPECT_EQ(ra.tet_strain, rb.tet_strain);
  EXPECT_EQ(ra.tet_stress, rb.tet_stress);
  EXPECT_EQ(ra.strain_energy, rb.strain_energy);
  EXPECT_EQ(ra.max_abs_principal_strain, rb.max_abs_principal_strain);
  EXPECT_EQ(ra.element, rb.element);
  EXPECT_EQ(ra.n_dofs, rb.n_dofs);
  ASSERT_EQ(ra.reactions.size(), rb.reactions.size());
  for (std::size_t g = 0; g < ra.reactions.size(); ++g) {
    EXPECT_EQ(ra.reactions[g].force, rb.reactions[g].force);
  }
  const auto ua = a.displacement_at(probes()), ub = b.displacement_at(probes());
  for (std::size_t i = 0; i < ua.size(); ++i) EXPECT_EQ(ua[i], ub[i]);
}

TEST(SolutionCache, AHitRestoresTheFreshSolveBitwise) {
  const TetMesh& mesh = test::short_tube_mesh(0);
  const fem::ElasticityProblem problem = curved_lame(0.3);
  fem::ElasticitySolver fresh(mesh, problem);
  fresh.solve();

  test::TempDir dir;
  std::ostringstream log;
  fem::SolutionCache cache(dir.path(), &log);
  fem::ElasticitySolver first(mesh, problem), second(mesh, problem);
  cache.solve(first, mesh, problem);
  cache.solve(second, mesh, problem);
  const ContentStoreStatistics s = cache.statistics();
  EXPECT_EQ(s.misses, 1);
  EXPECT_EQ(s.hits, 1);
  EXPECT_EQ(s.corrupt, 0);
  EXPECT_EQ(entries(dir.path()).size(), 1u);
  expect_same_solution(fresh, first);
  expect_same_solution(fresh, second);
  // A second cache object on the same directory (another run) hits too.
  fem::SolutionCache later(dir.path(), &log);
  fem::ElasticitySolver third(mesh, problem);
  later.solve(third, mesh, problem);
  EXPECT_EQ(later.statistics().hits, 1);
  expect_same_solution(fresh, third);
  EXPECT_EQ(log.str(), "");
}

TEST(SolutionCache, AStoredSolutionIsFoundAndRestoredAsASolvedOne) {
  // What the distributed reference job does: store a result and DoFs solved elsewhere (here a
  // serial solve), then a serial solve() on the same cache restores them without solving.
  const TetMesh& mesh = test::short_tube_mesh(0);
  const fem::ElasticityProblem problem = test::lame_problem(0.3, 2, fem::Formulation::displacement);
  fem::ElasticitySolver fresh(mesh, problem);
  fresh.solve();
  test::TempDir dir;
  std::ostringstream log;
  fem::SolutionCache cache(dir.path(), &log);
  EXPECT_FALSE(cache.contains(mesh, problem));
  cache.store(mesh, problem, fresh.result(), fresh.solution_dofs());
  EXPECT_TRUE(cache.contains(mesh, problem));
  fem::ElasticityProblem other = problem;
  other.material.poisson_ratio = 0.31;
  EXPECT_FALSE(cache.contains(mesh, other));

  fem::SolutionCache later(dir.path(), &log);
  fem::ElasticitySolver restored(mesh, problem);
  later.solve(restored, mesh, problem);
  EXPECT_EQ(later.statistics().hits, 1);
  EXPECT_EQ(later.statistics().misses, 0);
  expect_same_solution(fresh, restored);

  // A corrupt entry is not "contained": the job solves and stores it again.
  const fs::path entry = entries(dir.path()).at(0);
  fs::resize_file(entry, fs::file_size(entry) - 100);
  EXPECT_FALSE(later.contains(mesh, problem));
  EXPECT_NE(log.str().find("corrupt (truncated)"), std::string::npos) << log.str();
}

TEST(SolutionCache, EveryChangedInputChangesTheKey) {
  const TetMesh& mesh = test::short_tube_mesh(0);
  const fem::ElasticityProblem base = curved_lame(0.3);
  const auto key = fem::solution_cache_key(mesh, base);
  ASSERT_TRUE(key.has_value());
  EXPECT_EQ(fem::solution_cache_key(mesh, curved_lame(0.3)), key);  // deterministic

  std::vector<std::pair<std::string, fem::ElasticityProblem>> changed;
  auto with = [&](std::string what, auto change) {
    fem::ElasticityProblem p = base;
    change(p);
    changed.emplace_back(std::move(what), std::move(p));
  };
  with("nu", [](auto& p) { p.material.poisson_ratio = 0.30000000001; });
  with("E", [](auto& p) { p.material.youngs_modulus *= 1.5; });
  with("density", [](auto& p) { p.material.density = 1000.0; });
  with("pressure", [](auto& p) { p.pressures[0].pressure *= 2.0; });
  with("loaded group", [](auto& p) { p.pressures[0].group = "outer_wall"; });
  with("roller component", [](auto& p) { p.dirichlet[0].component = 1; });
  with("clamped instead of roller",
       [](auto& p) { p.dirichlet[0] = fem::DirichletCondition::clamped("inlet"); });
  with("pin", [](auto& p) { p.point_constraints.pop_back(); });
  with("curved wall radius",
       [](auto& p) { p.curved_surfaces = fem::tube_curved_walls(3.01e-3, 4e-3); });
  with("degree", [](auto& p) { p.options.degree = 1; });
  with("solver", [](auto& p) { p.options.solver = fem::LinearSolver::cg_amg; });
  with("CG tolerance", [](auto& p) { p.options.cg_relative_tolerance = 1e-9; });
  with("gravity", [](auto& p) { p.gravity = Vec3(0.0, -9.81, 0.0); });
  for (const auto& [what, p] : changed) {
    EXPECT_NE(fem::solution_cache_key(mesh, p), key) << what;
  }
  TetMesh moved = mesh;
  moved.nodes[7].x() += 1e-12;
  EXPECT_NE(fem::solution_cache_key(moved, base), key) << "a node moved by 1e-12 m";
  EXPECT_NE(fem::solution_cache_key(test::short_tube_mesh(1), base), key) << "another mesh";

  // Through the cache: the changed ν misses and is stored beside the first entry.
  test::TempDir dir;
  fem::SolutionCache cache(dir.path());
  fem::ElasticitySolver a(mesh, base), b(mesh, changed[0].second);
  cache.solve(a, mesh, base);
  cache.solve(b, mesh, changed[0].second);
  EXPECT_EQ(cache.statistics().misses, 2);
  EXPECT_EQ(cache.statistics().hits, 0);
  EXPECT_EQ(entries(dir.path()).size(), 2u);
}

TEST(SolutionCache, ACorruptOrTruncatedEntryIsRecomputedWithAMessage) {
  const TetMesh& mesh = test::short_tube_mesh(0);
  const fem::ElasticityProblem problem = test::lame_problem(0.3, 1, fem::Formulation::displacement);
  fem::ElasticitySolver fresh(mesh, problem);
  fresh.solve();
  test::TempDir dir;
  std::ostringstream log;
  fem::SolutionCache cache(dir.path(), &log);
  {
    fem::ElasticitySolver s(mesh, problem);
    cache.solve(s, mesh, problem);
  }
  const fs::path entry = entries(dir.path()).at(0);
  const auto size = fs::file_size(entry);
  {  // flip one byte in the middle of the stored displacements
    std::fstream f(entry, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(static_cast<std::streamoff>(size / 2));
    char c = 0;
    f.get(c);
    f.seekp(static_cast<std::streamoff>(size / 2));
    f.put(static_cast<char>(c ^ 0x10));
  }
  fem::ElasticitySolver after_flip(mesh, problem);
  cache.solve(after_flip, mesh, problem);
  expect_same_solution(fresh, after_flip);
  EXPECT_NE(log.str().find("corrupt (checksum mismatch)"), std::string::npos) << log.str();

  fs::resize_file(entry, size - 100);
  fem::ElasticitySolver after_truncation(mesh, problem);
  cache.solve(after_truncation, mesh, problem);
  expect_same_solution(fresh, after_truncation);
  EXPECT_NE(log.str().find("corrupt (truncated)"), std::string::npos) << log.str();

  const ContentStoreStatistics s = cache.statistics();
  EXPECT_EQ(s.misses, 3);
  EXPECT_EQ(s.corrupt, 2);
  EXPECT_EQ(s.hits, 0);
  EXPECT_EQ(fs::file_size(entry), size);  // replaced by a whole entry again
  fem::ElasticitySolver hit(mesh, problem);
  cache.solve(hit, mesh, problem);
  EXPECT_EQ(cache.statistics().hits, 1);
  expect_same_solution(fresh, hit);
}

TEST(SolutionCache, AStoredTransientEqualsTheFreshOneAndOtherStepsMiss) {
  const TetMesh& mesh = test::short_tube_mesh(0);
  const fem::ElasticityProblem problem = test::lame_problem(0.3, 1, fem::Formulation::displacement);
  fem::TransientOptions t;
  t.dt = 1e-4;
  t.steps = 20;
  t.mass_damping = 5.0;
  t.probe_points = probes();
  const fem::ElasticitySolver solver(mesh, problem);
  const fem::TransientResult fresh = solver.transient(t);

  test::TempDir dir;
  fem::SolutionCache cache(dir.path());
  const fem::TransientResult stored = cache.transient(solver, mesh, problem, t);
  const fem::TransientResult read = cache.transient(solver, mesh, problem, t);
  EXPECT_EQ(cache.statistics().misses, 1);
  EXPECT_EQ(cache.statistics().hits, 1);
  for (const fem::TransientResult* r : {&stored, &read}) {
    EXPECT_EQ(r->time, fresh.time);
    ASSERT_EQ(r->probe_displacement.size(), fresh.probe_displacement.size());
    for (std::size_t k = 0; k < fresh.probe_displacement.size(); ++k) {
      for (std::size_t i = 0; i < fresh.probe_displacement[k].size(); ++i) {
        ASSERT_EQ(r->probe_displacement[k][i], fresh.probe_displacement[k][i]) << k << " " << i;
      }
    }
    EXPECT_EQ(r->kinetic_energy, fresh.kinetic_energy);
    EXPECT_EQ(r->strain_energy, fresh.strain_energy);
    EXPECT_EQ(r->load_work, fresh.load_work);
    EXPECT_EQ(r->final_nodal_displacement, fresh.final_nodal_displacement);
  }
  fem::TransientOptions other = t;
  other.dt = 2e-4;
  cache.transient(solver, mesh, problem, other);
  other = t;
  other.probe_points.pop_back();
  cache.transient(solver, mesh, problem, other);
  EXPECT_EQ(cache.statistics().misses, 3);
  EXPECT_EQ(cache.statistics().hits, 1);
}

TEST(SolutionCache, ProblemsWithFunctionsAreSolvedButNotStored) {
  const TetMesh& mesh = test::short_tube_mesh(0);
  fem::ElasticityProblem problem = test::lame_problem(0.3, 1, fem::Formulation::displacement);
  problem.body_force = [](const Vec3&) { return Vec3(0.0, 0.0, 1.0); };
  EXPECT_FALSE(fem::solution_cache_key(mesh, problem).has_value());
  test::TempDir dir;
  fem::SolutionCache cache(dir.path());
  fem::ElasticitySolver s(mesh, problem);
  cache.solve(s, mesh, problem);
  EXPECT_EQ(cache.statistics().uncacheable, 1);
  EXPECT_TRUE(entries(dir.path()).empty());
}

TEST(SolutionCache, AnEmptyDirectoryDisablesIt) {
  const TetMesh& mesh = test::short_tube_mesh(0);
  const fem::ElasticityProblem problem = test::lame_problem(0.3, 1, fem::Formulation::displacement);
  fem::SolutionCache off{fs::path()};
  fem::ElasticitySolver s(mesh, problem);
  off.solve(s, mesh, problem);
  EXPECT_FALSE(off.enabled());
  EXPECT_EQ(off.statistics().misses + off.statistics().hits, 0);
  EXPECT_EQ(off.summary(), "FEM solution cache: off (--no-cache)");
}

}  // namespace
}  // namespace vessel
