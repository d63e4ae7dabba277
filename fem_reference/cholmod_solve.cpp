#include "fem_reference/cholmod_solve.hpp"

#include <Eigen/CholmodSupport>
#include <algorithm>
#include <atomic>
#include <cstring>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>

#include "meshes/foundation/solver_threads.hpp"

namespace vessel::fem {

namespace {

/// Both compressed: the same size and the same stored entries (values aside).
bool same_pattern(const Eigen::SparseMatrix<double>& a, const Eigen::SparseMatrix<double>& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols() || a.nonZeros() != b.nonZeros()) return false;
  const auto n = static_cast<std::size_t>(a.nonZeros());
  const auto outer = static_cast<std::size_t>(a.outerSize() + 1);
  return std::memcmp(a.outerIndexPtr(), b.outerIndexPtr(), outer * sizeof(int)) == 0 &&
         std::memcmp(a.innerIndexPtr(), b.innerIndexPtr(), n * sizeof(int)) == 0;
}

/// K itself when compressed (a matrix built by setFromTriplets is), else a compressed copy held in
/// `copy`: the comparisons read the compressed arrays.
const Eigen::SparseMatrix<double>& compressed(const Eigen::SparseMatrix<double>& K,
                                              std::optional<Eigen::SparseMatrix<double>>& copy) {
  if (K.isCompressed()) return K;
  copy.emplace(K);
  copy->makeCompressed();
  return *copy;
}

}  // namespace

Eigen::VectorXd solve_spd_cholmod(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& b) {
  return CholmodFactor(K).solve(b);
}

struct CholmodFactor::Impl {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
};

CholmodFactor::CholmodFactor(const Eigen::SparseMatrix<double>& K)
    : impl_(std::make_unique<Impl>()) {
  apply_solver_threads();
  // A matrix that is not positive definite is reported by the exception below (the
  // finite-strain Newton then solves by LU); CHOLMOD's own warning on stderr would only repeat it.
  impl_->llt.cholmod().print = 0;
  impl_->llt.compute(K);
  if (impl_->llt.info() != Eigen::Success) {
    throw std::runtime_error(
        "CHOLMOD could not factorise the displacement system: it is not positive definite "
        "(an unconstrained rigid-body motion?)");
  }
}

CholmodFactor::~CholmodFactor() = default;

namespace {

/// A kept factor with the matrix it factorises; `solving` serialises its solves (CHOLMOD's
/// workspace in the factor object is not safe for concurrent solves).
struct KeptFactor {
  Eigen::SparseMatrix<double> K;
  std::unique_ptr<CholmodFactor> factor;
  std::mutex solving;
};

constexpr std::size_t kKeptFactors = 4;
std::mutex kept_mutex;
std::list<std::shared_ptr<KeptFactor>> kept;  // most recently used first
std::atomic<long> hits{0};

bool identical(const Eigen::SparseMatrix<double>& a, const Eigen::SparseMatrix<double>& b) {
  return same_pattern(a, b) &&
         std::memcmp(a.valuePtr(), b.valuePtr(),
                     static_cast<std::size_t>(a.nonZeros()) * sizeof(double)) == 0;
}

}  // namespace

Eigen::VectorXd solve_spd_cholmod_keeping_factor(const Eigen::SparseMatrix<double>& K,
                                                 const Eigen::VectorXd& b) {
  std::optional<Eigen::SparseMatrix<double>> copy;
  const Eigen::SparseMatrix<double>& A = compressed(K, copy);
  std::shared_ptr<KeptFactor> entry;
  {
    const std::lock_guard lock(kept_mutex);
    const auto it =
        std::find_if(kept.begin(), kept.end(), [&](const auto& e) { return identical(e->K, A); });
    if (it != kept.end()) {
      entry = *it;
      kept.splice(kept.begin(), kept, it);
      ++hits;
    }
  }
  if (!entry) {  // factorise outside the lock: another thread may factorise another matrix
    entry = std::make_shared<KeptFactor>();
    entry->factor = std::make_unique<CholmodFactor>(A);
    entry->K = A;  // the one copy: kept to recognise the matrix next time
    const std::lock_guard lock(kept_mutex);
    kept.push_front(entry);
    if (kept.size() > kKeptFactors) kept.pop_back();
  }
  const std::lock_guard solving(entry->solving);
  return entry->factor->solve(b);
}

void release_kept_factors() {
  const std::lock_guard lock(kept_mutex);
  kept.clear();
}

long kept_factor_hits() { return hits.load(); }

Eigen::VectorXd CholmodFactor::solve(const Eigen::VectorXd& b) const {
  apply_solver_threads();
  Eigen::VectorXd x = impl_->llt.solve(b);
  if (impl_->llt.info() != Eigen::Success) throw std::runtime_error("CHOLMOD solve failed");
  return x;
}

Eigen::MatrixXd CholmodFactor::solve_block(const Eigen::MatrixXd& B) const {
  apply_solver_threads();
  Eigen::MatrixXd X = impl_->llt.solve(B);
  if (impl_->llt.info() != Eigen::Success) throw std::runtime_error("CHOLMOD solve failed");
  return X;
}

struct CholmodSamePattern::Impl {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
  Eigen::SparseMatrix<double> pattern;  ///< the analysed matrix's structure (values unused)
  int analyses = 0;
};

CholmodSamePattern::CholmodSamePattern() : impl_(std::make_unique<Impl>()) {
  impl_->llt.cholmod().print = 0;  // as in CholmodFactor: failures are reported by exception
}

CholmodSamePattern::~CholmodSamePattern() = default;

int CholmodSamePattern::analyses() const { return impl_->analyses; }

Eigen::VectorXd CholmodSamePattern::solve(const Eigen::SparseMatrix<double>& K,
                                          const Eigen::VectorXd& b) {
  std::optional<Eigen::SparseMatrix<double>> copy;
  const Eigen::SparseMatrix<double>& A = compressed(K, copy);
  apply_solver_threads();
  if (impl_->analyses == 0 || !same_pattern(impl_->pattern, A)) {
    impl_->llt.analyzePattern(A);
    impl_->pattern = A;
    ++impl_->analyses;
  }
  impl_->llt.factorize(A);
  if (impl_->llt.info() != Eigen::Success) {
    throw std::runtime_error(
        "CHOLMOD could not factorise the displacement system: it is not positive definite");
  }
  Eigen::VectorXd x = impl_->llt.solve(b);
  if (impl_->llt.info() != Eigen::Success) throw std::runtime_error("CHOLMOD solve failed");
  return x;
}

}  // namespace vessel::fem
