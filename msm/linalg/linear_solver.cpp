#include "msm/linalg/linear_solver.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <queue>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "meshes/foundation/errors.hpp"

namespace vessel::msm {

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::atomic<double> g_parallel_solve_min_entries{4e6};

/// The BLAS that CHOLMOD loaded (OpenBLAS here), looked up at run time as solver_threads.cpp
/// does, so that the parallel sweeps use the same dense kernels as CHOLMOD's own solve (Eigen's,
/// compiled for SSE2 only, were 30 % slower per sweep at level 2); null members: Eigen's kernels.
struct Blas {
  using Gemv = void (*)(const char*, const int*, const int*, const double*, const double*,
                        const int*, const double*, const int*, const double*, double*, const int*);
  using Trsv = void (*)(const char*, const char*, const char*, const int*, const double*,
                        const int*, double*, const int*);
  Gemv dgemv = nullptr;
  Trsv dtrsv = nullptr;
  void (*set_threads)(int) = nullptr;  ///< openblas_set_num_threads
};

const Blas& blas() {
  static const Blas b = [] {
    Blas r;
    r.dgemv = reinterpret_cast<Blas::Gemv>(dlsym(RTLD_DEFAULT, "dgemv_"));
    r.dtrsv = reinterpret_cast<Blas::Trsv>(dlsym(RTLD_DEFAULT, "dtrsv_"));
    r.set_threads = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    if (r.dgemv == nullptr || r.dtrsv == nullptr) r.dgemv = nullptr, r.dtrsv = nullptr;
    return r;
  }();
  return b;
}

}  // namespace

namespace detail {

/// Forward and backward sweeps with CHOLMOD's supernodal LLᵀ factor on several threads.
///
/// Supernode k holds columns super[k] … super[k+1]−1 of L as a dense column-major block of
/// nsrow × nscol numbers (rows s[pi[k]] …, the first nscol of them its own columns). Its parent
/// in the supernodal elimination tree holds its first row below the diagonal block. The plan
/// splits the tree into disjoint subtrees, shared among the threads by weight (numbers read), and
/// a top (every supernode above them) done by one thread. Forward sweep L y = Pb: the threads
/// run their subtrees (children before parents), writing the updates of rows inside the subtree
/// into y and those of the top's rows into their own accumulator; the accumulators are summed
/// into y and one thread finishes the top. Backward sweep Lᵀz = y: the top first on one thread,
/// then each thread its subtrees, parents before children, reading only rows of its own subtree
/// and of the top. x = Pᵀz. The same operations as CHOLMOD's supernodal solve
/// (cholmod_super_lsolve/ltsolve) in another order of the updates of the top's rows.
class SupernodalTreeSolve {
 public:
  SupernodalTreeSolve(const cholmod_factor& L, int threads) : threads_(threads) {
    n_ = static_cast<int>(L.n);
    ns_ = static_cast<int>(L.nsuper);
    const int* super = static_cast<const int*>(L.super);
    const int* pi = static_cast<const int*>(L.pi);
    const int* s = static_cast<const int*>(L.s);
    std::vector<int> supernode_of(static_cast<std::size_t>(n_));
    for (int k = 0; k < ns_; ++k) {
      for (int c = super[k]; c < super[k + 1]; ++c) supernode_of[c] = k;
    }
    std::vector<int> parent(ns_, -1);
    std::vector<double> w(ns_), subtree(ns_);
    first_.resize(ns_);
    std::vector<int> size(ns_, 1);
    for (int k = 0; k < ns_; ++k) {
      const int nscol = super[k + 1] - super[k];
      const int nsrow = pi[k + 1] - pi[k];
      if (nsrow > nscol) parent[k] = supernode_of[s[pi[k] + nscol]];
      w[k] = static_cast<double>(nscol) * (nsrow - nscol) + 0.5 * nscol * (nscol + 1.0);
      first_[k] = k;
    }
    subtree = w;
    for (int k = 0; k < ns_; ++k) {
      const int q = parent[k];
      if (q < 0) continue;
      if (q <= k) throw std::logic_error("CHOLMOD supernodes not in topological order");
      subtree[q] += subtree[k];
      size[q] += size[k];
      first_[q] = std::min(first_[q], first_[k]);
    }
    // Postordered (cholmod_analyze's default): the subtree of k is the supernodes first_[k] … k.
    for (int k = 0; k < ns_; ++k) {
      if (k - first_[k] + 1 != size[k]) throw std::logic_error("CHOLMOD supernodes not postordered");
    }
    std::vector<std::vector<int>> children(ns_);
    for (int k = 0; k < ns_; ++k) {
      if (parent[k] >= 0) children[parent[k]].push_back(k);
    }
    // Move the heaviest subtree's root to the top, its children becoming subtrees, while that
    // lowers the estimated sweep: top (one thread) + max(heaviest subtree, subtrees / threads).
    auto lighter = [&](int a, int b) { return subtree[a] < subtree[b]; };
    std::priority_queue<int, std::vector<int>, decltype(lighter)> heap(lighter);
    double in_subtrees = 0.0, in_top = 0.0;
    for (int k = 0; k < ns_; ++k) {
      if (parent[k] < 0) heap.push(k), in_subtrees += subtree[k];
    }
    std::vector<int> popped;
    double best = 1e300;
    std::size_t best_count = 0;
    while (!heap.empty()) {
      const double estimate = in_top + std::max(subtree[heap.top()], in_subtrees / threads);
      if (estimate < best) best = estimate, best_count = popped.size();
      if (in_top >= best) break;
      const int h = heap.top();
      heap.pop();
      popped.push_back(h);
      in_top += w[h];
      in_subtrees -= subtree[h];
      for (int c : children[h]) heap.push(c), in_subtrees += subtree[c];
    }
    std::vector<char> is_top(ns_, 0);
    for (std::size_t i = 0; i < best_count; ++i) is_top[popped[i]] = 1;
    std::vector<int> roots;  // of the subtrees: not top, parent top or none
    for (int k = 0; k < ns_; ++k) {
      if (is_top[k]) top_.push_back(k);
      else if (parent[k] < 0 || is_top[parent[k]]) roots.push_back(k);
    }
    // Longest processing time first: heaviest subtree to the lightest thread.
    std::sort(roots.begin(), roots.end(), [&](int a, int b) { return subtree[a] > subtree[b]; });
    parts_.assign(threads_, {});
    std::vector<double> load(threads_, 0.0);
    for (int r : roots) {
      const auto t = std::min_element(load.begin(), load.end()) - load.begin();
      load[t] += subtree[r];
      parts_[t].push_back(r);
    }
    for (auto& part : parts_) std::sort(part.begin(), part.end());
    for (int k : top_) {
      for (int c = super[k]; c < super[k + 1]; ++c) top_columns_.push_back(c);
    }
    accumulators_.assign(threads_, std::vector<double>(static_cast<std::size_t>(n_), 0.0));
    std::size_t rows = 0;
    for (int k = 0; k < ns_; ++k) rows = std::max<std::size_t>(rows, pi[k + 1] - pi[k]);
    work_.assign(threads_, std::vector<double>(rows));
    y_.resize(n_);
  }

  [[nodiscard]] int threads() const { return threads_; }

  void solve(const cholmod_factor& L, const double* b, double* x) const {
    const int* perm = static_cast<const int*>(L.Perm);
    double* y = y_.data();
    for (int i = 0; i < n_; ++i) y[i] = b[perm[i]];
    // The dense kernels run on the calling thread: OpenBLAS's own threads, if allowed, would
    // compete with this solve's (two callers each starting OpenBLAS threads on 2 cores).
    const Blas& k = blas();
    if (k.set_threads) k.set_threads(1);
    on_threads([&](int t) {
      double* acc = accumulators_[t].data();
      for (int r : parts_[t]) {
        const int end = static_cast<const int*>(L.super)[r + 1];  // first column above the subtree
        for (int q = first_[r]; q <= r; ++q) forward(L, q, y, acc, end, work_[t].data());
      }
    });
    for (int c : top_columns_) {
      double sum = 0.0;
      for (int t = 0; t < threads_; ++t) sum += std::exchange(accumulators_[t][c], 0.0);
      y[c] -= sum;
    }
    for (int q : top_) forward(L, q, y, nullptr, n_, work_[0].data());
    for (auto q = top_.rbegin(); q != top_.rend(); ++q) backward(L, *q, y, work_[0].data());
    on_threads([&](int t) {
      for (auto r = parts_[t].rbegin(); r != parts_[t].rend(); ++r) {
        for (int q = *r; q >= first_[*r]; --q) backward(L, q, y, work_[t].data());
      }
    });
    if (k.set_threads) k.set_threads(solver_threads());  // back to apply_solver_threads' setting
    for (int i = 0; i < n_; ++i) x[perm[i]] = y[i];
  }

 private:
  template <class F>
  void on_threads(const F& f) const {
    std::vector<std::thread> extra;
    for (int t = 1; t < threads_; ++t) extra.emplace_back(f, t);
    f(0);
    for (std::thread& th : extra) th.join();
  }

  using Block = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;

  /// Supernode q of L y = b: its columns' entries of y solved with the diagonal block, then
  /// y[row] −= (off-diagonal block · those entries) for the rows below: into y for rows < end,
  /// into acc for the rest (rows of the top, shared between threads).
  static void forward(const cholmod_factor& L, int q, double* y, double* acc, int end, double* t) {
    const int* super = static_cast<const int*>(L.super);
    const int* pi = static_cast<const int*>(L.pi);
    const int k1 = super[q], nscol = super[q + 1] - k1, nsrow = pi[q + 1] - pi[q];
    const int m = nsrow - nscol;
    const double* Lq = static_cast<const double*>(L.x) + static_cast<const int*>(L.px)[q];
    const int* rows = static_cast<const int*>(L.s) + pi[q] + nscol;
    const Blas& k = blas();
    const int one = 1;
    if (k.dtrsv) {
      k.dtrsv("L", "N", "N", &nscol, Lq, &nsrow, y + k1, &one);
    } else {
      Block(Lq, nscol, nscol, Eigen::OuterStride<>(nsrow))
          .triangularView<Eigen::Lower>()
          .solveInPlace(Eigen::Map<VectorXd>(y + k1, nscol));
    }
    if (m == 0) return;
    if (k.dgemv) {
      const double alpha = 1.0, beta = 0.0;
      k.dgemv("N", &m, &nscol, &alpha, Lq + nscol, &nsrow, y + k1, &one, &beta, t, &one);
    } else {
      Eigen::Map<VectorXd>(t, m).noalias() =
          Block(Lq + nscol, m, nscol, Eigen::OuterStride<>(nsrow)) *
          Eigen::Map<const VectorXd>(y + k1, nscol);
    }
    int i = 0;
    for (; i < m && rows[i] < end; ++i) y[rows[i]] -= t[i];  // rows are increasing
    for (; i < m; ++i) acc[rows[i]] += t[i];
  }

  /// Supernode q of Lᵀ z = y: its columns' entries −= (off-diagonal block)ᵀ · z[rows below],
  /// then solved with the transposed diagonal block.
  static void backward(const cholmod_factor& L, int q, double* z, double* g) {
    const int* super = static_cast<const int*>(L.super);
    const int* pi = static_cast<const int*>(L.pi);
    const int k1 = super[q], nscol = super[q + 1] - k1, nsrow = pi[q + 1] - pi[q];
    const int m = nsrow - nscol;
    const double* Lq = static_cast<const double*>(L.x) + static_cast<const int*>(L.px)[q];
    const int* rows = static_cast<const int*>(L.s) + pi[q] + nscol;
    const Blas& k = blas();
    const int one = 1;
    if (m > 0) {
      for (int i = 0; i < m; ++i) g[i] = z[rows[i]];
      if (k.dgemv) {
        const double alpha = -1.0, beta = 1.0;
        k.dgemv("T", &m, &nscol, &alpha, Lq + nscol, &nsrow, g, &one, &beta, z + k1, &one);
      } else {
        Eigen::Map<VectorXd>(z + k1, nscol).noalias() -=
            Block(Lq + nscol, m, nscol, Eigen::OuterStride<>(nsrow)).transpose() *
            Eigen::Map<const VectorXd>(g, m);
      }
    }
    if (k.dtrsv) {
      k.dtrsv("L", "T", "N", &nscol, Lq, &nsrow, z + k1, &one);
    } else {
      Block(Lq, nscol, nscol, Eigen::OuterStride<>(nsrow))
          .transpose()
          .triangularView<Eigen::Upper>()
          .solveInPlace(Eigen::Map<VectorXd>(z + k1, nscol));
    }
  }

  int threads_ = 1;
  int n_ = 0;
  int ns_ = 0;
  std::vector<int> first_;               ///< first supernode of each one's subtree
  std::vector<int> top_;                 ///< increasing
  std::vector<int> top_columns_;
  std::vector<std::vector<int>> parts_;  ///< per thread: its subtrees' roots, increasing
  mutable std::vector<std::vector<double>> accumulators_;  ///< per thread, n, zero between solves
  mutable std::vector<std::vector<double>> work_;
  mutable std::vector<double> y_;
};

}  // namespace detail

void CholmodSolver::set_parallel_solve_min_entries(double entries) {
  g_parallel_solve_min_entries.store(entries);
}
double CholmodSolver::parallel_solve_min_entries() { return g_parallel_solve_min_entries.load(); }

CholmodSolver::CholmodSolver() {
  llt_.cholmod().print = 0;  // a failed (indefinite) attempt is handled here, not printed
}
CholmodSolver::~CholmodSolver() {
  // Before llt_'s destructor finishes the CHOLMOD common object these were allocated with.
  cholmod_free_dense(&x_, &llt_.common());
  cholmod_free_dense(&y_, &llt_.common());
  cholmod_free_dense(&e_, &llt_.common());
}

bool CholmodSolver::same_pattern(const SparseMatrix& A) const {
  if (A.rows() != pattern_rows_ || !A.isCompressed() || pattern_inner_.empty()) return false;
  const auto n = static_cast<std::size_t>(A.outerSize()) + 1;
  const auto nnz = static_cast<std::size_t>(A.nonZeros());
  return pattern_outer_.size() == n && pattern_inner_.size() == nnz &&
         std::equal(pattern_outer_.begin(), pattern_outer_.end(), A.outerIndexPtr()) &&
         std::equal(pattern_inner_.begin(), pattern_inner_.end(), A.innerIndexPtr());
}

void CholmodSolver::keep_pattern(const SparseMatrix& A) {
  pattern_outer_.clear();
  pattern_inner_.clear();
  if (!A.isCompressed()) return;  // never matched: analysed afresh each time
  pattern_outer_.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1);
  pattern_inner_.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
}

bool CholmodSolver::try_factorize(const SparseMatrix& A) {
  apply_solver_threads();
  const double t0 = now();
  if (!same_pattern(A)) {
    // Supernodal from 1000 unknowns (measured here with OpenBLAS, CPU time of whole static
    // solves: 6.5k-unknown surface model 2.9 vs 8.3 s simplicial, 1.6k: 0.63 vs 0.85 s; with
    // Debian's reference BLAS the crossing was near 10k). Simplicial for the tiny test problems.
    llt_.setMode(A.rows() < 1000 ? Eigen::CholmodSimplicialLLt : Eigen::CholmodSupernodalLLt);
    llt_.analyzePattern(A);
    flops_ = llt_.cholmod().fl;
    tree_.reset();  // planned for the old symbolic factor
    pattern_rows_ = A.rows();
    keep_pattern(A);
    ++analyses_;
  }
  mu_ = 0.0;
  llt_.factorize(A);
  ++factorisations_;
  seconds_ += now() - t0;
  return llt_.info() == Eigen::Success;
}

void CholmodSolver::factorize(const SparseMatrix& A) {
  if (try_factorize(A)) return;
  // Not positive definite (e.g. a surface membrane without transverse stiffness): regularise.
  VectorXd diag = A.diagonal();
  // A dof without stiffness (zero diagonal: e.g. a node between compressed springs, whose
  // transverse stiffness the projection removed) gets a shift relative to the mean diagonal.
  const double floor = 1e-3 * diag.cwiseAbs().mean() + 1e-300;
  for (double mu = 1e-10; mu <= 1e-2; mu *= 10.0) {
    SparseMatrix R = A;
    for (Eigen::Index i = 0; i < R.rows(); ++i) R.coeffRef(i, i) += mu * std::max(diag[i], floor);
    const double t0 = now();
    llt_.factorize(R);
    ++factorisations_;
    seconds_ += now() - t0;
    if (llt_.info() == Eigen::Success) {
      mu_ = mu;
      return;
    }
  }
  throw std::runtime_error("CHOLMOD: the system matrix is not positive definite, even regularised");
}

VectorXd CholmodSolver::solve(const VectorXd& b) const {
  apply_solver_threads();
  return llt_.solve(b);
}

double CholmodSolver::factor_entries() const {
  const cholmod_factor* L = llt_.factor();
  if (L == nullptr) return 0.0;
  return static_cast<double>(L->is_super ? L->xsize : L->nzmax);
}

void CholmodSolver::solve_into(const VectorXd& b, VectorXd& x) const {
  apply_solver_threads();
  cholmod_factor* L = llt_.factor();
  if (L == nullptr || llt_.info() != Eigen::Success) {
    throw std::logic_error("CholmodSolver::solve_into before a successful factorisation");
  }
  if (b.size() != static_cast<Eigen::Index>(L->n)) {
    throw std::invalid_argument("CholmodSolver::solve_into: right-hand side of the wrong size");
  }
  const int threads = solver_threads();
  if (threads > 1 && L->is_super && L->is_ll && L->xtype == CHOLMOD_REAL &&
      static_cast<double>(L->xsize) >= parallel_solve_min_entries()) {
    if (!tree_ || tree_->threads() != threads) {
      tree_ = std::make_unique<detail::SupernodalTreeSolve>(*L, threads);
    }
    x.resize(b.size());
    tree_->solve(*L, b.data(), x.data());
    last_solve_threads_ = threads;
    return;
  }
  last_solve_threads_ = 1;
  cholmod_dense B{};
  B.nrow = B.d = L->n;
  B.ncol = 1;
  B.nzmax = L->n;
  B.x = const_cast<double*>(b.data());  // read only: CHOLMOD_A does not write B
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  if (!cholmod_solve2(CHOLMOD_A, L, &B, nullptr, &x_, nullptr, &y_, &e_, &llt_.common())) {
    throw std::runtime_error("CHOLMOD: solve failed");
  }
  x = Eigen::Map<const VectorXd>(static_cast<const double*>(x_->x), b.size());
}

Eigen::MatrixXd CholmodSolver::solve_columns(const Eigen::MatrixXd& B) const {
  apply_solver_threads();
  return llt_.solve(B);
}

}  // namespace vessel::msm
