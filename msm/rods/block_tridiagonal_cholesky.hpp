#pragma once
/// Cholesky factorisation of a symmetric positive definite block-tridiagonal matrix of B × B
/// blocks (diagonal blocks A(i, i), sub-diagonal blocks A(i+1, i)): L(i, i) = chol(A(i, i) −
/// L(i, i−1) L(i, i−1)ᵀ), L(i+1, i) = A(i+1, i) L(i, i)⁻ᵀ; O(n B³) to factorise, O(n B²) to
/// solve, in fixed-size blocks. The XPBD rod's direct solver uses it on its constraint blocks
/// taken two by two along the chain (Deul, Kugelstadt, Weiler & Bender 2018 solve the same
/// tree-structured system in linear time).
///
/// Z > 0 declares the sub-diagonal blocks' lower-left Z × Z corner (rows B−Z.., columns ..Z−1)
/// zero, as when the blocks pair up constraints that couple only up to two apart (the XPBD
/// rod: 3-row constraints, B = 6, Z = 3). L(i+1, i) keeps that corner zero (each of its rows
/// solves a lower-triangular system whose leading right-hand sides are zero), so the corner is
/// never read or written, and the products skip it.
#include <Eigen/Core>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace vessel::msm::rods {

template <int B, int Z = 0>
class BlockTridiagonalCholesky {
  static_assert(Z >= 0 && Z <= B, "the zero corner must fit in a block");

 public:
  using Block = Eigen::Matrix<double, B, B>;
  using Vector = Eigen::Matrix<double, B, 1>;

  /// n diagonal blocks, all zero.
  void resize(int n) {
    diagonal_.assign(n, Block::Zero());
    sub_.assign(n > 0 ? n - 1 : 0, Block::Zero());
    inverse_diagonal_.assign(n, Vector::Zero());
  }
  [[nodiscard]] int size() const { return static_cast<int>(diagonal_.size()); }
  /// A(i, i) (only its lower triangle is read).
  Block& diagonal(int i) { return diagonal_[i]; }
  /// A(i+1, i) (its zero corner, if Z > 0, is not read).
  Block& sub(int i) { return sub_[i]; }

  /// Overwrites the blocks with the factor. Throws std::runtime_error if a diagonal block is not
  /// positive definite.
  void factorize() {
    for (int i = 0; i < size(); ++i) factor_row(i);
  }

  /// Solves A x = r in place with the factor (r has B·n entries).
  void solve(Eigen::VectorXd& r) const {
    for (int i = 0; i < size(); ++i) forward_row(i, r.data());
    for (int i = size() - 1; i >= 0; --i) backward_row(i, r.data());
  }

  /// Assembles, factorises and solves A x = r in one sweep each way: fill(i) sets A(i, i),
  /// A(i+1, i) and r's block i just before block row i is factorised and its forward
  /// substitution done (the two dependency chains and the filling overlap); done(i) is called
  /// as soon as x's block i is solved (in r), from the last block to the first.
  template <class Fill, class Done>
  void assemble_factorize_solve(Eigen::VectorXd& r, Fill&& fill, Done&& done) {
    for (int i = 0; i < size(); ++i) {
      fill(i);
      factor_row(i);
      forward_row(i, r.data());
    }
    for (int i = size() - 1; i >= 0; --i) {
      backward_row(i, r.data());
      done(i);
    }
  }

 private:
  /// The first column of row r of a sub-diagonal block that is not in the zero corner.
  static constexpr int first_column(int r) { return r >= B - Z ? Z : 0; }

  /// Block row i of the factor: L(i, i) and L(i+1, i), computed in local arrays (which the
  /// compiler knows alias nothing) and stored once.
  void factor_row(int i) {
    double a[B][B], l[B][B], inverse[B];
#pragma GCC unroll 8
    for (int c = 0; c < B; ++c) {
#pragma GCC unroll 8
      for (int r = c; r < B; ++r) a[r][c] = diagonal_[i](r, c);
    }
    if (i > 0) subtract_lower_gram(sub_[i - 1], a);
    cholesky(a, l, inverse, i);
#pragma GCC unroll 8
    for (int c = 0; c < B; ++c) {
      inverse_diagonal_[i][c] = inverse[c];
#pragma GCC unroll 8
      for (int r = c; r < B; ++r) diagonal_[i](r, c) = l[r][c];
    }
    if (i + 1 == size()) return;
    // L(i+1, i) = A(i+1, i) L(i, i)⁻ᵀ: each row x solves L(i, i) xᵀ = (its row of A)ᵀ.
    Block& s = sub_[i];
#pragma GCC unroll 8
    for (int r = 0; r < B; ++r) {
      double x[B];
#pragma GCC unroll 8
      for (int j = first_column(r); j < B; ++j) {
        double v = s(r, j);
#pragma GCC unroll 8
        for (int k = first_column(r); k < j; ++k) v -= l[j][k] * x[k];
        x[j] = v * inverse[j];
      }
#pragma GCC unroll 8
      for (int j = first_column(r); j < B; ++j) s(r, j) = x[j];
    }
  }

  /// Block row i of L y = r (y over r; rows before i already solved). Scalar loads and stores
  /// only: packet copies of entries just stored one by one stall on store forwarding.
  void forward_row(int i, double* r) const {
    double* y = r + B * i;
    if (i > 0) {
      const double* previous = r + B * (i - 1);
#pragma GCC unroll 8
      for (int row = 0; row < B; ++row) {
        double v = 0.0;
#pragma GCC unroll 8
        for (int k = first_column(row); k < B; ++k) v += sub_[i - 1](row, k) * previous[k];
        y[row] -= v;
      }
    }
#pragma GCC unroll 8
    for (int j = 0; j < B; ++j) {
      double v = y[j];
#pragma GCC unroll 8
      for (int k = 0; k < j; ++k) v -= diagonal_[i](j, k) * y[k];
      y[j] = v * inverse_diagonal_[i][j];
    }
  }

  /// Block row i of Lᵀ x = y (x over y; rows after i already solved).
  void backward_row(int i, double* r) const {
    double* y = r + B * i;
    if (i + 1 < size()) {
      const double* next = r + B * (i + 1);
#pragma GCC unroll 8
      for (int col = 0; col < B; ++col) {
        double v = 0.0;
#pragma GCC unroll 8
        for (int row = 0; row < B; ++row) {
          if (col >= first_column(row)) v += sub_[i](row, col) * next[row];
        }
        y[col] -= v;
      }
    }
#pragma GCC unroll 8
    for (int j = B - 1; j >= 0; --j) {
      double v = y[j];
#pragma GCC unroll 8
      for (int k = j + 1; k < B; ++k) v -= diagonal_[i](k, j) * y[k];
      y[j] = v * inverse_diagonal_[i][j];
    }
  }

  /// The lower triangle of a −= s sᵀ (the only triangle the factorisation reads), s a
  /// sub-diagonal block.
  static void subtract_lower_gram(const Block& s, double (&a)[B][B]) {
    double t[B][B];
#pragma GCC unroll 8
    for (int r = 0; r < B; ++r) {
#pragma GCC unroll 8
      for (int k = first_column(r); k < B; ++k) t[r][k] = s(r, k);
    }
#pragma GCC unroll 8
    for (int c = 0; c < B; ++c) {
#pragma GCC unroll 8
      for (int r = c; r < B; ++r) {
        double v = 0.0;
#pragma GCC unroll 8
        for (int k = first_column(r); k < B; ++k) v += t[r][k] * t[c][k];
        a[r][c] -= v;
      }
    }
  }

  /// The lower Cholesky factor l of a's lower triangle (fixed-size, unrolled), 1/l(j, j) in
  /// inverse. The recursion runs on the unscaled columns u(i, j) = l(i, j) l(j, j) and
  /// 1/d_j = 1/l(j, j)² (as LDLᵀ does): d_j = a(j, j) − Σ_k u(j, k)² / d_k and
  /// u(i, j) = a(i, j) − Σ_k u(i, k) u(j, k) / d_k, so the chain from one pivot to the next
  /// holds one division and no square root; l(i, j) = u(i, j) · √d_j / d_j.
  static void cholesky(const double (&a)[B][B], double (&l)[B][B], double (&inverse)[B],
                       int block) {
    double u[B][B];
    double reciprocal[B];
#pragma GCC unroll 8
    for (int j = 0; j < B; ++j) {
      double d = a[j][j];
#pragma GCC unroll 8
      for (int k = 0; k < j; ++k) d -= u[j][k] * u[j][k] * reciprocal[k];
      if (!(d > 0.0)) throw_not_positive_definite(block);
      reciprocal[j] = 1.0 / d;
#pragma GCC unroll 8
      for (int i = j + 1; i < B; ++i) {
        double v = a[i][j];
#pragma GCC unroll 8
        for (int k = 0; k < j; ++k) v -= u[i][k] * u[j][k] * reciprocal[k];
        u[i][j] = v;
      }
      const double root = std::sqrt(d);
      l[j][j] = root;
      inverse[j] = root * reciprocal[j];
#pragma GCC unroll 8
      for (int i = j + 1; i < B; ++i) l[i][j] = u[i][j] * inverse[j];
    }
  }

  [[noreturn]] static void throw_not_positive_definite(int block) {
    throw std::runtime_error("BlockTridiagonalCholesky: block " + std::to_string(block) +
                             " is not positive definite");
  }

  std::vector<Block> diagonal_, sub_;
  std::vector<Vector> inverse_diagonal_;
};

}  // namespace vessel::msm::rods
