#include "msm/kernels/fast_springs.hpp"

#include <omp.h>
#include <sched.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <thread>
#include <utility>

#include "meshes/foundation/errors.hpp"
#include "msm/kernels/spring_kernels.hpp"
#include "msm/kernels/thread_parts.hpp"

namespace vessel::msm {

namespace {
std::atomic<int> g_kernel_threads{1};

/// Springs per block: the block's forces (3 × 8 bytes each) stay in L1 between the vectorised
/// pass that computes them and the scalar pass that scatters them.
constexpr std::size_t kBlock = 256;

/// Hooke springs [begin, end) of a set. kFull: the spring writes both ends (g_i += c e,
/// g_j −= c e); otherwise it is the half of a split spring and writes only i. Returns Σ k δ²
/// (the energy without the ½).
template <bool kFull, bool kGradient, bool kEnergy>
double hooke_range(const FastSprings::HookeSet& set, std::size_t begin, std::size_t end,
                   const double* __restrict x, double* __restrict g) {
  alignas(64) double cx[kBlock], cy[kBlock], cz[kBlock], en[kBlock];
  double e = 0.0;
  for (std::size_t b0 = begin; b0 < end; b0 += kBlock) {
    const std::size_t m = std::min(kBlock, end - b0);
    const std::int32_t* __restrict I = set.i.data() + b0;
    const std::int32_t* __restrict J = set.j.data() + b0;
    const double* __restrict rest = set.rest.data() + b0;
    const double* __restrict k = set.k.data() + b0;
    // Branch-free so that GCC vectorises it: coincident ends (L = 0, direction undefined) get a
    // zero force as in spring_gradient, by a 0/1 factor m rather than a branch or a select (GCC 12
    // does not if-convert `L > 0 ? … : 0` here under the default -ftrapping-math).
#pragma omp simd
    for (std::size_t q = 0; q < m; ++q) {
      const std::int32_t a = I[q];
      const std::int32_t b = J[q];
      const double ex = x[a] - x[b];
      const double ey = x[a + 1] - x[b + 1];
      const double ez = x[a + 2] - x[b + 2];
      const double L = std::sqrt(ex * ex + ey * ey + ez * ez);
      const double delta = L - rest[q];
      if constexpr (kGradient) {
        // ∇_xa ½k(L − l)² = k(L − l)/L · (xa − xb) (seed 000 eq. 3.2).
        // (L + (1 − m)) is L exactly when m = 1; with m = 0 the force is 0 (no division by 0).
        const double m0 = static_cast<double>(L > 0.0);
        const double c = m0 * (k[q] * delta / (L + (1.0 - m0)));
        cx[q] = c * ex;
        cy[q] = c * ey;
        cz[q] = c * ez;
      }
      if constexpr (kEnergy) en[q] = k[q] * delta * delta;
    }
    // Summed in spring order, not in the vector lanes' order: energy() and energy_gradient()
    // then return the same value bit for bit, whatever the vectoriser chose for each.
    if constexpr (kEnergy) {
      for (std::size_t q = 0; q < m; ++q) e += en[q];
    }
    if constexpr (kGradient) {
      for (std::size_t q = 0; q < m; ++q) {
        const std::int32_t a = I[q];
        g[a] += cx[q];
        g[a + 1] += cy[q];
        g[a + 2] += cz[q];
        if constexpr (kFull) {
          const std::int32_t b = J[q];
          g[b] -= cx[q];
          g[b + 1] -= cy[q];
          g[b + 2] -= cz[q];
        }
      }
    }
  }
  return e;
}

/// The bilinear spring of seed 001 eq. (1) over [begin, end), as hooke_range; with δ = L − l and
/// Δx_c the threshold: ψ' = kδ below it, kΔx_c + k2(δ − Δx_c) at or beyond it (compression always
/// k, as in bilinear_profile). Returns Σ 2ψ.
template <bool kFull, bool kGradient, bool kEnergy>
double bilinear_range(const FastSprings::BilinearSet& set, std::size_t begin, std::size_t end,
                      const double* __restrict x, double* __restrict g) {
  alignas(64) double cx[kBlock], cy[kBlock], cz[kBlock], en[kBlock];
  double e = 0.0;
  for (std::size_t b0 = begin; b0 < end; b0 += kBlock) {
    const std::size_t m = std::min(kBlock, end - b0);
    const std::int32_t* __restrict I = set.i.data() + b0;
    const std::int32_t* __restrict J = set.j.data() + b0;
    const double* __restrict rest = set.rest.data() + b0;
    const double* __restrict k1 = set.k.data() + b0;
    const double* __restrict k2 = set.k2.data() + b0;
    const double* __restrict dc = set.threshold.data() + b0;
#pragma omp simd
    for (std::size_t q = 0; q < m; ++q) {
      const std::int32_t a = I[q];
      const std::int32_t b = J[q];
      const double ex = x[a] - x[b];
      const double ey = x[a + 1] - x[b + 1];
      const double ez = x[a + 2] - x[b + 2];
      const double L = std::sqrt(ex * ex + ey * ey + ez * ez);
      const double delta = L - rest[q];
      // 0/1 factors instead of selects (see hooke_range): exactly one of the two terms is
      // nonzero, so each branch's value comes out as bilinear_profile computes it.
      const double beyond = static_cast<double>(delta >= dc[q]);
      const double below = 1.0 - beyond;
      const double over = delta - dc[q];
      if constexpr (kGradient) {
        const double dpsi = beyond * (k1[q] * dc[q] + k2[q] * over) + below * (k1[q] * delta);
        const double m0 = static_cast<double>(L > 0.0);
        const double c = m0 * (dpsi / (L + (1.0 - m0)));
        cx[q] = c * ex;
        cy[q] = c * ey;
        cz[q] = c * ez;
      }
      if constexpr (kEnergy) {
        // 2ψ: k1δ² below; k1Δx_c² + 2k1Δx_c(δ − Δx_c) + k2(δ − Δx_c)² beyond.
        en[q] =
            beyond * (k1[q] * dc[q] * dc[q] + 2.0 * k1[q] * dc[q] * over + k2[q] * over * over) +
            below * (k1[q] * delta * delta);
      }
    }
    // Summed in spring order, not in the vector lanes' order: energy() and energy_gradient()
    // then return the same value bit for bit, whatever the vectoriser chose for each.
    if constexpr (kEnergy) {
      for (std::size_t q = 0; q < m; ++q) e += en[q];
    }
    if constexpr (kGradient) {
      for (std::size_t q = 0; q < m; ++q) {
        const std::int32_t a = I[q];
        g[a] += cx[q];
        g[a + 1] += cy[q];
        g[a + 2] += cz[q];
        if constexpr (kFull) {
          const std::int32_t b = J[q];
          g[b] -= cx[q];
          g[b + 1] -= cy[q];
          g[b + 2] -= cz[q];
        }
      }
    }
  }
  return e;
}

template <class Set>
void reserve_set(Set& s, std::size_t n) {
  s.i.reserve(n);
  s.j.reserve(n);
  s.rest.reserve(n);
  s.k.reserve(n);
}

}  // namespace

void set_spring_kernel_threads(int n) {
  if (n < 1) throw InputError("spring kernel threads: expected >= 1, got " + std::to_string(n));
  g_kernel_threads.store(n);
}

int spring_kernel_threads() { return g_kernel_threads.load(); }

int available_cores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

std::vector<std::int32_t> morton_order(const std::vector<Vec3>& positions) {
  const int num_nodes = static_cast<int>(positions.size());
  std::vector<std::int32_t> order(positions.size());
  for (int v = 0; v < num_nodes; ++v) order[static_cast<std::size_t>(v)] = v;
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double extent = std::max((hi - lo).maxCoeff(), 1e-300);
  std::vector<std::uint64_t> code(positions.size());
  for (int v = 0; v < num_nodes; ++v) {
    std::uint64_t c = 0;
    std::uint64_t q[3];
    for (int d = 0; d < 3; ++d) {
      const double u = (positions[static_cast<std::size_t>(v)][d] - lo[d]) / extent;
      q[d] = static_cast<std::uint64_t>(std::clamp(u, 0.0, 1.0) * 2097151.0);  // 21 bits
    }
    for (int bit = 20; bit >= 0; --bit) {
      for (int d = 0; d < 3; ++d) c = (c << 1) | ((q[d] >> bit) & 1u);
    }
    code[static_cast<std::size_t>(v)] = c;
  }
  std::stable_sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) {
    return code[static_cast<std::size_t>(a)] < code[static_cast<std::size_t>(b)];
  });
  return order;
}

namespace {

/// InputError unless threads ≥ 1, the nodes fit 32-bit offsets 3·node and every spring joins
/// two of them.
void check_layout_input(const std::vector<Spring>& springs, int num_nodes, int threads) {
  if (threads < 1) {
    throw InputError("spring kernel threads: expected >= 1, got " + std::to_string(threads));
  }
  if (num_nodes < 0 || num_nodes > std::numeric_limits<std::int32_t>::max() / 3) {
    throw InputError("FastSprings: " + std::to_string(num_nodes) +
                     " nodes, expected 0 to 2^31/3 (32-bit offsets 3·node)");
  }
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const Spring& sp = springs[s];
    if (sp.a < 0 || sp.b < 0 || sp.a >= num_nodes || sp.b >= num_nodes) {
      throw InputError("FastSprings: spring " + std::to_string(s) + " joins nodes " +
                       std::to_string(sp.a) + " and " + std::to_string(sp.b) +
                       ", expected indices below " + std::to_string(num_nodes));
    }
  }
}

/// The order nodes are walked in: along a Morton (Z-order) curve of the rest positions when they
/// are given, so that each thread's nodes form a compact region (few springs cross between
/// threads) and consecutive springs touch nearby nodes (their positions and forces stay in
/// cache); else the index order.
std::vector<std::int32_t> walk_order(int num_nodes, const std::vector<Vec3>& rest_positions) {
  std::vector<std::int32_t> order(static_cast<std::size_t>(num_nodes));
  for (int v = 0; v < num_nodes; ++v) order[static_cast<std::size_t>(v)] = v;
  if (!rest_positions.empty()) {
    if (static_cast<int>(rest_positions.size()) != num_nodes) {
      throw InputError("FastSprings: " + std::to_string(rest_positions.size()) +
                       " rest positions, expected one per node (" + std::to_string(num_nodes) +
                       ")");
    }
    order = morton_order(rest_positions);
  }
  return order;
}

/// The thread owning each node: threads own consecutive runs of the walk order, balanced by the
/// springs whose first end in the order lies in them.
std::vector<int> balance_owners(const std::vector<Spring>& springs,
                                const std::vector<std::int32_t>& order,
                                const std::vector<std::int32_t>& rank, int T) {
  const int num_nodes = static_cast<int>(order.size());
  std::vector<std::size_t> per_rank(static_cast<std::size_t>(num_nodes), 0);
  for (const Spring& sp : springs) {
    ++per_rank[static_cast<std::size_t>(
        std::min(rank[static_cast<std::size_t>(sp.a)], rank[static_cast<std::size_t>(sp.b)]))];
  }
  std::vector<int> owner(static_cast<std::size_t>(num_nodes), T - 1);
  std::size_t seen = 0;
  int t = 0;
  for (int r = 0; r < num_nodes; ++r) {
    while (t + 1 < T && seen >= (springs.size() * static_cast<std::size_t>(t + 1)) / T) ++t;
    owner[static_cast<std::size_t>(order[r])] = t;
    seen += per_rank[static_cast<std::size_t>(r)];
  }
  return owner;
}

/// A spring (or half of a split one) as a thread lists it: the end it writes first.
struct Item {
  std::int32_t i, j;
  std::size_t s;
};
using ThreadItems = std::vector<std::vector<Item>>;  // one list per thread

/// Per thread: Hooke and bilinear springs with both ends in its nodes ("full") and the halves of
/// springs split between two threads (each thread writes its own end).
struct ThreadLists {
  ThreadItems hooke_full, hooke_half, bilinear_full, bilinear_half;
  std::size_t bilinear = 0, split = 0;
};

ThreadLists split_by_owner(const std::vector<Spring>& springs, const std::vector<int>& owner,
                           int T) {
  ThreadLists out;
  out.hooke_full.resize(T);
  out.hooke_half.resize(T);
  out.bilinear_full.resize(T);
  out.bilinear_half.resize(T);
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const Spring& sp = springs[s];
    // Hooke for an infinite threshold (as spring_profile decides) and for a NaN one (which
    // bilinear_profile treats as never reached); the bilinear set's thresholds are finite.
    const bool bilinear = std::isfinite(sp.law.threshold);
    const int oa = owner[static_cast<std::size_t>(sp.a)];
    const int ob = owner[static_cast<std::size_t>(sp.b)];
    out.bilinear += bilinear;
    if (oa == ob) {
      (bilinear ? out.bilinear_full : out.hooke_full)[oa].push_back({sp.a, sp.b, s});
    } else {
      ++out.split;
      (bilinear ? out.bilinear_half : out.hooke_half)[oa].push_back({sp.a, sp.b, s});
      (bilinear ? out.bilinear_half : out.hooke_half)[ob].push_back({sp.b, sp.a, s});
    }
  }
  return out;
}

/// Springs in the order of their first end along the node order (then the second end).
void sort_by_rank(ThreadLists& lists, const std::vector<std::int32_t>& rank) {
  auto by_rank = [&](const Item& x, const Item& y) {
    const auto key = [&](const Item& it) {
      const std::int32_t ri = rank[static_cast<std::size_t>(it.i)];
      const std::int32_t rj = rank[static_cast<std::size_t>(it.j)];
      return std::make_pair(std::min(ri, rj), std::max(ri, rj));
    };
    return key(x) < key(y);
  };
  for (ThreadItems* items : {&lists.hooke_full, &lists.hooke_half, &lists.bilinear_full,
                             &lists.bilinear_half}) {
    for (auto& l : *items) std::stable_sort(l.begin(), l.end(), by_rank);
  }
}

/// Sorted, consecutive springs share their first end: the scatter's read-modify-write of that
/// node's force would chain from one spring to the next through memory (store-to-load
/// forwarding, several cycles a link). Each chunk of kBlock springs is read column-wise as a
/// kStride × (kBlock/kStride) table, so neighbours in the loop are kBlock/kStride springs apart
/// in the sorted order: other nodes, still within the chunk's small region.
void interleave_chunks(ThreadLists& lists) {
  constexpr std::size_t kStride = 8;
  for (ThreadItems* items : {&lists.hooke_full, &lists.hooke_half, &lists.bilinear_full,
                             &lists.bilinear_half}) {
    for (auto& l : *items) {
      std::vector<Item> chunk;
      for (std::size_t c0 = 0; c0 + kBlock <= l.size(); c0 += kBlock) {
        chunk.assign(l.begin() + static_cast<std::ptrdiff_t>(c0),
                     l.begin() + static_cast<std::ptrdiff_t>(c0 + kBlock));
        for (std::size_t p = 0; p < kBlock; ++p) {
          l[c0 + p] = chunk[(p % kStride) * (kBlock / kStride) + p / kStride];
        }
      }
    }
  }
}

/// Each thread's [begin, end) in a set filled thread by thread.
using ThreadRanges = std::vector<std::array<std::size_t, 2>>;

/// Appends the Hooke springs of `lists` to `set`, thread by thread.
ThreadRanges fill_hooke(const ThreadItems& lists, const std::vector<Spring>& springs,
                        FastSprings::HookeSet& set) {
  std::size_t total = 0;
  for (const auto& l : lists) total += l.size();
  reserve_set(set, total);
  ThreadRanges ranges(lists.size());
  for (std::size_t t = 0; t < lists.size(); ++t) {
    ranges[t][0] = set.i.size();
    for (const Item& it : lists[t]) {
      set.i.push_back(3 * it.i);
      set.j.push_back(3 * it.j);
      set.rest.push_back(springs[it.s].rest_length);
      set.k.push_back(springs[it.s].law.k1);
    }
    ranges[t][1] = set.i.size();
  }
  return ranges;
}

/// Appends the bilinear springs of `lists` to `set`, thread by thread.
ThreadRanges fill_bilinear(const ThreadItems& lists, const std::vector<Spring>& springs,
                           FastSprings::BilinearSet& set) {
  std::size_t total = 0;
  for (const auto& l : lists) total += l.size();
  reserve_set(set, total);
  set.k2.reserve(total);
  set.threshold.reserve(total);
  ThreadRanges ranges(lists.size());
  for (std::size_t t = 0; t < lists.size(); ++t) {
    ranges[t][0] = set.i.size();
    for (const Item& it : lists[t]) {
      set.i.push_back(3 * it.i);
      set.j.push_back(3 * it.j);
      set.rest.push_back(springs[it.s].rest_length);
      set.k.push_back(springs[it.s].law.k1);
      set.k2.push_back(springs[it.s].law.k2);
      set.threshold.push_back(springs[it.s].law.threshold);
    }
    ranges[t][1] = set.i.size();
  }
  return ranges;
}

}  // namespace

FastSprings::FastSprings(const std::vector<Spring>& springs, int num_nodes, int threads,
                         const std::vector<Vec3>& rest_positions)
    : num_nodes_(num_nodes), threads_(threads), num_springs_(springs.size()) {
  check_layout_input(springs, num_nodes, threads);
  const int T = threads;
  parts_.resize(static_cast<std::size_t>(T));
  const std::vector<std::int32_t> order = walk_order(num_nodes, rest_positions);
  std::vector<std::int32_t> rank(static_cast<std::size_t>(num_nodes));
  for (int r = 0; r < num_nodes; ++r) rank[static_cast<std::size_t>(order[r])] = r;
  const std::vector<int> owner = balance_owners(springs, order, rank, T);
  // Each thread's nodes in index order (it zeroes their gradient entries).
  std::vector<std::vector<std::int32_t>> owned(static_cast<std::size_t>(T));
  for (int v = 0; v < num_nodes; ++v) owned[owner[static_cast<std::size_t>(v)]].push_back(v);
  owned_nodes_.clear();
  owned_nodes_.reserve(static_cast<std::size_t>(num_nodes));
  for (int u = 0; u < T; ++u) {
    parts_[u].nodes[0] = owned_nodes_.size();
    owned_nodes_.insert(owned_nodes_.end(), owned[u].begin(), owned[u].end());
    parts_[u].nodes[1] = owned_nodes_.size();
  }
  ThreadLists lists = split_by_owner(springs, owner, T);
  num_bilinear_ += lists.bilinear;
  num_split_ += lists.split;
  if (!rest_positions.empty()) sort_by_rank(lists, rank);
  interleave_chunks(lists);
  auto assign = [&](Range range, const ThreadRanges& ranges) {
    for (int t = 0; t < T; ++t) {
      parts_[t].range[range][0] = ranges[t][0];
      parts_[t].range[range][1] = ranges[t][1];
    }
  };
  assign(kHookeFull, fill_hooke(lists.hooke_full, springs, hooke_full_));
  assign(kHookeHalf, fill_hooke(lists.hooke_half, springs, hooke_half_));
  assign(kBilinearFull, fill_bilinear(lists.bilinear_full, springs, bil_full_));
  assign(kBilinearHalf, fill_bilinear(lists.bilinear_half, springs, bil_half_));
}

FastSprings& FastSprings::operator=(const FastSprings& o) {
  if (this == &o) return *this;
  num_nodes_ = o.num_nodes_;
  threads_ = o.threads_;
  num_springs_ = o.num_springs_;
  num_bilinear_ = o.num_bilinear_;
  num_split_ = o.num_split_;
  hooke_full_ = o.hooke_full_;
  hooke_half_ = o.hooke_half_;
  bil_full_ = o.bil_full_;
  bil_half_ = o.bil_half_;
  parts_ = o.parts_;
  owned_nodes_ = o.owned_nodes_;
  last_team_.store(o.last_team_.load());
  return *this;
}

template <bool kGradient, bool kEnergy>
double FastSprings::run_part(const Part& p, const double* x, double* g) const {
  if constexpr (kGradient) {
    for (std::size_t u = p.nodes[0]; u < p.nodes[1]; ++u) {
      double* gv = g + 3 * static_cast<std::ptrdiff_t>(owned_nodes_[u]);
      gv[0] = gv[1] = gv[2] = 0.0;
    }
  }
  auto r = [&](Range which, int end) { return p.range[which][end]; };
  // Σ 2ψ of whole springs, and of split springs (each counted by both of its threads).
  const double full =
      hooke_range<true, kGradient, kEnergy>(hooke_full_, r(kHookeFull, 0), r(kHookeFull, 1), x, g) +
      bilinear_range<true, kGradient, kEnergy>(bil_full_, r(kBilinearFull, 0), r(kBilinearFull, 1),
                                               x, g);
  const double half = hooke_range<false, kGradient, kEnergy>(hooke_half_, r(kHookeHalf, 0),
                                                             r(kHookeHalf, 1), x, g) +
                      bilinear_range<false, kGradient, kEnergy>(bil_half_, r(kBilinearHalf, 0),
                                                                r(kBilinearHalf, 1), x, g);
  return 0.5 * full + 0.25 * half;
}

template <bool kGradient, bool kEnergy>
double FastSprings::run(const double* x, double* g) const {
  if (threads_ == 1) return run_part<kGradient, kEnergy>(parts_[0], x, g);
  return sum_over_thread_parts(threads_, last_team_, [&](int t) {
    return run_part<kGradient, kEnergy>(parts_[static_cast<std::size_t>(t)], x, g);
  });
}

double FastSprings::energy(const double* x) const { return run<false, true>(x, nullptr); }

void FastSprings::gradient(const double* x, double* g) const { (void)run<true, false>(x, g); }

double FastSprings::energy_gradient(const double* x, double* g) const {
  return run<true, true>(x, g);
}

}  // namespace vessel::msm
