#include "fem_reference/rod_theory/elastica.hpp"

#include <boost/math/special_functions/ellint_1.hpp>
#include <boost/math/special_functions/ellint_2.hpp>
#include <boost/math/tools/roots.hpp>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace vessel::rod_theory {

namespace {

using boost::math::ellint_1;
using boost::math::ellint_2;

double bisect(const auto& f, double a, double b) {
  boost::math::tools::eps_tolerance<double> tol(52);
  std::uintmax_t iterations = 200;
  const auto r = boost::math::tools::toms748_solve(f, a, b, tol, iterations);
  return 0.5 * (r.first + r.second);
}

}  // namespace

ElasticaTip bisshopp_drucker(double alpha) {
  if (!(alpha > 0.0)) throw std::invalid_argument("bisshopp_drucker: alpha must be > 0");
  const auto k_of = [](double theta0) { return std::sqrt((1.0 + std::sin(theta0)) / 2.0); };
  const auto phi1_of = [](double k) { return std::asin(1.0 / (std::sqrt(2.0) * k)); };
  const auto load = [&](double theta0) {
    const double k = k_of(theta0);
    return ellint_1(k) - ellint_1(k, phi1_of(k)) - std::sqrt(alpha);
  };
  ElasticaTip tip;
  // θ₀ < π/2 − 1e-6 keeps k below 1 in double precision, so K(k) finite.
  tip.tip_angle = bisect(load, 1e-14, std::numbers::pi / 2 - 1e-6);
  const double k = k_of(tip.tip_angle);
  tip.deflection = 1.0 - 2.0 / std::sqrt(alpha) * (ellint_2(k) - ellint_2(k, phi1_of(k)));
  tip.shortening = 1.0 - std::sqrt(2.0 * std::sin(tip.tip_angle) / alpha);
  return tip;
}

std::array<double, 4> integrate_planar(const std::array<double, 4>& start, double fx, double fy,
                                       double length) {
  using State = std::array<double, 4>;
  namespace odeint = boost::numeric::odeint;
  const auto rhs = [fx, fy](const State& y, State& dy, double) {
    dy[0] = std::cos(y[2]);
    dy[1] = std::sin(y[2]);
    dy[2] = y[3];
    dy[3] = fx * std::sin(y[2]) - fy * std::cos(y[2]);
  };
  State y = start;
  auto stepper = odeint::make_controlled(1e-13, 1e-13, odeint::runge_kutta_dopri5<State>());
  odeint::integrate_adaptive(stepper, rhs, y, 0.0, length, length / 64);
  return y;
}

PlanarShot shoot_planar_cantilever(double fx, double fy, double tip_moment, double clamp_angle,
                                   double length) {
  // m(0) from the linear solution, then Newton (central-difference slope) at growing load.
  const auto tip_m = [&](double m0, double s) {
    return integrate_planar({0.0, 0.0, clamp_angle, m0}, s * fx, s * fy, length)[3] -
           s * tip_moment;
  };
  double m0 = 0.0;
  const int ramps = 64;
  for (int r = 1; r <= ramps; ++r) {
    const double s = static_cast<double>(r) / ramps;
    for (int it = 0; it < 60; ++it) {
      const double f = tip_m(m0, s);
      if (std::abs(f) < 1e-13) break;
      const double h = 1e-6;
      const double df = (tip_m(m0 + h, s) - tip_m(m0 - h, s)) / (2 * h);
      m0 -= f / df;
    }
  }
  const auto y = integrate_planar({0.0, 0.0, clamp_angle, m0}, fx, fy, length);
  PlanarShot shot{y[0], y[1], y[2], m0, std::abs(y[3] - tip_moment)};
  if (!(shot.residual < 1e-10)) {
    throw std::runtime_error("shoot_planar_cantilever: no convergence, residual " +
                             std::to_string(shot.residual));
  }
  return shot;
}

double euler_cantilever_load() { return std::numbers::pi * std::numbers::pi / 4.0; }

double greenhill_clamped() {
  const double pi = std::numbers::pi;
  // tan(μ/2) − μ/2 changes sign once on (2π, 3π), where μ/2 runs through (π, 3π/2).
  return bisect([](double mu) { return std::tan(mu / 2) - mu / 2; }, 2 * pi + 1e-9, 3 * pi - 1e-9);
}

double cantilever_beta(int n) {
  if (n < 1) throw std::invalid_argument("cantilever_beta: n must be >= 1");
  const double pi = std::numbers::pi;
  // One root in each ((n − 1)π + π/2, nπ + π/2) ... bracket (n − ½)π ± π/2.
  const double c = (n - 0.5) * pi;
  return bisect([](double b) { return std::cos(b) * std::cosh(b) + 1.0; }, c - pi / 2 + 1e-9,
                c + pi / 2 - 1e-9);
}

}  // namespace vessel::rod_theory
