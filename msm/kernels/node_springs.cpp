#include "msm/kernels/node_springs.hpp"

#include <immintrin.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "meshes/foundation/errors.hpp"
#include "msm/kernels/spring_kernels.hpp"
#include "msm/kernels/thread_parts.hpp"
#include "msm/kernels/fast_springs.hpp"

namespace vessel::msm {

namespace {

constexpr int L4 = NodeSprings::kLanes;
/// Nodes sorted by their number of springs within windows of this many consecutive nodes of the
/// Morton order (the σ of SELL-C-σ): enough to make chunks nearly uniform, small enough to keep
/// the curve's locality.
constexpr std::size_t kSortWindow = 32;

// ---- The portable path: the same layout and formulas, one lane at a time. ----

/// Hooke entries [4·q0, 4·q1) of one chunk: adds k(L − l)/L · (xi − xj) to the lanes' forces
/// and k(L − l)² to e4 (each spring is seen from both ends: ¼ of the sum is the energy).
template <bool kGradient, bool kEnergy>
void hooke_portable(const NodeSprings::Entries& h, std::int32_t q0, std::int32_t q1,
                    const double* __restrict x, const double (&xi)[3][L4], double (&f)[3][L4],
                    double (&e4)[L4]) {
  const std::int32_t* __restrict other = h.other.data();
  const double* __restrict K = h.k.data();
  const double* __restrict R = h.rest.data();
  for (std::int32_t q = q0; q < q1; ++q) {
    // Branch-free over the four lanes so that the compiler vectorises it (as in fast_springs.cpp).
#pragma omp simd
    for (int l = 0; l < L4; ++l) {
      const std::size_t s = static_cast<std::size_t>(q) * L4 + static_cast<std::size_t>(l);
      const std::int32_t j = other[s];
      const double ex = xi[0][l] - x[j], ey = xi[1][l] - x[j + 1], ez = xi[2][l] - x[j + 2];
      const double L = std::sqrt(ex * ex + ey * ey + ez * ez);
      const double kd = K[s] * (L - R[s]);
      if constexpr (kEnergy) e4[l] += kd * (L - R[s]);
      if constexpr (kGradient) {
        // ∇_xi ½k(L − l)² = k(L − l)/L · (xi − xj) (seed 000 eq. 3.2); zero for coincident ends
        // (and for the padding, whose other end is the node itself), as in spring_gradient, by a
        // 0/1 factor: L + (1 − m) is L when m = 1 and 1 when L = 0.
        const double m = static_cast<double>(L > 0.0);
        const double c = m * (kd / (L + (1.0 - m)));
        f[0][l] += c * ex;
        f[1][l] += c * ey;
        f[2][l] += c * ez;
      }
    }
  }
}

/// Bilinear entries (seed 001 eq. 1, as bilinear_profile): ψ' = k1δ below the threshold Δx_c,
/// k1Δx_c + k2(δ − Δx_c) at or beyond it; adds 2ψ to e4.
template <bool kGradient, bool kEnergy>
void bilinear_portable(const NodeSprings::Entries& b, std::int32_t q0, std::int32_t q1,
                       const double* __restrict x, const double (&xi)[3][L4],
                       double (&f)[3][L4], double (&e4)[L4]) {
  for (std::int32_t q = q0; q < q1; ++q) {
#pragma omp simd
    for (int l = 0; l < L4; ++l) {
      const std::size_t s = static_cast<std::size_t>(q) * L4 + static_cast<std::size_t>(l);
      const std::int32_t j = b.other[s];
      const double ex = xi[0][l] - x[j], ey = xi[1][l] - x[j + 1], ez = xi[2][l] - x[j + 2];
      const double L = std::sqrt(ex * ex + ey * ey + ez * ez);
      const double delta = L - b.rest[s];
      const double k1 = b.k[s], k2 = b.k2[s], dc = b.threshold[s];
      // 0/1 factors: exactly one term is nonzero, so each branch comes out as bilinear_profile
      // computes it.
      const double beyond = static_cast<double>(delta >= dc);
      const double below = 1.0 - beyond;
      const double over = delta - dc;
      if constexpr (kEnergy) {
        e4[l] += beyond * (k1 * dc * dc + 2.0 * k1 * dc * over + k2 * over * over) +
                 below * (k1 * delta * delta);
      }
      if constexpr (kGradient) {
        const double dpsi = beyond * (k1 * dc + k2 * over) + below * (k1 * delta);
        const double m = static_cast<double>(L > 0.0);
        const double c = m * (dpsi / (L + (1.0 - m)));
        f[0][l] += c * ex;
        f[1][l] += c * ey;
        f[2][l] += c * ez;
      }
    }
  }
}

template <bool kGradient, bool kEnergy>
double chunks_portable(const NodeSprings::Chunks& ch, const NodeSprings::Entries& h,
                       const NodeSprings::Entries& b, std::size_t c0, std::size_t c1,
                       const double* __restrict x, double* __restrict g) {
  double e4[L4] = {0.0, 0.0, 0.0, 0.0};
  for (std::size_t c = c0; c < c1; ++c) {
    double xi[3][L4], f[3][L4] = {};
    for (int l = 0; l < L4; ++l) {
      const double* p = x + ch.own[c * L4 + static_cast<std::size_t>(l)];
      for (int d = 0; d < 3; ++d) xi[d][l] = p[d];
    }
    hooke_portable<kGradient, kEnergy>(h, ch.hooke_begin[c], ch.hooke_begin[c + 1], x, xi, f, e4);
    bilinear_portable<kGradient, kEnergy>(b, ch.bil_begin[c], ch.bil_begin[c + 1], x, xi, f, e4);
    if constexpr (kGradient) {
      for (int l = 0; l < L4; ++l) {
        const std::int32_t o = ch.out[c * L4 + static_cast<std::size_t>(l)];
        if (o < 0) continue;
        for (int d = 0; d < 3; ++d) g[o + d] = f[d][l];
      }
    }
  }
  return (e4[0] + e4[1]) + (e4[2] + e4[3]);
}

// ---- The AVX2 + FMA path (compiled for that target only in these functions; called only when
// the processor has both). ----

#define VV_AVX2 __attribute__((target("avx2,fma")))

/// The other ends' positions of slot q's four lanes as x, y and z vectors. Two 16-byte loads and
/// one 8-byte load per end: never past the end of x (the last node has no fourth double).
VV_AVX2 inline void load_others(const double* __restrict x, const std::int32_t* id, __m256d& X,
                                __m256d& Y, __m256d& Z) {
  const __m256d a02 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(x + id[0])),
                                           _mm_loadu_pd(x + id[2]), 1);
  const __m256d a13 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(x + id[1])),
                                           _mm_loadu_pd(x + id[3]), 1);
  const __m128d z01 = _mm_loadh_pd(_mm_load_sd(x + id[0] + 2), x + id[1] + 2);
  const __m128d z23 = _mm_loadh_pd(_mm_load_sd(x + id[2] + 2), x + id[3] + 2);
  X = _mm256_unpacklo_pd(a02, a13);  // (x0, x1, x2, x3)
  Y = _mm256_unpackhi_pd(a02, a13);
  Z = _mm256_insertf128_pd(_mm256_castpd128_pd256(z01), z23, 1);
}

template <bool kGradient, bool kEnergy>
VV_AVX2 double chunks_avx2(const NodeSprings::Chunks& ch, const NodeSprings::Entries& h,
                           const NodeSprings::Entries& b, std::size_t c0, std::size_t c1,
                           const double* __restrict x, double* __restrict g) {
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
  __m256d esum = zero;
  const std::int32_t* hid = h.other.data();
  const double* hk = h.k.data();
  const double* hr = h.rest.data();
  const std::int32_t* bid = b.other.data();
  const double* bk = b.k.data();
  const double* bk2 = b.k2.data();
  const double* br = b.rest.data();
  const double* bdc = b.threshold.data();
  for (std::size_t c = c0; c < c1; ++c) {
    __m256d xi, yi, zi;
    load_others(x, ch.own.data() + c * L4, xi, yi, zi);
    __m256d fx = zero, fy = zero, fz = zero;
    for (std::int32_t q = ch.hooke_begin[c]; q < ch.hooke_begin[c + 1]; ++q) {
      const std::size_t s = static_cast<std::size_t>(q) * L4;
      __m256d X, Y, Z;
      load_others(x, hid + s, X, Y, Z);
      const __m256d ex = _mm256_sub_pd(xi, X), ey = _mm256_sub_pd(yi, Y), ez = _mm256_sub_pd(zi, Z);
      const __m256d L2 = _mm256_fmadd_pd(ez, ez, _mm256_fmadd_pd(ey, ey, _mm256_mul_pd(ex, ex)));
      const __m256d L = _mm256_sqrt_pd(L2);
      const __m256d delta = _mm256_sub_pd(L, _mm256_loadu_pd(hr + s));
      const __m256d kd = _mm256_mul_pd(_mm256_loadu_pd(hk + s), delta);
      if constexpr (kEnergy) esum = _mm256_fmadd_pd(kd, delta, esum);
      if constexpr (kGradient) {
        // k(L − l)/L where L > 0, else 0 (coincident ends, padding): divide by 1 there and mask.
        const __m256d pos = _mm256_cmp_pd(L, zero, _CMP_GT_OQ);
        const __m256d cc = _mm256_and_pd(pos, _mm256_div_pd(kd, _mm256_blendv_pd(one, L, pos)));
        fx = _mm256_fmadd_pd(cc, ex, fx);
        fy = _mm256_fmadd_pd(cc, ey, fy);
        fz = _mm256_fmadd_pd(cc, ez, fz);
      }
    }
    for (std::int32_t q = ch.bil_begin[c]; q < ch.bil_begin[c + 1]; ++q) {
      const std::size_t s = static_cast<std::size_t>(q) * L4;
      __m256d X, Y, Z;
      load_others(x, bid + s, X, Y, Z);
      const __m256d ex = _mm256_sub_pd(xi, X), ey = _mm256_sub_pd(yi, Y), ez = _mm256_sub_pd(zi, Z);
      const __m256d L2 = _mm256_fmadd_pd(ez, ez, _mm256_fmadd_pd(ey, ey, _mm256_mul_pd(ex, ex)));
      const __m256d L = _mm256_sqrt_pd(L2);
      const __m256d delta = _mm256_sub_pd(L, _mm256_loadu_pd(br + s));
      const __m256d k1 = _mm256_loadu_pd(bk + s), k2 = _mm256_loadu_pd(bk2 + s);
      const __m256d dc = _mm256_loadu_pd(bdc + s);
      const __m256d beyond = _mm256_cmp_pd(delta, dc, _CMP_GE_OQ);
      const __m256d over = _mm256_sub_pd(delta, dc);
      if constexpr (kEnergy) {
        // 2ψ: k1δ² below; k1Δx_c² + 2k1Δx_c(δ − Δx_c) + k2(δ − Δx_c)² beyond.
        const __m256d k1dc = _mm256_mul_pd(k1, dc);
        const __m256d above = _mm256_fmadd_pd(
            _mm256_mul_pd(k2, over), over,
            _mm256_fmadd_pd(_mm256_add_pd(k1dc, k1dc), over, _mm256_mul_pd(k1dc, dc)));
        const __m256d below = _mm256_mul_pd(_mm256_mul_pd(k1, delta), delta);
        esum = _mm256_add_pd(esum, _mm256_blendv_pd(below, above, beyond));
      }
      if constexpr (kGradient) {
        const __m256d dpsi = _mm256_blendv_pd(_mm256_mul_pd(k1, delta),
                                              _mm256_fmadd_pd(k2, over, _mm256_mul_pd(k1, dc)),
                                              beyond);
        const __m256d pos = _mm256_cmp_pd(L, zero, _CMP_GT_OQ);
        const __m256d cc =
            _mm256_and_pd(pos, _mm256_div_pd(dpsi, _mm256_blendv_pd(one, L, pos)));
        fx = _mm256_fmadd_pd(cc, ex, fx);
        fy = _mm256_fmadd_pd(cc, ey, fy);
        fz = _mm256_fmadd_pd(cc, ez, fz);
      }
    }
    if constexpr (kGradient) {
      alignas(32) double ox[L4], oy[L4], oz[L4];
      _mm256_store_pd(ox, fx);
      _mm256_store_pd(oy, fy);
      _mm256_store_pd(oz, fz);
      for (int l = 0; l < L4; ++l) {
        const std::int32_t o = ch.out[c * L4 + static_cast<std::size_t>(l)];
        if (o < 0) continue;
        g[o] = ox[l];
        g[o + 1] = oy[l];
        g[o + 2] = oz[l];
      }
    }
  }
  alignas(32) double e4[L4];
  _mm256_store_pd(e4, esum);
  return (e4[0] + e4[1]) + (e4[2] + e4[3]);
}

#undef VV_AVX2

}  // namespace

bool NodeSprings::cpu_has_avx2_fma() {
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return has;
}

NodeSprings::NodeSprings(const std::vector<Spring>& springs, int num_nodes, int threads,
                         const std::vector<Vec3>& rest_positions)
    : num_nodes_(num_nodes), threads_(threads), num_springs_(springs.size()) {
  if (threads < 1) {
    throw InputError("spring kernel threads: expected >= 1, got " + std::to_string(threads));
  }
  if (num_nodes < 0 || num_nodes > std::numeric_limits<std::int32_t>::max() / 3 - 1) {
    throw InputError("NodeSprings: " + std::to_string(num_nodes) +
                     " nodes, expected 0 to 2^31/3 (32-bit offsets 3·node)");
  }
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const Spring& sp = springs[s];
    if (sp.a < 0 || sp.b < 0 || sp.a >= num_nodes || sp.b >= num_nodes) {
      throw InputError("NodeSprings: spring " + std::to_string(s) + " joins nodes " +
                       std::to_string(sp.a) + " and " + std::to_string(sp.b) +
                       ", expected indices below " + std::to_string(num_nodes));
    }
  }
  std::vector<std::int32_t> order(static_cast<std::size_t>(num_nodes));
  for (int v = 0; v < num_nodes; ++v) order[static_cast<std::size_t>(v)] = v;
  if (!rest_positions.empty()) {
    if (static_cast<int>(rest_positions.size()) != num_nodes) {
      throw InputError("NodeSprings: " + std::to_string(rest_positions.size()) +
                       " rest positions, expected one per node (" + std::to_string(num_nodes) +
                       ")");
    }
    order = morton_order(rest_positions);
  }
  // Each node's springs, as (other end, spring), Hooke and bilinear apart. Hooke for a threshold
  // that is not finite (spring_profile's infinite one, and NaN, which bilinear_profile never
  // reaches); a spring from a node to itself is listed twice at it (both ends), like any other.
  std::vector<std::vector<std::pair<std::int32_t, std::size_t>>> hl(order.size()), bl(order.size());
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const Spring& sp = springs[s];
    const bool bilinear = std::isfinite(sp.law.threshold);
    num_bilinear_ += bilinear;
    auto& lists = bilinear ? bl : hl;
    lists[static_cast<std::size_t>(sp.a)].push_back({sp.b, s});
    lists[static_cast<std::size_t>(sp.b)].push_back({sp.a, s});
  }
  const auto degree = [&](std::int32_t v) {
    return hl[static_cast<std::size_t>(v)].size() + bl[static_cast<std::size_t>(v)].size();
  };
  for (std::size_t w = 0; w < order.size(); w += kSortWindow) {
    const auto end = order.begin() + static_cast<std::ptrdiff_t>(std::min(order.size(), w + kSortWindow));
    std::stable_sort(order.begin() + static_cast<std::ptrdiff_t>(w), end,
                     [&](std::int32_t a, std::int32_t b) { return degree(a) > degree(b); });
  }
  // Chunks of four consecutive nodes; slot q holds each lane's q-th spring, padded with
  // zero-stiffness springs from the node to itself.
  const std::size_t num_chunks = (order.size() + L4 - 1) / L4;
  chunks_.own.reserve(num_chunks * L4);
  chunks_.out.reserve(num_chunks * L4);
  hooke_.other.reserve(2 * springs.size());
  for (std::size_t c = 0; c < num_chunks; ++c) {
    std::int32_t node[L4];
    for (int l = 0; l < L4; ++l) {
      const std::size_t r = c * L4 + static_cast<std::size_t>(l);
      node[l] = r < order.size() ? order[r] : order[c * L4];
      chunks_.own.push_back(3 * node[l]);
      chunks_.out.push_back(r < order.size() ? 3 * node[l] : -1);
    }
    for (const bool bilinear : {false, true}) {
      auto& lists = bilinear ? bl : hl;
      Entries& set = bilinear ? bil_ : hooke_;
      std::size_t width = 0;
      for (int l = 0; l < L4; ++l) {
        const std::size_t r = c * L4 + static_cast<std::size_t>(l);
        if (r < order.size()) width = std::max(width, lists[static_cast<std::size_t>(node[l])].size());
      }
      for (std::size_t q = 0; q < width; ++q) {
        for (int l = 0; l < L4; ++l) {
          const std::size_t r = c * L4 + static_cast<std::size_t>(l);
          const auto& list = lists[static_cast<std::size_t>(node[l])];
          const bool real = r < order.size() && q < list.size();
          const Spring* sp = real ? &springs[list[q].second] : nullptr;
          set.other.push_back(3 * (real ? list[q].first : node[l]));
          set.rest.push_back(real ? sp->rest_length : 0.0);
          set.k.push_back(real ? sp->law.k1 : 0.0);
          if (bilinear) {
            set.k2.push_back(real ? sp->law.k2 : 0.0);
            set.threshold.push_back(real ? sp->law.threshold : 0.0);
          }
        }
      }
      auto& begin = bilinear ? chunks_.bil_begin : chunks_.hooke_begin;
      begin.push_back(static_cast<std::int32_t>(set.k.size() / L4));
    }
  }
  // Threads own consecutive runs of chunks, balanced by slots.
  thread_chunks_.assign(static_cast<std::size_t>(threads) + 1, num_chunks);
  thread_chunks_[0] = 0;
  const std::size_t total_slots = num_entries() / L4;
  std::size_t c = 0;
  for (int t = 1; t < threads; ++t) {
    const std::size_t target = total_slots * static_cast<std::size_t>(t) / static_cast<std::size_t>(threads);
    while (c < num_chunks && static_cast<std::size_t>(chunks_.hooke_begin[c] + chunks_.bil_begin[c]) < target) ++c;
    thread_chunks_[static_cast<std::size_t>(t)] = c;
  }
}

NodeSprings& NodeSprings::operator=(const NodeSprings& o) {
  if (this == &o) return *this;
  num_nodes_ = o.num_nodes_;
  threads_ = o.threads_;
  portable_ = o.portable_;
  num_springs_ = o.num_springs_;
  num_bilinear_ = o.num_bilinear_;
  chunks_ = o.chunks_;
  hooke_ = o.hooke_;
  bil_ = o.bil_;
  thread_chunks_ = o.thread_chunks_;
  last_team_.store(o.last_team_.load());
  return *this;
}

template <bool kGradient, bool kEnergy>
double NodeSprings::run_chunks(std::size_t begin, std::size_t end, const double* x,
                               double* g) const {
  if (uses_avx2()) return chunks_avx2<kGradient, kEnergy>(chunks_, hooke_, bil_, begin, end, x, g);
  return chunks_portable<kGradient, kEnergy>(chunks_, hooke_, bil_, begin, end, x, g);
}

template <bool kGradient, bool kEnergy>
double NodeSprings::run(const double* x, double* g) const {
  // Every spring is summed from both ends: ¼ Σ 2ψ over the entries is Σ ψ.
  if (threads_ == 1) return 0.25 * run_chunks<kGradient, kEnergy>(0, thread_chunks_[1], x, g);
  return 0.25 * sum_over_thread_parts(threads_, last_team_, [&](int t) {
    const auto u = static_cast<std::size_t>(t);
    return run_chunks<kGradient, kEnergy>(thread_chunks_[u], thread_chunks_[u + 1], x, g);
  });
}

double NodeSprings::energy(const double* x) const { return run<false, true>(x, nullptr); }

void NodeSprings::gradient(const double* x, double* g) const { (void)run<true, false>(x, g); }

double NodeSprings::energy_gradient(const double* x, double* g) const {
  return run<true, true>(x, g);
}

}  // namespace vessel::msm
