// Vectors, matrices, frames and small numeric helpers shared by the whole renderer.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace pt {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;
constexpr float kInf = INFINITY;

struct Vec2 {
  float x = 0, y = 0;
};

struct Vec3 {
  float x = 0, y = 0, z = 0;
  constexpr Vec3() = default;
  constexpr Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
  constexpr explicit Vec3(float s) : x(s), y(s), z(s) {}
  float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};

inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
inline Vec3 operator*(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline Vec3 operator*(float s, Vec3 a) { return {a.x * s, a.y * s, a.z * s}; }
inline Vec3 operator/(Vec3 a, float s) { return a * (1.0f / s); }
inline Vec3 operator/(Vec3 a, Vec3 b) { return {a.x / b.x, a.y / b.y, a.z / b.z}; }
inline Vec3& operator+=(Vec3& a, Vec3 b) { return a = a + b; }
inline Vec3& operator-=(Vec3& a, Vec3 b) { return a = a - b; }
inline Vec3& operator*=(Vec3& a, Vec3 b) { return a = a * b; }
inline Vec3& operator*=(Vec3& a, float s) { return a = a * s; }
inline Vec3& operator/=(Vec3& a, float s) { return a = a / s; }
inline bool operator==(Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
inline bool operator!=(Vec3 a, Vec3 b) { return !(a == b); }

inline float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length_squared(Vec3 a) { return dot(a, a); }
inline float length(Vec3 a) { return std::sqrt(dot(a, a)); }
inline Vec3 normalize(Vec3 a) {
  float l = length(a);
  return l > 0 ? a / l : Vec3(0.0f);
}
inline Vec3 abs(Vec3 a) { return {std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)}; }
inline Vec3 min(Vec3 a, Vec3 b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
inline Vec3 max(Vec3 a, Vec3 b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
inline float max_component(Vec3 a) { return std::max(a.x, std::max(a.y, a.z)); }
inline float min_component(Vec3 a) { return std::min(a.x, std::min(a.y, a.z)); }
inline bool is_black(Vec3 a) { return a.x == 0 && a.y == 0 && a.z == 0; }
inline bool is_finite(Vec3 a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }
// Rec. 709 luminance, the weights the course uses for its "illuminance".
inline float luminance(Vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
inline float clampf(float v, float lo, float hi) { return std::min(hi, std::max(lo, v)); }
inline float safe_sqrt(float v) { return std::sqrt(std::max(0.0f, v)); }
inline float sqr(float v) { return v * v; }
inline Vec3 reflect(Vec3 wo, Vec3 n) { return -wo + 2 * dot(wo, n) * n; }

// The orthonormal shading frame, Frame, is lane_math.h's (written once for every lane width).

struct Ray {
  Vec3 o, d;
  float tmin = 0, tmax = kInf;
};

// Row-major 4x4 affine transform in double precision (scene files are transformed once at load).
struct Mat4 {
  double m[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
  static Mat4 identity() { return Mat4(); }
  static Mat4 zero() {
    Mat4 r;
    std::memset(r.m, 0, sizeof(r.m));
    return r;
  }
  Mat4 operator*(const Mat4& b) const {
    Mat4 r = zero();
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        for (int k = 0; k < 4; ++k) r.m[i][j] += m[i][k] * b.m[k][j];
    return r;
  }
  Vec3 point(Vec3 p) const {
    double v[3];
    for (int i = 0; i < 3; ++i) v[i] = m[i][0] * p.x + m[i][1] * p.y + m[i][2] * p.z + m[i][3];
    return {float(v[0]), float(v[1]), float(v[2])};
  }
  Vec3 vector(Vec3 d) const {
    double v[3];
    for (int i = 0; i < 3; ++i) v[i] = m[i][0] * d.x + m[i][1] * d.y + m[i][2] * d.z;
    return {float(v[0]), float(v[1]), float(v[2])};
  }
  // Normals transform by the inverse transpose; the cofactor matrix of the 3x3 part has the
  // same direction (and sign handling for mirrored transforms) without dividing by the determinant.
  Vec3 normal(Vec3 n) const {
    double c[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
        c[i][j] = m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1];
      }
    double v[3];
    for (int i = 0; i < 3; ++i) v[i] = c[i][0] * n.x + c[i][1] * n.y + c[i][2] * n.z;
    return {float(v[0]), float(v[1]), float(v[2])};
  }
  double det3() const {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  }
};

struct Bounds3 {
  Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
  void expand(Vec3 p) {
    lo = min(lo, p);
    hi = max(hi, p);
  }
  bool empty() const { return lo.x > hi.x; }
  Vec3 center() const { return (lo + hi) * 0.5f; }
  Vec3 diagonal() const { return hi - lo; }
};

}  // namespace pt
