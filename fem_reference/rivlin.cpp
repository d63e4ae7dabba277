#include "fem_reference/rivlin.hpp"

#include <array>
#include <cmath>
#include <functional>
#include <stdexcept>

namespace vessel::fem {

namespace {

/// Adaptive Gauss–Kronrod 7–15 on [a, b]: the Kronrod estimate, split until |K − G| ≤ tol.
double gauss_kronrod(const std::function<double(double)>& f, double a, double b, double tol,
                     int depth = 0) {
  // Nodes and weights of the 15-point Kronrod rule and its embedded 7-point Gauss rule
  // (Piessens et al., QUADPACK, 1983, routine qk15).
  static constexpr std::array<double, 8> xk{
      0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
      0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
      0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
      0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
  static constexpr std::array<double, 8> wk{
      0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
      0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
      0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
      0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
  static constexpr std::array<double, 4> wg{
      0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
      0.381830050505118944950369775488975, 0.417959183673469387755102040816327};
  const double c = 0.5 * (a + b), h = 0.5 * (b - a);
  const double fc = f(c);
  double kronrod = wk[7] * fc, gauss = wg[3] * fc;
  for (int j = 0; j < 7; ++j) {
    const double s = f(c - h * xk[j]) + f(c + h * xk[j]);
    kronrod += wk[j] * s;
    if (j % 2 == 1) gauss += wg[j / 2] * s;
  }
  kronrod *= h;
  gauss *= h;
  if (std::abs(kronrod - gauss) <= tol || depth > 40) return kronrod;
  return gauss_kronrod(f, a, c, 0.5 * tol, depth + 1) +
         gauss_kronrod(f, c, b, 0.5 * tol, depth + 1);
}

}  // namespace

double RivlinTube::deformed_radius(double R, double a) const {
  return std::sqrt(R * R + a * a - inner_radius * inner_radius);
}

double RivlinTube::pressure_by_quadrature(double a) const {
  const double c = a * a - inner_radius * inner_radius;
  const double b = deformed_radius(outer_radius, a);
  // σ_θθ − σ_rr = μ(λ_θ² − λ_r²) with λ_θ = r/R, λ_r = R/r; ∂σ_rr/∂r = (σ_θθ − σ_rr)/r.
  auto integrand = [&](double r) {
    const double R2 = r * r - c;
    return shear_modulus * (r * r / R2 - R2 / (r * r)) / r;
  };
  const double scale = std::abs(pressure(a)) + shear_modulus * 1e-300;
  return gauss_kronrod(integrand, a, b, 1e-13 * scale);
}

double RivlinTube::pressure(double a) const {
  const double A = inner_radius, B = outer_radius;
  const double c = a * a - A * A;
  const double b = deformed_radius(B, a);
  return shear_modulus * (std::log(a * B / (A * b)) + 0.5 * c * (1.0 / (a * a) - 1.0 / (b * b)));
}

double RivlinTube::limit_pressure() const {
  return shear_modulus * std::log(outer_radius / inner_radius);
}

double RivlinTube::inner_radius_at(double P) const {
  if (!(P >= 0.0 && P < limit_pressure())) {
    throw std::domain_error("Rivlin tube: pressure outside [0, mu ln(B/A)): no equilibrium");
  }
  double lo = inner_radius, hi = 2.0 * inner_radius;
  while (pressure(hi) < P) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (pressure(mid) < P ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Vec3 RivlinTube::displacement(const Vec3& x, double P) const {
  const double R = std::hypot(x.x(), x.y());
  const double r = deformed_radius(R, inner_radius_at(P));
  return Vec3(x.x(), x.y(), 0.0) * ((r - R) / R);
}

}  // namespace vessel::fem
