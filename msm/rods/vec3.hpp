#pragma once
/// A 3-vector over any scalar (double or Jet), for the rod elements' energies.
#include <Eigen/Core>

namespace vessel::msm::rods {

template <class T>
struct V3 {
  T x, y, z;
  V3() = default;
  V3(T a, T b, T c) : x(a), y(b), z(c) {}
  explicit V3(const Eigen::Vector3d& v) : x(v.x()), y(v.y()), z(v.z()) {}
};
template <class T>
V3<T> operator+(const V3<T>& a, const V3<T>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
V3<T> operator-(const V3<T>& a, const V3<T>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T, class S>
V3<T> operator*(const S& s, const V3<T>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <class T>
T dot(const V3<T>& a, const V3<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
V3<T> cross(const V3<T>& a, const V3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
T norm(const V3<T>& a) {
  using std::sqrt;
  return sqrt(dot(a, a));
}

}  // namespace vessel::msm::rods

namespace vessel::msm::rods {
/// A constant vector as a V3 over T.
template <class T>
V3<T> lift(const Eigen::Vector3d& v) {
  return {T(v.x()), T(v.y()), T(v.z())};
}
}  // namespace vessel::msm::rods
