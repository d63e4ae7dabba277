#pragma once
/// Second-order forward-mode automatic differentiation over a fixed number N of inputs: a Jet
/// carries a value, its gradient and its Hessian with respect to the N inputs of one rod element.
/// Each element's energy is written once, templated on the scalar (double for the energy alone,
/// Jet<N> for gradient and Hessian), so the three always agree; the tests check them against
/// finite differences.
#include <Eigen/Core>
#include <cmath>
#include <type_traits>

namespace vessel::msm::rods {

/// An empty Hessian for first-order jets (Second = false): gradients at a fraction of the cost.
struct NoHessian {};

template <int N, bool Second = true>
struct Jet {
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = std::conditional_t<Second, Eigen::Matrix<double, N, N>, NoHessian>;
  double v = 0.0;
  Vec g = Vec::Zero();
  [[no_unique_address]] Mat h = zero_hessian();
  static Mat zero_hessian() {
    if constexpr (Second) {
      return Mat::Zero();
    } else {
      return {};
    }
  }

  Jet() = default;
  Jet(double value) : v(value) {}  // NOLINT: constants mix freely with jets
  /// The i-th input, with value `value`.
  static Jet variable(double value, int i) {
    Jet j(value);
    j.g[i] = 1.0;
    return j;
  }
};

/// f(a) by the chain rule from f(a.v), f'(a.v), f''(a.v).
template <int N, bool S>
Jet<N, S> chain(const Jet<N, S>& a, double f, double df, double d2f) {
  Jet<N, S> r;
  r.v = f;
  r.g = df * a.g;
  if constexpr (S) r.h = df * a.h + d2f * (a.g * a.g.transpose());
  return r;
}

template <int N, bool S>
Jet<N, S> operator+(const Jet<N, S>& a, const Jet<N, S>& b) {
  Jet<N, S> r;
  r.v = a.v + b.v;
  r.g = a.g + b.g;
  if constexpr (S) r.h = a.h + b.h;
  return r;
}
template <int N, bool S>
Jet<N, S> operator-(const Jet<N, S>& a, const Jet<N, S>& b) {
  Jet<N, S> r;
  r.v = a.v - b.v;
  r.g = a.g - b.g;
  if constexpr (S) r.h = a.h - b.h;
  return r;
}
template <int N, bool S>
Jet<N, S> operator-(const Jet<N, S>& a) {
  Jet<N, S> r;
  r.v = -a.v;
  r.g = -a.g;
  if constexpr (S) r.h = -a.h;
  return r;
}
template <int N, bool S>
Jet<N, S> operator*(const Jet<N, S>& a, const Jet<N, S>& b) {
  Jet<N, S> r;
  r.v = a.v * b.v;
  r.g = a.v * b.g + b.v * a.g;
  if constexpr (S) {
    const Eigen::Matrix<double, N, N> cross = a.g * b.g.transpose();
    r.h = a.v * b.h + b.v * a.h + cross + cross.transpose();
  }
  return r;
}
template <int N, bool S>
Jet<N, S> operator*(double s, const Jet<N, S>& a) {
  Jet<N, S> r;
  r.v = s * a.v;
  r.g = s * a.g;
  if constexpr (S) r.h = s * a.h;
  return r;
}
template <int N, bool S>
Jet<N, S> operator*(const Jet<N, S>& a, double s) {
  return s * a;
}
template <int N, bool S>
Jet<N, S> operator+(const Jet<N, S>& a, double s) {
  Jet<N, S> r = a;
  r.v += s;
  return r;
}
template <int N, bool S>
Jet<N, S> operator+(double s, const Jet<N, S>& a) {
  return a + s;
}
template <int N, bool S>
Jet<N, S> operator-(const Jet<N, S>& a, double s) {
  return a + (-s);
}
template <int N, bool S>
Jet<N, S> operator-(double s, const Jet<N, S>& a) {
  return (-a) + s;
}
template <int N, bool S>
Jet<N, S> inverse(const Jet<N, S>& a) {
  const double i = 1.0 / a.v;
  return chain(a, i, -i * i, 2.0 * i * i * i);
}
template <int N, bool S>
Jet<N, S> operator/(const Jet<N, S>& a, const Jet<N, S>& b) {
  return a * inverse(b);
}
template <int N, bool S>
Jet<N, S> operator/(const Jet<N, S>& a, double s) {
  return (1.0 / s) * a;
}
template <int N, bool S>
Jet<N, S> operator/(double s, const Jet<N, S>& a) {
  return s * inverse(a);
}
template <int N, bool S>
Jet<N, S> sqrt(const Jet<N, S>& a) {
  const double r = std::sqrt(a.v);
  return chain(a, r, 0.5 / r, -0.25 / (r * a.v));
}
template <int N, bool S>
Jet<N, S> sin(const Jet<N, S>& a) {
  return chain(a, std::sin(a.v), std::cos(a.v), -std::sin(a.v));
}
template <int N, bool S>
Jet<N, S> cos(const Jet<N, S>& a) {
  return chain(a, std::cos(a.v), -std::sin(a.v), -std::cos(a.v));
}
/// atan2(y, x) as a function of both: d = (x dy − y dx)/(x² + y²).
template <int N, bool S>
Jet<N, S> atan2(const Jet<N, S>& y, const Jet<N, S>& x) {
  const double r2 = x.v * x.v + y.v * y.v;
  Jet<N, S> r;
  r.v = std::atan2(y.v, x.v);
  r.g = (x.v * y.g - y.v * x.g) / r2;
  if constexpr (S) {
    // Hessian of atan2 in (y, x): ∂²/∂y² = −2xy/r⁴, ∂²/∂x² = 2xy/r⁴, ∂²/∂x∂y = (y² − x²)/r⁴.
    const double r4 = r2 * r2;
    const double hyy = -2.0 * x.v * y.v / r4;
    const double hxx = 2.0 * x.v * y.v / r4;
    const double hxy = (y.v * y.v - x.v * x.v) / r4;
    const Eigen::Matrix<double, N, N> yx = y.g * x.g.transpose();
    r.h = (x.v * y.h - y.v * x.h) / r2 + hyy * (y.g * y.g.transpose()) +
          hxx * (x.g * x.g.transpose()) + hxy * (yx + yx.transpose());
  }
  return r;
}

inline double value_of(double a) { return a; }
template <int N, bool S>
double value_of(const Jet<N, S>& a) {
  return a.v;
}

}  // namespace vessel::msm::rods
