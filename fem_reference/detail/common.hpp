#pragma once
/// Private to fem_reference (included by its own .cpp files only): the deal.II namespace alias,
/// the dimension and the small helpers every translation unit of the FEM reference uses.
#include <deal.II/base/function.h>
#include <deal.II/base/point.h>
#include <deal.II/lac/vector.h>

#include <chrono>
#include <functional>

#include "meshes/tet_mesh.hpp"

namespace vessel::fem::detail {

namespace dl = dealii;
inline constexpr int kDim = 3;

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

inline Vec3 to_vec3(const dl::Point<kDim>& p) { return {p[0], p[1], p[2]}; }

/// A std::function displacement as a deal.II Function with `n_components` components (the first
/// three are u; any further, the mixed element's pressure, are zero). An empty f is u = 0.
class VectorFunction : public dl::Function<kDim> {
 public:
  VectorFunction(std::function<Vec3(const Vec3&)> f, unsigned components)
      : dl::Function<kDim>(components), f_(std::move(f)) {}
  double value(const dl::Point<kDim>& p, unsigned component) const override {
    if (component >= 3 || !f_) return 0.0;
    return f_(to_vec3(p))[static_cast<int>(component)];
  }
  void vector_value(const dl::Point<kDim>& p, dl::Vector<double>& v) const override {
    v = 0.0;
    if (!f_) return;
    const Vec3 u = f_(to_vec3(p));
    for (unsigned c = 0; c < 3; ++c) v[c] = u[static_cast<int>(c)];
  }

 private:
  std::function<Vec3(const Vec3&)> f_;
};

}  // namespace vessel::fem::detail
