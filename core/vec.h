#pragma once
/// \file Small 2D/3D vector types. Float for storage, double for accumulation (see STYLE.md §6).
#include <array>
#include <cmath>
#include <ostream>

namespace raysift {

template <typename T>
struct Vec3T {
  T x = 0, y = 0, z = 0;
  constexpr Vec3T() = default;
  constexpr Vec3T(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
  template <typename U>
  constexpr explicit Vec3T(const Vec3T<U>& o) : x(T(o.x)), y(T(o.y)), z(T(o.z)) {}

  constexpr T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr Vec3T operator+(const Vec3T& o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3T operator-(const Vec3T& o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3T operator-() const { return {-x, -y, -z}; }
  constexpr Vec3T operator*(T s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3T operator/(T s) const { return {x / s, y / s, z / s}; }
  constexpr Vec3T& operator+=(const Vec3T& o) { x += o.x; y += o.y; z += o.z; return *this; }
  constexpr Vec3T& operator-=(const Vec3T& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
  constexpr Vec3T& operator*=(T s) { x *= s; y *= s; z *= s; return *this; }
  constexpr bool operator==(const Vec3T& o) const { return x == o.x && y == o.y && z == o.z; }
  constexpr bool operator!=(const Vec3T& o) const { return !(*this == o); }
};

template <typename T> constexpr Vec3T<T> operator*(T s, const Vec3T<T>& v) { return v * s; }
template <typename T> constexpr T dot(const Vec3T<T>& a, const Vec3T<T>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <typename T> constexpr Vec3T<T> cross(const Vec3T<T>& a, const Vec3T<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <typename T> inline T length(const Vec3T<T>& v) { return std::sqrt(dot(v, v)); }
/// Returns the zero vector for a zero-length input instead of NaN.
template <typename T> inline Vec3T<T> normalize(const Vec3T<T>& v) {
  const T len = length(v);
  return len > T(0) ? v / len : Vec3T<T>{};
}
template <typename T> inline Vec3T<T> min(const Vec3T<T>& a, const Vec3T<T>& b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
template <typename T> inline Vec3T<T> max(const Vec3T<T>& a, const Vec3T<T>& b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
template <typename T> inline bool is_finite(const Vec3T<T>& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
template <typename T> std::ostream& operator<<(std::ostream& os, const Vec3T<T>& v) {
  return os << '(' << v.x << ", " << v.y << ", " << v.z << ')';
}

using Vec3f = Vec3T<float>;
using Vec3d = Vec3T<double>;
using Vec3i = Vec3T<int>;

struct Vec2d {
  double x = 0, y = 0;
};

/// Axis-aligned box; empty when min > max on any axis.
struct Bbox3d {
  Vec3d min{1e300, 1e300, 1e300};
  Vec3d max{-1e300, -1e300, -1e300};
  bool is_empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
  void expand(const Vec3d& p) { min = raysift::min(min, p); max = raysift::max(max, p); }
  Vec3d extent() const { return max - min; }
  Vec3d center() const { return (min + max) * 0.5; }
  double diagonal() const { return is_empty() ? 0.0 : length(extent()); }
};

}  // namespace raysift
