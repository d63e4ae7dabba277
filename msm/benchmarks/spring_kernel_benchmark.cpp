// The spring force pass against the memory-bandwidth roofline (issue 13, items 3 and 4), in one
// run: a STREAM-like triad (the roofline, on one thread and on all cores), the per-spring
// reference kernel (SpringModel::reference_gradient), the edge-based fast kernel
// (FastSprings::gradient, "Fast") and the node-centric kernel SpringModel runs on
// (NodeSprings::gradient, "Node": its AVX2 path, and "NodePortable": its portable path) on one
// thread and on all cores, on the level-1 and level-2 volume
// networks (tet edges of the generated straight tube, seed 001 stiffness) and the level-2
// surface grid (structured straight tube, seed 000). Release build; not run by ctest:
//
//   build/msm/spring_kernel_benchmark --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true --benchmark_out=kernel.json
// (one line)
//
// Counters (per second of wall-clock time):
//   springs_per_s     springs whose force is computed per second;
//   roofline          springs_per_s × 120 B / triad bandwidth on as many threads, where 120 B is
//                     the per-spring traffic without reuse: two 4-byte node indices, rest length
//                     and k (8 B each), the two end positions read (2 × 24 B) and the two end
//                     forces written (2 × 24 B);
//   roofline_compulsory  the same with the compulsory traffic only: 24 B of spring data streamed
//                     per spring plus each node's position read and force written once
//                     (48 B × nodes / springs), a lower bound that caching can at best reach;
//   roofline_layout   (Node only) the same with the bytes its layout streams: 20 B per stored
//                     entry (4-byte other end, 8-byte k and rest length; every spring at both
//                     ends, plus padding) plus 48 B × nodes (own position read, force written
//                     once), per spring.
// The triad a[i] = b[i] + s·c[i] counts 24 B per element (two reads, one write; STREAM's
// convention, no write-allocate), on arrays of 128 MiB each, far beyond the caches.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "meshes/mesh_cache.hpp"
#include "msm/kernels/fast_springs.hpp"
#include "msm/kernels/node_springs.hpp"
#include "msm/model/build_network.hpp"
#include "msm/terms/spring_model.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

constexpr double kBytesPerSpring = 2 * 4 + 8 + 8 + 2 * 24 + 2 * 24;  // = 120
constexpr std::size_t kTriadElements = std::size_t{1} << 24;         // 128 MiB per array

/// Triad bandwidth (bytes/s) measured on each thread count, filled by BM_Triad, which runs first.
std::map<int, double> g_triad_bandwidth;

struct Case {
  std::string name;
  SpringNetwork net;
  std::unique_ptr<SpringModel> model;
  Eigen::VectorXd x;  ///< a perturbed state (forces nonzero)
  double compulsory_bytes_per_spring = 0.0;
};

Case make_case(const std::string& name, ModelType model, MeshStyle style, int level,
               StiffnessRule stiffness) {
  VesselParams params;  // the straight tube of the default scene
  params.style = style;
  params.level = level;
  const TetMesh mesh = load_or_generate_vessel(params, default_cache_dir(), {});
  NetworkOptions o;
  o.model = model;
  o.stiffness = stiffness;
  if (model == ModelType::surface) o.topology = Topology::grid;
  Case c;
  c.name = name;
  c.net = build_network(mesh, params, o).network;
  c.model = std::make_unique<SpringModel>(c.net);
  c.x = flatten(c.net.nodes);
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0.0, 1e-6);  // 1 µm against mm-long springs
  for (Eigen::Index i = 0; i < c.x.size(); ++i) c.x[i] += n(rng);
  c.compulsory_bytes_per_spring = 24.0 + 48.0 * static_cast<double>(c.net.nodes.size()) /
                                             static_cast<double>(c.net.springs.size());
  return c;
}

void BM_Triad(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  std::vector<double> a(kTriadElements), b(kTriadElements, 1.0), c(kTriadElements, 2.0);
  const double s = 3.0;
  const auto n = static_cast<std::ptrdiff_t>(kTriadElements);
  // First touch by the same threads and schedule as the timed loop.
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::ptrdiff_t i = 0; i < n; ++i) a[i] = 0.0;
  for (auto _ : state) {
#pragma omp parallel for num_threads(threads) schedule(static)
    for (std::ptrdiff_t i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
    benchmark::DoNotOptimize(a.data());
    benchmark::ClobberMemory();
  }
  const double bytes = 24.0 * static_cast<double>(kTriadElements);
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(bytes));
  state.counters["triad_bytes_per_s"] = benchmark::Counter(
      bytes * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

/// Sets the springs/s and roofline counters of a force-pass benchmark on `threads` threads.
void set_counters(benchmark::State& state, const Case& c, int threads) {
  const double springs =
      static_cast<double>(c.net.springs.size()) * static_cast<double>(state.iterations());
  state.counters["springs"] = static_cast<double>(c.net.springs.size());
  state.counters["springs_per_s"] = benchmark::Counter(springs, benchmark::Counter::kIsRate);
  const auto bw = g_triad_bandwidth.find(threads);
  if (bw != g_triad_bandwidth.end() && bw->second > 0) {
    // A rate counter of springs × bytes / bandwidth is the fraction of the roofline.
    state.counters["roofline"] =
        benchmark::Counter(springs * kBytesPerSpring / bw->second, benchmark::Counter::kIsRate);
    state.counters["roofline_compulsory"] = benchmark::Counter(
        springs * c.compulsory_bytes_per_spring / bw->second, benchmark::Counter::kIsRate);
  }
}

void BM_Reference(benchmark::State& state, const Case* c) {
  Eigen::VectorXd g;
  for (auto _ : state) {
    c->model->reference_gradient(c->x, g);
    benchmark::DoNotOptimize(g.data());
    benchmark::ClobberMemory();
  }
  set_counters(state, *c, 1);
}

/// The node-centric kernel; `portable` takes its portable path even where AVX2 runs.
void BM_Node(benchmark::State& state, const Case* c, bool portable) {
  const int threads = static_cast<int>(state.range(0));
  NodeSprings node(c->net.springs, static_cast<int>(c->net.nodes.size()), threads, c->net.nodes);
  node.set_portable(portable);
  Eigen::VectorXd g(c->x.size());
  for (auto _ : state) {
    node.gradient(c->x.data(), g.data());
    benchmark::DoNotOptimize(g.data());
    benchmark::ClobberMemory();
  }
  set_counters(state, *c, threads);
  state.counters["avx2"] = node.uses_avx2() ? 1.0 : 0.0;
  const double springs = static_cast<double>(c->net.springs.size());
  const double layout_bytes = (20.0 * static_cast<double>(node.num_entries()) +
                               48.0 * static_cast<double>(c->net.nodes.size())) /
                              springs;
  state.counters["layout_bytes_per_spring"] = layout_bytes;
  const auto bw = g_triad_bandwidth.find(threads);
  if (bw != g_triad_bandwidth.end() && bw->second > 0) {
    state.counters["roofline_layout"] =
        benchmark::Counter(springs * static_cast<double>(state.iterations()) * layout_bytes /
                               bw->second,
                           benchmark::Counter::kIsRate);
  }
}

void BM_Fast(benchmark::State& state, const Case* c) {
  const int threads = static_cast<int>(state.range(0));
  const FastSprings fast(c->net.springs, static_cast<int>(c->net.nodes.size()), threads,
                         c->net.nodes);
  Eigen::VectorXd g(c->x.size());
  for (auto _ : state) {
    fast.gradient(c->x.data(), g.data());
    benchmark::DoNotOptimize(g.data());
    benchmark::ClobberMemory();
  }
  set_counters(state, *c, threads);
  state.counters["split_springs"] = static_cast<double>(fast.num_split_springs());
}

/// Triad results are read back from the reporter, so that the later benchmarks' roofline
/// counters use the bandwidth measured in this run (the median when repeated).
class TriadCapture : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.run_name.function_name != "BM_Triad") continue;
      const auto it = r.counters.find("triad_bytes_per_s");
      if (it == r.counters.end()) continue;
      const bool median = r.run_type == Run::RT_Aggregate && r.aggregate_name == "median";
      const bool single = r.run_type == Run::RT_Iteration;
      const int threads = std::stoi(r.run_name.args);
      // A single run's value until the median of the repetitions arrives.
      if (median || (single && !medians_.count(threads))) {
        g_triad_bandwidth[threads] = it->second.value;
        if (median) medians_.insert({threads, true});
      }
    }
    ConsoleReporter::ReportRuns(runs);
  }

 private:
  std::map<int, bool> medians_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  const int cores = available_cores();
  std::vector<Case> cases;
  cases.push_back(make_case("volume_L1", ModelType::volume, MeshStyle::unstructured, 1,
                            StiffnessRule::seed001));
  cases.push_back(make_case("volume_L2", ModelType::volume, MeshStyle::unstructured, 2,
                            StiffnessRule::seed001));
  cases.push_back(make_case("surface_grid_L2", ModelType::surface, MeshStyle::structured, 2,
                            StiffnessRule::seed000));
  benchmark::AddCustomContext("bytes_per_spring_roofline",
                              "120 (2x4 B indices + 8 B rest length + 8 B k + 2x24 B positions "
                              "read + 2x24 B forces written)");
  benchmark::AddCustomContext("bytes_per_spring_compulsory",
                              "24 + 48 x nodes/springs (spring data once, each node's position "
                              "read and force written once)");
  benchmark::AddCustomContext("bytes_per_spring_node_layout",
                              "(20 x stored entries + 48 x nodes) / springs (NodeSprings: other "
                              "end 4 B + k 8 B + rest 8 B per entry, each spring at both ends, "
                              "own position read and force written once per node)");
  benchmark::AddCustomContext("node_avx2", NodeSprings::cpu_has_avx2_fma() ? "yes" : "no");
  benchmark::AddCustomContext("triad", "a = b + s*c, 3 x 128 MiB, 24 B per element");
  benchmark::AddCustomContext("cores", std::to_string(cores));
  for (const Case& c : cases) {
    const std::string info = c.name + ": " + std::to_string(c.net.nodes.size()) + " nodes, " +
                             std::to_string(c.net.springs.size()) + " springs";
    benchmark::AddCustomContext("network_" + c.name, info);
  }

  auto* triad = benchmark::RegisterBenchmark("BM_Triad", BM_Triad)
                    ->UseRealTime()
                    ->Unit(benchmark::kMillisecond)
                    ->Arg(1);
  if (cores > 1) triad->Arg(cores);
  for (const Case& c : cases) {
    benchmark::RegisterBenchmark(("BM_Reference/" + c.name).c_str(), BM_Reference, &c)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    auto* fast = benchmark::RegisterBenchmark(("BM_Fast/" + c.name).c_str(), BM_Fast, &c)
                     ->UseRealTime()
                     ->Unit(benchmark::kMicrosecond)
                     ->ArgName("threads")
                     ->Arg(1);
    if (cores > 1) fast->Arg(cores);
    auto* node = benchmark::RegisterBenchmark(("BM_Node/" + c.name).c_str(), BM_Node, &c, false)
                     ->UseRealTime()
                     ->Unit(benchmark::kMicrosecond)
                     ->ArgName("threads")
                     ->Arg(1);
    if (cores > 1) node->Arg(cores);
    benchmark::RegisterBenchmark(("BM_NodePortable/" + c.name).c_str(), BM_Node, &c, true)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond)
        ->ArgName("threads")
        ->Arg(1);
  }
  TriadCapture display;
  benchmark::RunSpecifiedBenchmarks(&display);
  benchmark::Shutdown();
  return 0;
}
