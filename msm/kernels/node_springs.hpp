#pragma once
/// The node-centric (gather) spring force pass: the same energies and gradients as the per-spring
/// reference kernel (spring_kernels.hpp: Hooke ψ = ½k(L − l)², seed 000 eq. 3.2; the bilinear
/// spring of seed 001 eq. 1) and as FastSprings (fast_springs.hpp), laid out per node instead of
/// per spring:
/// - every node lists its springs (the other end's offset 3·node into x, k, rest length; the
///   bilinear springs' k2 and threshold in a list of their own), and each spring is evaluated
///   from both of its ends: twice the arithmetic, but the node's force is summed in registers
///   and written once, with no scatter, no read-modify-write of g and no write conflicts;
/// - nodes are taken four at a time (one per SIMD lane, sliced ELLPACK "SELL-4" as in sparse
///   matrix–vector products): slot q of a chunk holds the q-th spring of each of its four nodes,
///   so one slot is one 4-wide vector of springs; a node with fewer springs than the longest of
///   its chunk is padded with zero-stiffness springs to itself (zero force, zero energy);
/// - nodes in the order of a Morton curve through the rest positions (morton_order), then sorted
///   by their number of springs within windows of 32, so that a chunk's four nodes have nearly
///   equal lists (little padding) and neighbouring chunks touch nearby positions (cache reuse);
/// - positions are read from the caller's flat x = (x0, y0, z0, x1, ...) and the gradient
///   written into its flat g: no internal copy of the state and no permutation pass;
/// - an AVX2+FMA path (4 doubles per vector) chosen at run time when the processor has both
///   (__builtin_cpu_supports), else a portable path over the same layout (what the compiler's
///   default target vectorises); the binary runs on any x86-64;
/// - threads over the cores: each thread owns a run of chunks (balanced by slots), computes its
///   nodes' forces and writes them; no colouring, no atomics, no buffers, no reduction of g.
/// Bytes streamed per spring (docs/measurements/spring_kernel_notes.md): 2 × (4 + 8 + 8) = 40 B of spring
/// data (each spring stored at both ends) plus padding, each node's position read once as the
/// chunk's own and its force written once (48 B × nodes / springs); the other ends' positions are
/// re-read from cache.
/// Measured by msm/benchmarks/spring_kernel_benchmark.cpp against FastSprings, the reference
/// kernel and the memory-bandwidth roofline.
#include <atomic>
#include <cstdint>
#include <vector>

#include "msm/kernels/fast_springs.hpp"  // morton_order, the kernel thread setting
#include "msm/topology/springs.hpp"

namespace vessel::msm {

class NodeSprings {
 public:
  NodeSprings() = default;
  /// Lays out `springs` (Hooke when law.threshold is not finite, bilinear otherwise) on
  /// `num_nodes` nodes for `threads` threads. With the nodes' rest positions (m), nodes are taken
  /// along a Morton curve; without, in index order. InputError if threads < 1, a spring's node
  /// is out of range or the positions are not one per node.
  NodeSprings(const std::vector<Spring>& springs, int num_nodes, int threads = 1,
              const std::vector<Vec3>& rest_positions = {});

  /// Σ ψ over the springs at x (3·num_nodes values), J.
  [[nodiscard]] double energy(const double* x) const;
  /// g = ∂E/∂x (3·num_nodes values, overwritten), N.
  void gradient(const double* x, double* g) const;
  /// Both in one pass; returns the energy (the same value energy(x) returns, bit for bit).
  double energy_gradient(const double* x, double* g) const;

  /// True when this processor has AVX2 and FMA (the fast path can run).
  [[nodiscard]] static bool cpu_has_avx2_fma();
  /// Takes the portable path even where AVX2 runs (tests and the benchmark compare both).
  void set_portable(bool portable) { portable_ = portable; }
  /// Whether calls take the AVX2+FMA path.
  [[nodiscard]] bool uses_avx2() const { return !portable_ && cpu_has_avx2_fma(); }

  [[nodiscard]] int threads() const { return threads_; }
  [[nodiscard]] int num_nodes() const { return num_nodes_; }
  [[nodiscard]] std::size_t num_springs() const { return num_springs_; }
  [[nodiscard]] std::size_t num_bilinear() const { return num_bilinear_; }
  /// Spring entries stored, padding included (4 per slot); 2 × num_springs() without padding.
  [[nodiscard]] std::size_t num_entries() const { return hooke_.k.size() + bil_.k.size(); }
  /// Threads that ran the last call's parallel region (1 when threads() is 1).
  [[nodiscard]] int last_team_size() const { return last_team_.load(std::memory_order_relaxed); }

  static constexpr int kLanes = 4;  ///< nodes per chunk (doubles per AVX2 vector)

  /// Per chunk slot and lane (index 4·slot + lane): the other end's offset 3·node into x, its
  /// rest length and k; the bilinear list adds k2 and the threshold Δx_c.
  struct Entries {
    std::vector<std::int32_t> other;
    std::vector<double> rest, k, k2, threshold;
  };
  /// The chunks: per chunk and lane, the node's offset 3·node (own[]; an empty last-chunk lane
  /// repeats lane 0's node and has out[] = −1, so its force is not written), and its slot ranges
  /// [hooke_begin[c], hooke_begin[c+1]) and [bil_begin[c], bil_begin[c+1]).
  struct Chunks {
    std::vector<std::int32_t> own, out;
    std::vector<std::int32_t> hooke_begin{0}, bil_begin{0};
  };

 private:
  template <bool kGradient, bool kEnergy>
  double run(const double* x, double* g) const;
  template <bool kGradient, bool kEnergy>
  double run_chunks(std::size_t begin, std::size_t end, const double* x, double* g) const;

  int num_nodes_ = 0;
  int threads_ = 1;
  bool portable_ = false;
  std::size_t num_springs_ = 0;
  std::size_t num_bilinear_ = 0;
  Chunks chunks_;
  Entries hooke_, bil_;
  std::vector<std::size_t> thread_chunks_ = std::vector<std::size_t>(2, 0);  ///< T + 1 bounds
  mutable std::atomic<int> last_team_{1};

 public:
  NodeSprings(const NodeSprings& o) { *this = o; }
  NodeSprings& operator=(const NodeSprings& o);
};

}  // namespace vessel::msm
