// The fast spring kernels against the per-spring reference kernel (msm/kernels/spring_kernels,
// itself checked against finite differences and hand-derived values in test_spring_kernels.cpp)
// on random perturbed states of each network kind, on one thread and several: the edge-based
// FastSprings (msm/kernels/fast_springs) and the node-centric NodeSprings
// (msm/kernels/node_springs, SpringModel's kernel) on its AVX2 path and its portable one; and
// their threads against the OpenMP limits that set_solver_threads sets for CHOLMOD.
#include <gtest/gtest.h>
#include <omp.h>

#include <random>
#include <type_traits>

#include "meshes/foundation/errors.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "msm/kernels/fast_springs.hpp"
#include "msm/kernels/node_springs.hpp"
#include "msm/kernels/spring_kernels.hpp"
#include "msm/model/build_network.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/linalg/linear_solver.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

struct Networks {
  SpringNetwork volume, grid, triangles, bilinear;
};

const Networks& networks() {
  static const Networks n = [] {
    Networks r;
    VesselParams unstructured;  // level 0 straight tube
    const TetMesh tets = generate_vessel_mesh(unstructured);
    VesselParams structured;
    structured.style = MeshStyle::structured;
    const TetMesh grid_mesh = generate_vessel_mesh(structured);
    NetworkOptions o;
    o.model = ModelType::volume;
    o.stiffness = StiffnessRule::seed001;
    r.volume = build_network(tets, unstructured, o).network;
    // seed 001's bilinear law: k2 = 3 k1 beyond 1 % elongation.
    o.stiffness_params.bilinear_ratio = 3.0;
    o.stiffness_params.bilinear_threshold_strain = 0.01;
    r.bilinear = build_network(tets, unstructured, o).network;
    NetworkOptions s;
    s.model = ModelType::surface;
    s.stiffness = StiffnessRule::seed000;
    s.topology = Topology::grid;
    r.grid = build_network(grid_mesh, structured, s).network;
    s.topology = Topology::triangles;
    s.two_ring = true;
    r.triangles = build_network(tets, unstructured, s).network;
    return r;
  }();
  return n;
}

/// Rest positions moved by normal noise of `relative` × the shortest spring, so that springs
/// stretch and compress by up to a few per cent.
Eigen::VectorXd perturbed(const SpringNetwork& net, std::mt19937& rng, double relative) {
  double shortest = std::numeric_limits<double>::infinity();
  for (const Spring& s : net.springs) shortest = std::min(shortest, s.rest_length);
  std::normal_distribution<double> n(0.0, relative * shortest);
  Eigen::VectorXd x = flatten(net.nodes);
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] += n(rng);
  return x;
}

double relative_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).lpNorm<Eigen::Infinity>() / b.lpNorm<Eigen::Infinity>();
}

/// SpringModel (on NodeSprings) against its own reference kernel, including the Hessian.
void expect_fast_equals_reference(const SpringNetwork& net, int threads, unsigned seed) {
  SpringModel model(net);
  model.set_threads(threads);
  ASSERT_EQ(model.threads(), threads);
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd x = perturbed(net, rng, 0.02);
    const double e_ref = model.reference_energy(x);
    Eigen::VectorXd g_ref, g, g2;
    model.reference_gradient(x, g_ref);
    const double e = model.energy(x);
    model.gradient(x, g);
    const double e2 = model.energy_gradient(x, g2);
    EXPECT_GT(e_ref, 0.0);
    EXPECT_LE(std::abs(e - e_ref), 1e-12 * e_ref) << threads << " threads";
    EXPECT_LE(relative_difference(g, g_ref), 1e-12) << threads << " threads";
    // One pass for both gives the same numbers as the separate passes, bit for bit.
    EXPECT_EQ(e2, e);
    EXPECT_EQ((g2 - g).lpNorm<Eigen::Infinity>(), 0.0);
    // The Hessian's 3×3-block assembly against the reference kernel's 6×6 blocks, same pattern.
    for (bool psd : {false, true}) {
      SparseMatrix H, H_ref;
      model.hessian(x, H, psd);
      model.reference_hessian(x, H_ref, psd);
      ASSERT_EQ(H.nonZeros(), H_ref.nonZeros());
      const Eigen::Map<const Eigen::VectorXd> h(H.valuePtr(), H.nonZeros());
      const Eigen::Map<const Eigen::VectorXd> h_ref(H_ref.valuePtr(), H_ref.nonZeros());
      EXPECT_LE((h - h_ref).lpNorm<Eigen::Infinity>(), 1e-12 * h_ref.lpNorm<Eigen::Infinity>());
      EXPECT_LE((SparseMatrix(H - H_ref)).norm(), 1e-12 * H_ref.norm());
    }
  }
}

/// A kernel object (FastSprings or NodeSprings) built directly on the network against the
/// reference kernel: energy, gradient and the fused pass, three random states.
template <class Kernel>
void expect_kernel_equals_reference(const SpringNetwork& net, int threads, unsigned seed,
                                    bool portable = false) {
  const SpringModel model(net);  // for the reference kernel only
  Kernel kernel(net.springs, static_cast<int>(net.nodes.size()), threads, net.nodes);
  if constexpr (std::is_same_v<Kernel, NodeSprings>) {
    kernel.set_portable(portable);
    EXPECT_EQ(kernel.uses_avx2(), !portable && NodeSprings::cpu_has_avx2_fma());
  }
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd x = perturbed(net, rng, 0.02);
    const double e_ref = model.reference_energy(x);
    Eigen::VectorXd g_ref, g(x.size()), g2(x.size());
    model.reference_gradient(x, g_ref);
    g.setConstant(1e300);  // every entry must be written
    const double e = kernel.energy(x.data());
    kernel.gradient(x.data(), g.data());
    const double e2 = kernel.energy_gradient(x.data(), g2.data());
    EXPECT_GT(e_ref, 0.0);
    EXPECT_LE(std::abs(e - e_ref), 1e-12 * e_ref) << threads << " threads, portable " << portable;
    EXPECT_LE(relative_difference(g, g_ref), 1e-12) << threads << " threads, portable " << portable;
    EXPECT_EQ(e2, e);
    EXPECT_EQ((g2 - g).lpNorm<Eigen::Infinity>(), 0.0);
  }
}

template <class Kernel>
void expect_every_kind_equals_reference() {
  const Networks& n = networks();
  unsigned seed = 20;
  for (const SpringNetwork* net : {&n.volume, &n.grid, &n.triangles, &n.bilinear}) {
    for (int t : {1, 2, 3}) {
      expect_kernel_equals_reference<Kernel>(*net, t, ++seed);
      if constexpr (std::is_same_v<Kernel, NodeSprings>) {
        expect_kernel_equals_reference<Kernel>(*net, t, seed, true);
      }
    }
  }
}

}  // namespace

TEST(FastSprings, EveryNetworkKindEqualsTheReferenceKernelOnOneAndSeveralThreads) {
  expect_every_kind_equals_reference<FastSprings>();
}

TEST(NodeSprings, EveryNetworkKindEqualsTheReferenceKernelOnBothPathsAndSeveralThreads) {
  expect_every_kind_equals_reference<NodeSprings>();
}

TEST(NodeSprings, TheBilinearStatesReachBothBranches) {
  // networks().bilinear at the states of expect_kernel_equals_reference: springs on both sides
  // of the threshold, else one branch of the bilinear entries goes untested.
  const SpringNetwork& net = networks().bilinear;
  std::mt19937 rng(30);
  const Eigen::VectorXd x = perturbed(net, rng, 0.02);
  std::size_t beyond = 0;
  for (const Spring& s : net.springs) {
    const double L = (x.segment<3>(3 * s.a) - x.segment<3>(3 * s.b)).norm();
    beyond += L - s.rest_length >= s.law.threshold;
  }
  EXPECT_GT(beyond, net.springs.size() / 20);
  EXPECT_LT(beyond, net.springs.size() - net.springs.size() / 20);
  const NodeSprings kernel(net.springs, static_cast<int>(net.nodes.size()), 1, net.nodes);
  EXPECT_EQ(kernel.num_bilinear(), net.springs.size());
}

TEST(NodeSprings, StoresEachSpringAtBothEndsWithLittlePadding) {
  const SpringNetwork& net = networks().volume;
  const NodeSprings kernel(net.springs, static_cast<int>(net.nodes.size()), 1, net.nodes);
  EXPECT_GE(kernel.num_entries(), 2 * net.springs.size());
  // Nodes sorted by degree within windows: padding under 15 % on a tetrahedral tube.
  EXPECT_LT(kernel.num_entries(), 2 * net.springs.size() * 115 / 100);
}

TEST(NodeSprings, HandDerivedSpringsCoincidentEndsAndALoopOnBothPaths) {
  // Two nodes, a spring of rest length l stretched to 2l along x, and a spring from node 1 to
  // itself (coincident ends: no force, energy ½k l² as spring_energy gives), on 5 threads (more
  // threads than chunks).
  Spring s;
  s.a = 0;
  s.b = 1;
  s.rest_length = 1e-3;
  s.law.k1 = 5.0;
  Spring loop = s;
  loop.a = loop.b = 1;
  loop.rest_length = 2e-3;
  for (bool portable : {false, true}) {
    NodeSprings kernel({s, loop}, 2, 5);
    kernel.set_portable(portable);
    const double l = 1e-3, k = 5.0;
    const double x[6] = {0, 0, 0, 2 * l, 0, 0};
    double g[6] = {1, 1, 1, 1, 1, 1};
    const double e = 0.5 * k * l * l + 0.5 * k * 4 * l * l;
    EXPECT_NEAR(kernel.energy_gradient(x, g), e, 1e-15 * e);
    EXPECT_NEAR(g[0], -k * l, 1e-15 * k * l);  // ∂E/∂xa = k (L − l)(xa − xb)/L, xa − xb = −2l
    EXPECT_NEAR(g[3], k * l, 1e-15 * k * l);
    for (int i : {1, 2, 4, 5}) EXPECT_EQ(g[i], 0.0);
  }
  // No springs: zero gradient over every node, zero energy.
  const NodeSprings none({}, 3, 2);
  const double x[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  double g[9] = {1, 1, 1, 1, 1, 1, 1, 1, 1};
  EXPECT_EQ(none.energy_gradient(x, g), 0.0);
  for (double gi : g) EXPECT_EQ(gi, 0.0);
}

TEST(NodeSprings, BadLayoutsAreRefusedWithAClearError) {
  Spring s;
  s.a = 0;
  s.b = 3;
  EXPECT_THROW(NodeSprings({s}, 2, 1), InputError);
  s.b = 1;
  EXPECT_THROW(NodeSprings({s}, 2, 0), InputError);
  EXPECT_THROW(NodeSprings({s}, 2, 1, {Vec3::Zero()}), InputError);
}

TEST(NodeSprings, SolverThreadLimitsDoNotCutTheKernelsTeamAndAreRestoredAfterIt) {
  const int saved = solver_threads();
  set_solver_threads(1);
  SparseMatrix A(2, 2);
  A.insert(0, 0) = 2.0;
  A.insert(1, 1) = 3.0;
  CholmodSolver solver;
  solver.factorize(A);
  ASSERT_EQ(omp_get_max_active_levels(), 0);
  const SpringNetwork& net = networks().volume;
  const NodeSprings kernel(net.springs, static_cast<int>(net.nodes.size()), 2, net.nodes);
  const Eigen::VectorXd x = flatten(net.nodes);
  Eigen::VectorXd g(x.size());
  kernel.gradient(x.data(), g.data());
  EXPECT_EQ(kernel.last_team_size(), 2);
  EXPECT_EQ(omp_get_max_active_levels(), 0);
  set_solver_threads(saved);
}

TEST(SpringModelKernel, VolumeNetworkEqualsTheReferenceKernelOnOneAndSeveralThreads) {
  for (int t : {1, 2, 3}) expect_fast_equals_reference(networks().volume, t, 11);
}

TEST(SpringModelKernel, SurfaceGridEqualsTheReferenceKernelOnOneAndSeveralThreads) {
  for (int t : {1, 2, 3}) expect_fast_equals_reference(networks().grid, t, 12);
}

TEST(SpringModelKernel, SurfaceTrianglesEqualTheReferenceKernelOnOneAndSeveralThreads) {
  for (int t : {1, 2, 3}) expect_fast_equals_reference(networks().triangles, t, 13);
}

TEST(SpringModelKernel, BilinearSpringsEqualTheReferenceKernelOnBothBranches) {
  const SpringNetwork& net = networks().bilinear;
  // The states must put springs on both sides of the threshold, or one branch goes untested.
  std::mt19937 rng(14);
  const Eigen::VectorXd x = perturbed(net, rng, 0.02);
  std::size_t beyond = 0;
  for (const Spring& s : net.springs) {
    ASSERT_TRUE(std::isfinite(s.law.threshold));
    const double L = (x.segment<3>(3 * s.a) - x.segment<3>(3 * s.b)).norm();
    beyond += L - s.rest_length >= s.law.threshold;
  }
  EXPECT_GT(beyond, net.springs.size() / 20);
  EXPECT_LT(beyond, net.springs.size() - net.springs.size() / 20);
  for (int t : {1, 2, 3}) expect_fast_equals_reference(net, t, 14);
}

TEST(FastSprings, ThreadsSplitTheNodesAndEvaluateOnlyCrossingSpringsTwice) {
  const SpringNetwork& net = networks().volume;
  const int n = static_cast<int>(net.nodes.size());
  const FastSprings one(net.springs, n, 1);
  EXPECT_EQ(one.num_split_springs(), 0u);
  const FastSprings two(net.springs, n, 2);
  EXPECT_GT(two.num_split_springs(), 0u);
  EXPECT_LT(two.num_split_springs(), net.springs.size());
  // Regions along a Morton curve of the rest positions: on a tube, a cut across it, which far
  // fewer springs cross than the split of the index range (gmsh's numbering is not local).
  const FastSprings spatial(net.springs, n, 2, net.nodes);
  EXPECT_GT(spatial.num_split_springs(), 0u);
  EXPECT_LT(spatial.num_split_springs(), two.num_split_springs());
  EXPECT_THROW(FastSprings(net.springs, n, 2, {Vec3::Zero()}), InputError);
  // More threads than nodes: empty ranges, still the whole answer.
  std::vector<Spring> pair{net.springs.front()};
  pair.front().a = 0;
  pair.front().b = 1;
  const FastSprings many(pair, 2, 5);
  const double x[6] = {0, 0, 0, 2 * pair.front().rest_length, 0, 0};
  double g[6];
  const double k = pair.front().law.k1, l = pair.front().rest_length;
  EXPECT_NEAR(many.energy_gradient(x, g), 0.5 * k * l * l, 1e-15 * k * l * l);
  EXPECT_NEAR(g[0], -k * l, 1e-15 * k * l);  // ∂E/∂xa = k (L − l) (xa − xb)/L, xa − xb = −2l
  EXPECT_NEAR(g[3], k * l, 1e-15 * k * l);
}

TEST(FastSprings, CoincidentEndsGiveZeroForceAndTheRestEnergyAsTheReferenceDoes) {
  Spring s;
  s.a = 0;
  s.b = 1;
  s.rest_length = 1e-3;
  s.law.k1 = 5.0;
  const FastSprings fast({s}, 2, 1);
  const double x[6] = {1e-3, 2e-3, 3e-3, 1e-3, 2e-3, 3e-3};
  double g[6] = {1, 1, 1, 1, 1, 1};
  EXPECT_DOUBLE_EQ(fast.energy_gradient(x, g), 0.5 * 5.0 * 1e-6);
  for (double gi : g) EXPECT_EQ(gi, 0.0);
}

TEST(FastSprings, BadLayoutsAreRefusedWithAClearError) {
  Spring s;
  s.a = 0;
  s.b = 3;
  EXPECT_THROW(FastSprings({s}, 2, 1), InputError);
  s.b = 1;
  EXPECT_THROW(FastSprings({s}, 2, 0), InputError);
  EXPECT_THROW(set_spring_kernel_threads(0), InputError);
}

TEST(FastSprings, SolverThreadLimitsDoNotCutTheKernelsTeamAndAreRestoredAfterIt) {
  // set_solver_threads(1) leaves max-active-levels at 0 on this thread at every CHOLMOD call, so
  // that CHOLMOD's parallel regions run serially; the kernel's own region must still get its
  // threads, and CHOLMOD's setting must be back afterwards.
  const int saved = solver_threads();
  set_solver_threads(1);
  SparseMatrix A(2, 2);
  A.insert(0, 0) = 2.0;
  A.insert(1, 1) = 3.0;
  CholmodSolver solver;
  solver.factorize(A);
  ASSERT_EQ(omp_get_max_active_levels(), 0);
  const SpringNetwork& net = networks().volume;
  const FastSprings fast(net.springs, static_cast<int>(net.nodes.size()), 2);
  const Eigen::VectorXd x = flatten(net.nodes);
  Eigen::VectorXd g(x.size());
  fast.gradient(x.data(), g.data());
  EXPECT_EQ(fast.last_team_size(), 2);
  EXPECT_EQ(omp_get_max_active_levels(), 0);
  set_solver_threads(saved);
}
