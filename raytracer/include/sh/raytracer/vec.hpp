#pragma once
// Host-side 3-vectors for scene data (kernels use the DSL's Attrib3f).
#include <algorithm>
#include <cmath>

namespace sh::rt {

struct Vec3 {
  float x = 0, y = 0, z = 0;
  float operator[](int i) const { return i == 0 ? x : i == 1 ? y : z; }
  float& operator[](int i) { return i == 0 ? x : i == 1 ? y : z; }
};

inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline Vec3 operator*(float s, Vec3 a) { return a * s; }
inline float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
// In double: the squares of a float's range (a cross product of edges
// 1e10 long, or 1e-12 short) neither overflow nor vanish there.
inline double length_in_double(Vec3 a) {
  double x = a.x, y = a.y, z = a.z;
  return std::sqrt(x * x + y * y + z * z);
}
inline float length(Vec3 a) { return static_cast<float>(length_in_double(a)); }
inline Vec3 normalize(Vec3 a) {
  double l = length_in_double(a);
  if (!(l > 0)) return Vec3{};
  return {static_cast<float>(a.x / l), static_cast<float>(a.y / l), static_cast<float>(a.z / l)};
}
inline Vec3 min(Vec3 a, Vec3 b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
inline Vec3 max(Vec3 a, Vec3 b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
inline bool finite(Vec3 a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }

}  // namespace sh::rt
