/// The distributed (MPI) FEM reference against a second solver: the serial ElasticitySolver with
/// a direct factorisation (CHOLMOD; UMFPACK for Taylor–Hood), on the same mesh and problem, at the
/// mesh's nodes and at points where a model's nodes sit; the gathered DoFs restored into a serial
/// solver (what the solution cache stores); and the solve on one rank
/// (MPI_COMM_SELF) against the solve on every rank; the ranks other than 0 given no mesh at all.
/// Run by ctest under `mpirun -np 2` (see CMakeLists.txt); every comparison is made on rank 0, and
/// any rank's failure fails the run.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include "fem_reference/distributed_elasticity.hpp"
#include "fem_reference/elasticity.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/surface_loads.hpp"

using namespace vessel;
using namespace vessel::fem;

namespace {

int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}
int world_size() {
  int s = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}

/// A short unstructured tube (a = 3 mm, t = 1 mm, L = 6 mm, gmsh level 0), meshed on rank 0
/// and sent to the others.
constexpr double kLength = 6e-3;
const TetMesh& tube() {
  static const TetMesh mesh = make_mesh_on_rank0([] {
    VesselParams p;
    p.length = kLength;
    p.level = 0;
    return generate_vessel_mesh(p);
  });
  return mesh;
}

/// Solved to well below the 1e-8 comparison tolerance: CG's relative residual 1e-13.
constexpr double kCgTolerance = 1e-13;
constexpr double kAgreement = 1e-8;

double max_norm(const std::vector<Vec3>& v) {
  double m = 0.0;
  for (const auto& x : v) m = std::max(m, x.norm());
  return m;
}
/// max_i |a_i − b_i| / max_i |b_i|
double max_relative_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).norm());
  return d / max_norm(b);
}

enum class Load { contact, pressure_rollers, pressure_gravity };

ElasticityProblem make_problem(Load load, int degree, double nu = 0.3) {
  const TetMesh& mesh = tube();
  ElasticityProblem p;
  p.material.poisson_ratio = nu;  // automatic: Taylor–Hood from the mixed threshold 0.49 on
  p.options.degree = degree;
  p.options.cg_relative_tolerance = kCgTolerance;
  if (load == Load::contact) {
    // The shared catheter patch at mid-length on the inner wall; both ends clamped.
    ContactPatchSpec spec;
    spec.point = Vec3(3e-3, 0.0, 0.5 * kLength);
    spec.radius = 1e-3;
    spec.force = 1e-4;
    p.patches.push_back(contact_patch(mesh, spec));
    p.dirichlet = {DirichletCondition::clamped("inlet"), DirichletCondition::clamped("outlet")};
  } else if (load == Load::pressure_rollers) {
    // The Lamé set-up: rollers on both ends and three point pins.
    p.pressures.push_back({"inner_wall", 10.0});
    p.dirichlet = {DirichletCondition::roller("inlet", 2), DirichletCondition::roller("outlet", 2)};
    p.point_constraints = tube_in_plane_pins(3e-3, 0.0);
  } else {
    p.pressures.push_back({"inner_wall", 5.0});
    p.gravity = Vec3(0.0, -9.81, 0.0);
    p.dirichlet = {DirichletCondition::clamped("inlet")};
  }
  return p;
}

/// Where a model's nodes sit: on the exact inner and outer cylinders (up to the chord's sagitta
/// outside the straight-sided tets, as the harness's surface models) and mid-wall, at angles and
/// heights that are not the mesh's nodes.
std::vector<Vec3> model_like_points() {
  std::vector<Vec3> out;
  for (int j = 0; j < 60; ++j) {
    const double theta = 0.37 + 2.0 * M_PI * j / 60.0;
    const double z = kLength * (0.05 + 0.9 * ((j * 7) % 60) / 60.0);
    for (const double r : {3e-3, 3.5e-3, 4e-3}) {
      out.emplace_back(r * std::cos(theta), r * std::sin(theta), z);
    }
  }
  return out;
}
/// The harness's barycentric tolerance for model nodes (verification/harness/references.hpp).
constexpr double kModelNodeTolerance = 0.25;

/// Rank 0: the distributed solve at model-like points against the serial solver's
/// displacement_at there, and the serial solver restored from the gathered DoFs (what
/// fem::SolutionCache stores) evaluating the same points: the serial DoF numbering must be right.
void check_points_and_serial_dofs(const DistributedResult& d, const ElasticitySolver& serial,
                                  const ElasticityProblem& problem) {
  const std::vector<Vec3> points = model_like_points();
  const std::vector<Vec3> s = serial.displacement_at(points, kModelNodeTolerance);
  const double diff = max_relative_difference(d.point_displacement, s);
  std::printf("%d rank(s): %zu model-like points, max |u - u_serial| / max |u| = %.3g\n",
              d.n_ranks, points.size(), diff);
  EXPECT_LT(diff, kAgreement);
  ElasticitySolver restored(tube(), problem);
  ASSERT_EQ(d.serial_dofs.size(), serial.result().n_dofs);
  restored.restore(d.fem, d.serial_dofs);
  const std::vector<Vec3> r = restored.displacement_at(points, kModelNodeTolerance);
  // The same coefficients evaluated two ways: equal to rounding.
  EXPECT_LT(max_relative_difference(r, d.point_displacement), 1e-12);
  EXPECT_LT(max_relative_difference(r, s), kAgreement);
  EXPECT_LT(max_relative_difference(restored.result().nodal_displacement,
                                    serial.result().nodal_displacement),
            kAgreement);
}

/// The distributed solve over every rank and over rank 0 alone, checked against CHOLMOD (serial
/// ElasticitySolver, direct) on rank 0: nodal displacement, contact-point displacement, applied
/// load, reactions and strain energy. `solver`: the distributed solve's (the displacement
/// system's CG-AMG by default, or the matrix-free p-multigrid).
void check_against_serial(Load load, int degree, double nu = 0.3,
                          LinearSolver solver = LinearSolver::automatic) {
  const TetMesh& mesh = tube();
  ElasticityProblem problem = make_problem(load, degree, nu);
  problem.options.solver = solver;
  const bool mixed = nu >= problem.options.mixed_threshold;
  const LinearSolver expected = mixed                                 ? LinearSolver::gmres_block
                                : solver == LinearSolver::matrix_free ? solver
                                                                      : LinearSolver::cg_amg;
  DistributedOptions opt;
  const Vec3 point(3.2e-3, 0.1e-3, 0.5 * kLength);  // inside the wall, off the nodes
  opt.evaluation_points = {point};
  for (const Vec3& x : model_like_points()) opt.evaluation_points.push_back(x);
  opt.outside_tolerance = kModelNodeTolerance;
  opt.serial_dofs = true;
  const DistributedResult all = solve_elasticity_distributed(mesh, problem, opt);
  EXPECT_EQ(all.n_ranks, world_size());
  ASSERT_EQ(all.cells_per_rank.size(), static_cast<std::size_t>(world_size()));
  std::size_t cells = 0;
  for (auto c : all.cells_per_rank) cells += c;
  EXPECT_EQ(cells, mesh.tets.size());
  if (world_size() > 1) {
    for (auto c : all.cells_per_rank) EXPECT_GT(c, 0u) << "a rank got no cells";
  }
  if (world_rank() != 0) {
    EXPECT_TRUE(all.fem.nodal_displacement.empty());
    return;
  }

  ElasticityProblem direct = problem;
  direct.options.solver = LinearSolver::direct;
  ElasticitySolver serial(mesh, direct);
  const ElasticityResult& s = serial.solve();
  ASSERT_EQ(s.solver, LinearSolver::direct);
  const Vec3 s_point = serial.displacement_at({point})[0];
  const std::string element = mixed ? "P2-P1 (Taylor-Hood)" : degree == 1 ? "P1" : "P2";
  ASSERT_EQ(s.element, element);

  DistributedOptions self = opt;
  self.self_only = true;
  const DistributedResult one = solve_elasticity_distributed(mesh, problem, self);
  EXPECT_EQ(one.n_ranks, 1);

  // Force scale: the net load, or the pressure's |p|·A when it cancels over the closed wall.
  double load_scale = s.applied_load.norm();
  for (const auto& pr : problem.pressures) {
    load_scale = std::max(
        load_scale, std::abs(pr.pressure) * group_area(mesh, mesh.require_group(pr.group, 2, "")));
  }
  for (const DistributedResult* d : {&all, &one}) {
    SCOPED_TRACE(std::to_string(d->n_ranks) + " rank(s)");
    const auto& r = d->fem;
    EXPECT_EQ(r.n_dofs, s.n_dofs);
    EXPECT_EQ(r.element, element);
    EXPECT_EQ(r.n_pressure_dofs, s.n_pressure_dofs);
    EXPECT_EQ(r.solver, expected);
    EXPECT_GT(r.iterations, 0u);
    ASSERT_EQ(r.nodal_displacement.size(), mesh.nodes.size());
    const double diff = max_relative_difference(r.nodal_displacement, s.nodal_displacement);
    std::printf("%d rank(s): %zu DoFs, %u Krylov iterations, max |u - u_direct| / max |u| = %.3g\n",
                d->n_ranks, r.n_dofs, r.iterations, diff);
    EXPECT_LT(diff, kAgreement);
    EXPECT_LT((d->point_displacement.at(0) - s_point).norm() / max_norm(s.nodal_displacement),
              kAgreement);
    DistributedResult at_points = *d;
    at_points.point_displacement.erase(at_points.point_displacement.begin());
    check_points_and_serial_dofs(at_points, serial, problem);
    EXPECT_LT((r.applied_load - s.applied_load).norm(), 1e-12 * load_scale);
    EXPECT_NEAR(r.strain_energy, s.strain_energy, kAgreement * s.strain_energy);
    ASSERT_EQ(r.reactions.size(), s.reactions.size());
    for (std::size_t g = 0; g < s.reactions.size(); ++g) {
      EXPECT_EQ(r.reactions[g].group, s.reactions[g].group);
      EXPECT_LT((r.reactions[g].force - s.reactions[g].force).norm(), kAgreement * load_scale)
          << r.reactions[g].group;
    }
  }
  // One rank against all ranks: the same field to solver tolerance.
  const double diff =
      max_relative_difference(all.fem.nodal_displacement, one.fem.nodal_displacement);
  std::printf("1 vs %d ranks: max |u_1 - u_n| / max |u_1| = %.3g\n", all.n_ranks, diff);
  EXPECT_LT(diff, kAgreement);
}

/// The InputError every rank throws (they all validate the same input), or "".
std::string input_error(const ElasticityProblem& p) {
  try {
    (void)solve_elasticity_distributed(tube(), p);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(DistributedElasticity, P1ContactMatchesCholmodOnOneAndAllRanks) {
  check_against_serial(Load::contact, 1);
}
TEST(DistributedElasticity, P2ContactMatchesCholmodOnOneAndAllRanks) {
  check_against_serial(Load::contact, 2);
}
TEST(DistributedElasticity, TaylorHoodContactAtNu049MatchesUmfpackOnOneAndAllRanks) {
  check_against_serial(Load::contact, 2, 0.49);
}
TEST(DistributedElasticity, TaylorHoodIncompressibleContactMatchesUmfpack) {
  check_against_serial(Load::contact, 2, 0.5);
}
TEST(DistributedElasticity, TaylorHoodPressureRollersAndPinsMatchUmfpack) {
  check_against_serial(Load::pressure_rollers, 2, 0.5);
}
TEST(DistributedElasticity, P1PressureRollersAndPinsMatchCholmod) {
  check_against_serial(Load::pressure_rollers, 1);
}
TEST(DistributedElasticity, P2PressureRollersAndPinsMatchCholmod) {
  check_against_serial(Load::pressure_rollers, 2);
}
TEST(DistributedElasticity, P2PressureAndGravityClampedInletMatchCholmod) {
  check_against_serial(Load::pressure_gravity, 2);
}

// The matrix-free p-multigrid on each rank's cells (the batched kernel reading ghosts, the P1
// level's distributed matrix and ML, the P2 -> P1 embedding across ranks) against CHOLMOD.
TEST(DistributedElasticity, MatrixFreeP2ContactMatchesCholmodOnOneAndAllRanks) {
  check_against_serial(Load::contact, 2, 0.3, LinearSolver::matrix_free);
}
TEST(DistributedElasticity, MatrixFreeP2PressureRollersAndPinsMatchCholmod) {
  check_against_serial(Load::pressure_rollers, 2, 0.3, LinearSolver::matrix_free);
}
TEST(DistributedElasticity, MatrixFreeP2PressureAndGravityAtNu045MatchCholmod) {
  check_against_serial(Load::pressure_gravity, 2, 0.45, LinearSolver::matrix_free);
}
TEST(DistributedElasticity, MatrixFreeP1ContactMatchesCholmodOnOneAndAllRanks) {
  check_against_serial(Load::contact, 1, 0.3, LinearSolver::matrix_free);
}

TEST(DistributedElasticity, OtherRanksGetOnlyTheirPartAndEvaluateTheirPointsAsTheSerialSolver) {
  // Rank 0 alone passes the mesh, the problem and the points; the others pass an empty mesh and a
  // default problem, so whatever they solve came from rank 0's partition.
  const bool root = world_rank() == 0;
  const std::size_t n_tets = tube().tets.size();  // collective: the test's mesh, made on rank 0
  const TetMesh empty;
  const ElasticityProblem problem = root ? make_problem(Load::contact, 2) : ElasticityProblem{};
  DistributedOptions opt;
  if (root) {
    opt.evaluation_points = model_like_points();
    opt.outside_tolerance = kModelNodeTolerance;
  }
  const DistributedResult d = solve_elasticity_distributed(root ? tube() : empty, problem, opt);
  const std::size_t n_points = model_like_points().size();
  ASSERT_EQ(d.point_displacement.size(), n_points);
  ASSERT_EQ(d.point_rank.size(), n_points);
  ASSERT_EQ(d.local_tets_per_rank.size(), static_cast<std::size_t>(world_size()));
  std::size_t total = 0;
  for (auto c : d.cells_per_rank) total += c;
  EXPECT_EQ(total, n_tets);
  for (int r = 0; r < world_size(); ++r) {
    const auto held = d.local_tets_per_rank[static_cast<std::size_t>(r)];
    EXPECT_GE(held, d.cells_per_rank[static_cast<std::size_t>(r)]) << "rank " << r;
    if (world_size() > 1) {
      EXPECT_LT(held, total) << "rank " << r << " holds the whole mesh";
    }
  }
  // The serial direct solve on rank 0, sent to every rank: each rank checks every point, the
  // points of the other ranks' cells included.
  std::vector<double> serial(3 * n_points, 0.0);
  if (root) {
    ElasticityProblem direct = problem;
    direct.options.solver = LinearSolver::direct;
    ElasticitySolver solver(tube(), direct);
    solver.solve();
    const auto u = solver.displacement_at(model_like_points(), kModelNodeTolerance);
    for (std::size_t k = 0; k < n_points; ++k)
      for (int c = 0; c < 3; ++c) serial[3 * k + static_cast<std::size_t>(c)] = u[k][c];
  }
  MPI_Bcast(serial.data(), static_cast<int>(serial.size()), MPI_DOUBLE, 0, MPI_COMM_WORLD);
  std::vector<Vec3> expected(n_points), mine, others, mine_expected, others_expected;
  for (std::size_t k = 0; k < n_points; ++k) {
    expected[k] = Vec3(serial[3 * k], serial[3 * k + 1], serial[3 * k + 2]);
    const bool by_me = d.point_rank[k] == world_rank();
    (by_me ? mine : others).push_back(d.point_displacement[k]);
    (by_me ? mine_expected : others_expected).push_back(expected[k]);
  }
  if (world_size() > 1) {
    EXPECT_FALSE(others.empty()) << "every point fell in rank " << world_rank() << "'s cells";
    EXPECT_FALSE(mine.empty()) << "no point fell in rank " << world_rank() << "'s cells";
  }
  const double scale = max_norm(expected);
  const auto diff = [&](const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
    double m = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, (a[i] - b[i]).norm());
    return m / scale;
  };
  EXPECT_LT(diff(mine, mine_expected), kAgreement) << "rank " << world_rank() << ", own points";
  EXPECT_LT(diff(others, others_expected), kAgreement)
      << "rank " << world_rank() << ", the other ranks' points";
}

TEST(DistributedElasticity, AFunctionOnlyRankZeroHasIsRefusedOnEveryRank) {
  // A prescribed displacement is a function: it cannot be sent, so every rank must pass it.
  ElasticityProblem p = make_problem(Load::contact, 1);
  if (world_rank() == 0) {
    p.dirichlet[0].value = [](const Vec3&) { return Vec3(0.0, 0.0, 1e-6); };
  }
  std::string msg;
  try {
    (void)solve_elasticity_distributed(tube(), p);
  } catch (const std::logic_error& e) {
    msg = e.what();
  }
  if (world_size() > 1) {
    EXPECT_NE(msg.find("prescribed displacement on 'inlet'"), std::string::npos) << msg;
  } else {
    EXPECT_EQ(msg, "");  // one rank: its own function
  }
}

TEST(DistributedElasticity, GravityLoadIsTheWeightAndReactionsBalanceIt) {
  // Independent of any solver: the applied load of gravity is ρ g V (V the tets' volume), and the
  // one clamped end carries all of it.
  ElasticityProblem p;
  p.options.cg_relative_tolerance = kCgTolerance;
  p.gravity = Vec3(0.0, -9.81, 0.0);
  p.dirichlet = {DirichletCondition::clamped("inlet")};
  const auto d = solve_elasticity_distributed(tube(), p);
  const Vec3 weight = p.material.density * mesh_volume(tube()) * p.gravity;
  EXPECT_LT((d.fem.applied_load - weight).norm(), 1e-12 * weight.norm());
  ASSERT_EQ(d.fem.reactions.size(), 1u);
  EXPECT_LT((d.fem.reactions[0].force + weight).norm(), 1e-8 * weight.norm());
}

TEST(DistributedElasticity, RefusesWhatIsNotDistributedWithClearMessages) {
  ElasticityProblem p = make_problem(Load::contact, 2);
  p.material.poisson_ratio = 0.5;
  p.options.formulation = Formulation::displacement;  // λ infinite: refused as by the serial solver
  EXPECT_NE(input_error(p).find("0.5"), std::string::npos) << input_error(p);
  p = make_problem(Load::contact, 2);
  p.curved_surfaces = tube_curved_walls(3e-3, 4e-3);
  EXPECT_NE(input_error(p).find("curved"), std::string::npos);
  p = make_problem(Load::contact, 1);
  p.options.solver = LinearSolver::direct;
  EXPECT_NE(input_error(p).find("solver 'direct' is serial only"), std::string::npos);
  p.options.solver = LinearSolver::matrix_free;
  p.material.poisson_ratio = 0.5;
  p.options.formulation = Formulation::automatic;
  EXPECT_NE(input_error(p).find("matrix-free is for the displacement system"), std::string::npos);
  p = make_problem(Load::contact, 1);
  p.material.youngs_modulus = -1.0;
  EXPECT_NE(input_error(p).find("Young's modulus"), std::string::npos);
  p = make_problem(Load::contact, 3);
  EXPECT_NE(input_error(p).find("degree = 3"), std::string::npos);
  p = make_problem(Load::contact, 1);
  p.dirichlet.push_back(DirichletCondition::clamped("no_such_group"));
  EXPECT_NE(input_error(p).find("no_such_group"), std::string::npos);
  p = make_problem(Load::pressure_rollers, 1);
  p.point_constraints.push_back({Vec3(3.5e-3, 0.0, 1.0), 0});  // far beyond the tube's end
  EXPECT_NE(input_error(p).find("no mesh node there"), std::string::npos);
}

TEST(DistributedElasticity, EvaluationPointOutsideTheWallIsAnInputError) {
  ElasticityProblem p = make_problem(Load::contact, 1);
  DistributedOptions opt;
  opt.evaluation_points = {Vec3(0.0, 0.0, 0.5 * kLength)};  // on the axis, in the lumen
  std::string msg;
  try {
    (void)solve_elasticity_distributed(tube(), p, opt);
  } catch (const InputError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("outside the FEM mesh"), std::string::npos) << msg;
}

TEST(DistributedMesh, RankZeroMeshReachesEveryRankAndItsErrorsToo) {
  // A hand-built mesh (one tet, one triangle group) made on rank 0 only.
  TetMesh made;
  made.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  made.tets = {{0, 1, 2, 3}};
  made.triangles = {{0, 2, 1}};
  made.groups = {{"bottom", 2, 7, {0}}, {"wall", 3, 10, {0}}};
  int calls = 0;
  const TetMesh got = make_mesh_on_rank0([&] {
    ++calls;
    return made;
  });
  EXPECT_EQ(calls, world_rank() == 0 ? 1 : 0);
  EXPECT_EQ(got.nodes, made.nodes);
  EXPECT_EQ(got.tets, made.tets);
  EXPECT_EQ(got.triangles, made.triangles);
  ASSERT_EQ(got.groups.size(), 2u);
  EXPECT_EQ(got.groups[0].name, "bottom");
  EXPECT_EQ(got.groups[0].tag, 7);
  EXPECT_EQ(got.groups[1].dim, 3);
  EXPECT_EQ(got.groups[1].elements, std::vector<int>{0});

  std::string msg;
  try {
    (void)make_mesh_on_rank0([]() -> TetMesh { throw InputError("mesh.msh line 3: bad node"); });
  } catch (const InputError& e) {
    msg = e.what();
  }
  EXPECT_EQ(msg, "mesh.msh line 3: bad node");
}

int main(int argc, char** argv) {
  MpiSession mpi;
  bool listing = false;  // before InitGoogleTest, which removes the flags it knows from argv
  for (int i = 1; i < argc; ++i) listing |= std::strcmp(argv[i], "--gtest_list_tests") == 0;
  ::testing::InitGoogleTest(&argc, argv);
  if (mpi.rank() != 0) {
    // One test list for ctest's discovery; the other ranks report failures only (to stderr).
    if (listing) (void)std::freopen("/dev/null", "w", stdout);
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
    struct FailurePrinter : ::testing::EmptyTestEventListener {
      int rank;
      explicit FailurePrinter(int r) : rank(r) {}
      void OnTestPartResult(const ::testing::TestPartResult& r) override {
        if (r.failed()) {
          std::fprintf(stderr, "[rank %d] %s:%d: Failure\n%s\n", rank,
                       r.file_name() ? r.file_name() : "?", r.line_number(), r.summary());
        }
      }
    };
    listeners.Append(new FailurePrinter(mpi.rank()));
  }
  return RUN_ALL_TESTS();
}
