// Four floats at a time with GCC vector extensions on SSE2 (the portable build's vectors), for
// the loops that repeat scalar code lane by lane (diffuse_lanes.cpp, Camera::pinhole_rays). Each
// helper is the scalar operation in the scalar order, so the lanes keep the scalar bits: a dot
// product is (x x' + y y') + z z', and there is no FMA to contract.
#pragma once

#include <emmintrin.h>

#include <cstdint>

#include "math.h"

namespace pt::simd {

typedef float vf __attribute__((vector_size(16)));
typedef int32_t vi __attribute__((vector_size(16)));

struct V3 {
  vf x, y, z;
};

inline vf splat(float f) { return vf{f, f, f, f}; }
inline vf load(const float* p) { return *reinterpret_cast<const vf*>(p); }  // 16-byte aligned
inline vf loadu(const float* p) {
  vf a;
  __builtin_memcpy(&a, p, sizeof a);
  return a;
}
inline void store(float* p, vf a) { *reinterpret_cast<vf*>(p) = a; }
inline void storei(int* p, vi a) { *reinterpret_cast<vi*>(p) = a; }
inline V3 load3(const float* x, const float* y, const float* z, int i) { return {load(x + i), load(y + i), load(z + i)}; }
inline void store3(float* x, float* y, float* z, int i, V3 a) {
  store(x + i, a.x);
  store(y + i, a.y);
  store(z + i, a.z);
}

inline vf sel(vi mask, vf a, vf b) { return mask ? a : b; }
inline V3 sel(vi mask, V3 a, V3 b) { return {sel(mask, a.x, b.x), sel(mask, a.y, b.y), sel(mask, a.z, b.z)}; }
inline V3 neg(V3 a) { return {-a.x, -a.y, -a.z}; }
inline V3 add(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 mul(V3 a, V3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline V3 mul(V3 a, vf s) { return {a.x * s, a.y * s, a.z * s}; }
inline V3 broadcast(Vec3 a) { return {splat(a.x), splat(a.y), splat(a.z)}; }
inline vf dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline vf sqrt(vf a) { return vf(_mm_sqrt_ps(__m128(a))); }
inline vf fabs(vf a) { return vf(vi(a) & 0x7fffffff); }
inline vi is_finite(vf a) { return (vi(a) & 0x7f800000) != 0x7f800000; }
inline vi is_black(V3 a) { return (a.x == 0) & (a.y == 0) & (a.z == 0); }
inline vi all_finite(V3 a) { return is_finite(a.x) & is_finite(a.y) & is_finite(a.z); }
// sample_concentric_disk (sampling.h) with sincos_quarter's polynomials (math.h).
inline void concentric_disk(vf ux, vf uy, vf& x, vf& y) {
  const vf one = splat(1.0f);
  vf ox = splat(2.0f) * ux - one, oy = splat(2.0f) * uy - one;
  vi wide = fabs(ox) > fabs(oy);
  vf a = splat(kPi / 4) * sel(wide, oy / ox, ox / oy);
  vf a2 = a * a;
  vf s = a * (one + a2 * (splat(-1.0f / 6) + a2 * (splat(1.0f / 120) + a2 * splat(-1.0f / 5040))));
  vf c = one + a2 * (splat(-0.5f) + a2 * (splat(1.0f / 24) + a2 * (splat(-1.0f / 720) + a2 * splat(1.0f / 40320))));
  vi centre = (ox == 0) & (oy == 0);
  x = sel(centre, vf{}, sel(wide, ox * c, oy * s));
  y = sel(centre, vf{}, sel(wide, ox * s, oy * c));
}
inline vf max0(vf a) { return sel(vf{} < a, a, vf{}); }  // std::max(0.0f, a)

}  // namespace pt::simd
