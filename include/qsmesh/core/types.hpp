// Basic index and vector types shared by every module.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <type_traits>

namespace qsmesh {

/// Local (per rank, per face, per array) index: 32 bits.
using LO = std::int32_t;
/// Global id across the whole distributed mesh: 64 bits.
using GO = std::int64_t;

inline constexpr LO kNoIndex = -1;

/// A point or vector in 3D model space (model units).
struct Vec3 {
  double x = 0, y = 0, z = 0;

  constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3 operator/(double s) const { return {x / s, y / s, z / s}; }
  constexpr Vec3& operator+=(const Vec3& o) {
    x += o.x;
    y += o.y;
    z += o.z;
    return *this;
  }
  constexpr Vec3& operator-=(const Vec3& o) {
    x -= o.x;
    y -= o.y;
    z -= o.z;
    return *this;
  }
  constexpr Vec3& operator*=(double s) {
    x *= s;
    y *= s;
    z *= s;
    return *this;
  }
  constexpr double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr bool operator==(const Vec3&) const = default;
};

constexpr Vec3 operator*(double s, const Vec3& v) { return v * s; }
constexpr double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
constexpr double norm2(const Vec3& a) { return dot(a, a); }
inline double distance(const Vec3& a, const Vec3& b) { return norm(a - b); }
/// Unit vector along a; the zero vector stays zero.
inline Vec3 normalized(const Vec3& a) {
  const double n = norm(a);
  return n > 0 ? a / n : a;
}

/// A point or vector in a face's parameter plane (u, v).
struct Vec2 {
  double u = 0, v = 0;

  constexpr Vec2 operator+(const Vec2& o) const { return {u + o.u, v + o.v}; }
  constexpr Vec2 operator-(const Vec2& o) const { return {u - o.u, v - o.v}; }
  constexpr Vec2 operator*(double s) const { return {u * s, v * s}; }
  constexpr Vec2 operator/(double s) const { return {u / s, v / s}; }
  constexpr Vec2& operator+=(const Vec2& o) {
    u += o.u;
    v += o.v;
    return *this;
  }
  constexpr double operator[](int i) const { return i == 0 ? u : v; }
  constexpr bool operator==(const Vec2&) const = default;
};

constexpr Vec2 operator*(double s, const Vec2& v) { return v * s; }
constexpr double dot(const Vec2& a, const Vec2& b) { return a.u * b.u + a.v * b.v; }
/// z-component of the 2D cross product.
constexpr double cross(const Vec2& a, const Vec2& b) { return a.u * b.v - a.v * b.u; }
inline double norm(const Vec2& a) { return std::sqrt(dot(a, a)); }

/// Axis-aligned box in 3D.
struct Box3 {
  Vec3 lo{+1e300, +1e300, +1e300};
  Vec3 hi{-1e300, -1e300, -1e300};

  void add(const Vec3& p) {
    lo = {std::fmin(lo.x, p.x), std::fmin(lo.y, p.y), std::fmin(lo.z, p.z)};
    hi = {std::fmax(hi.x, p.x), std::fmax(hi.y, p.y), std::fmax(hi.z, p.z)};
  }
  void add(const Box3& b) {
    if (b.valid()) {
      add(b.lo);
      add(b.hi);
    }
  }
  [[nodiscard]] bool valid() const { return lo.x <= hi.x; }
  [[nodiscard]] double diagonal() const { return valid() ? distance(lo, hi) : 0.0; }
};

/// Axis-aligned box in a parameter plane.
struct Box2 {
  Vec2 lo{+1e300, +1e300};
  Vec2 hi{-1e300, -1e300};

  void add(const Vec2& p) {
    lo = {std::fmin(lo.u, p.u), std::fmin(lo.v, p.v)};
    hi = {std::fmax(hi.u, p.u), std::fmax(hi.v, p.v)};
  }
  [[nodiscard]] bool valid() const { return lo.u <= hi.u; }
};

/// True for std::array<T, N>: code that walks a record's declared fields (parallel/record.hpp,
/// the drivers' report totals) treats fixed arrays element by element.
template <class T>
struct IsStdArray : std::false_type {};
template <class T, std::size_t N>
struct IsStdArray<std::array<T, N>> : std::true_type {};

}  // namespace qsmesh
