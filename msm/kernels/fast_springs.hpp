#pragma once
/// The fast spring force pass: the same energies and gradients as the per-spring reference kernel
/// (spring_kernels.hpp: Hooke ψ = ½k(L − l)², seed 000 eq. 3.2; the bilinear spring of seed 001
/// eq. 1), laid out for the memory system rather than for one spring at a time:
/// - structure of arrays: the ends' offsets 3·node into x and g (4 bytes each), rest length and k
///   in separate arrays (24 bytes per Hooke spring streamed, against the 56-byte Spring record);
///   the bilinear springs' k2 and threshold in a set of their own, so the Hooke pass has no
///   per-spring branch on the law;
/// - positions read from the flat x = (x0, y0, z0, x1, ...) and the gradient written into a flat
///   g of the same layout;
/// - per block of springs, a branch-free loop (coincident ends by a 0/1 factor) that GCC
///   auto-vectorises (see msm/CMakeLists.txt), then a scalar scatter of the block's forces;
/// - threads over the cores without write conflicts by owner-computes: the nodes are split into
///   one compact region per thread (consecutive runs of a Morton curve through the rest
///   positions, balanced by springs); a thread zeroes and accumulates only its own nodes of g; a
///   spring with both ends in one region is that thread's, and a spring whose ends lie in two
///   regions is evaluated by both threads, each adding only its own end's force (and half the
///   energy). No atomics, no per-thread buffers, no reduction of g.
/// Measured against the memory-bandwidth roofline by msm/benchmarks/spring_kernel_benchmark.cpp
/// (docs/measurements/spring_kernel_notes.md).
/// The thread count is fixed when the layout is built (it decides the split); it is this object's
/// own setting, independent of set_solver_threads (the OpenMP limits set there for CHOLMOD are
/// overridden for the kernel's own parallel region and restored after it).
#include <atomic>
#include <cstdint>
#include <vector>

#include "msm/topology/springs.hpp"

namespace vessel::msm {

/// Threads of the spring force pass of models built from now on (SpringModel); default 1, like
/// set_solver_threads: timings stay per core, and on a machine shared with other work a
/// fork–join pass waits for descheduled threads (docs/measurements/spring_kernel_notes.md, "Under
/// contention"). InputError if n < 1.
void set_spring_kernel_threads(int n);
[[nodiscard]] int spring_kernel_threads();
/// Processor cores this process may run on (its CPU affinity mask; else
/// std::thread::hardware_concurrency; at least 1).
[[nodiscard]] int available_cores();

/// The nodes in the order of a Morton (Z-order) curve through their positions (m): 21 bits per
/// coordinate over the bounding cube, ties kept in index order. Nearby nodes come close in the
/// order, so runs of it are compact regions and consecutive nodes share cached neighbours.
[[nodiscard]] std::vector<std::int32_t> morton_order(const std::vector<Vec3>& positions);

class FastSprings {
 public:
  FastSprings() = default;
  /// Lays out `springs` (Hooke when law.threshold is infinite, bilinear otherwise) on
  /// `num_nodes` nodes for `threads` threads. With the nodes' rest positions (m), threads own
  /// compact regions and springs are ordered along a Morton curve; without, index ranges and the
  /// given order. InputError if threads < 1, a spring's node is out of range or the positions
  /// are not one per node.
  FastSprings(const std::vector<Spring>& springs, int num_nodes, int threads = 1,
              const std::vector<Vec3>& rest_positions = {});

  /// Σ ψ over the springs at x (3·num_nodes values), J.
  [[nodiscard]] double energy(const double* x) const;
  /// g = ∂E/∂x (3·num_nodes values, overwritten), N.
  void gradient(const double* x, double* g) const;
  /// Both in one pass over the springs; returns the energy (the same value energy(x) returns).
  double energy_gradient(const double* x, double* g) const;

  [[nodiscard]] int threads() const { return threads_; }
  [[nodiscard]] int num_nodes() const { return num_nodes_; }
  [[nodiscard]] std::size_t num_springs() const { return num_springs_; }
  [[nodiscard]] std::size_t num_bilinear() const { return num_bilinear_; }
  /// Threads that ran the last call's parallel region (1 when threads() is 1): the check that
  /// the OpenMP limits set for CHOLMOD did not cut the kernel's team.
  [[nodiscard]] int last_team_size() const { return last_team_.load(std::memory_order_relaxed); }
  /// Springs evaluated twice because their ends lie in two threads' node ranges.
  [[nodiscard]] std::size_t num_split_springs() const { return num_split_; }

  /// Hooke springs: ψ = ½k(L − l)². i, j: offsets 3·node of the ends into x and g (no index
  /// arithmetic in the vectorised loop); `i` is the end whose gradient a half spring writes.
  struct HookeSet {
    std::vector<std::int32_t> i, j;
    std::vector<double> rest, k;
  };
  /// Bilinear springs (seed 001 eq. 1): k up to the threshold elongation, k2 beyond it.
  struct BilinearSet {
    std::vector<std::int32_t> i, j;
    std::vector<double> rest, k, k2, threshold;
  };

 private:
  /// What thread t owns: its node range and its slice of each set.
  enum Range { kHookeFull, kHookeHalf, kBilinearFull, kBilinearHalf };
  struct Part {
    std::size_t nodes[2]{};     ///< [begin, end) into owned_nodes_: the nodes it zeroes
    std::size_t range[4][2]{};  ///< [Range][begin, end) into the set of that kind
  };
  template <bool kGradient, bool kEnergy>
  double run(const double* x, double* g) const;
  template <bool kGradient, bool kEnergy>
  double run_part(const Part& part, const double* x, double* g) const;

  int num_nodes_ = 0;
  int threads_ = 1;
  std::size_t num_springs_ = 0;
  std::size_t num_bilinear_ = 0;
  std::size_t num_split_ = 0;
  // Springs with both ends in one thread's range ("full") and the halves of split springs, each
  // set ordered thread by thread (Part gives the slices).
  HookeSet hooke_full_, hooke_half_;
  BilinearSet bil_full_, bil_half_;
  std::vector<Part> parts_ = std::vector<Part>(1);  // one per thread
  std::vector<std::int32_t> owned_nodes_;           // each thread's nodes, thread by thread
  mutable std::atomic<int> last_team_{1};

 public:
  FastSprings(const FastSprings& o) { *this = o; }
  FastSprings& operator=(const FastSprings& o);
};

}  // namespace vessel::msm
