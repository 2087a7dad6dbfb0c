// Lanes: the vocabulary the path's physics is written in, at every width, and that physics
// (lane_physics.inc) compiled at each. A lane namespace has the same names at every width:
//
//   F, I, M, V2, V3   a float, an int32, a mask, 2- and 3-vectors of floats, kWidth of each
//   U                 a uint32 (the sampler's hashes: sobol.inc)
//   select(m, a, b)   a where m, else b; and the operators, dot, sqrt, abs, min, max, ...
//
//   lane1  width 1: float, int32_t, bool, Vec2, Vec3 (the scalar code: pt::Frame is lane1::Frame)
//   lane4  width 4: GCC vectors in SSE2, the portable build
//   lane8  width 8: GCC vectors in AVX2, for code that runs after forms::use_avx2()
//
// Each physics function is thus written once and compiled three times: the scalar path calls
// lane1's, the lanes lane4's or lane8's, and every lane computes the scalar bits (the vector
// helpers round as the scalar ones). Templates over the lane type cannot do this: a template
// takes its target (AVX2 or not) from where it is defined, so one defined for portable code would
// compile its eight-wide instances without AVX2 (clang rejects their vector arguments). Each width
// gets its own copy of the text instead, compiled for its target, as Highway's foreach_target and
// Embree's ISA namespaces do. A wider target (AVX-512: lane16) is one more block below.
#pragma once

#include <immintrin.h>

#include <cmath>
#include <cstdint>
#include <cstring>

#include "math.h"
#include "simd.h"

// The lane helpers and the physics are forced inline: the lanes' loops must see whole vector
// expressions, not calls that pass vectors through memory.
#define PT_LANE inline __attribute__((always_inline))

namespace pt::lane1 {

constexpr int kWidth = 1;
using F = float;
using I = int32_t;
using M = bool;
using V2 = Vec2;
using V3 = Vec3;  // its operators, dot, normalize, is_black, is_finite (Vec3) are math.h's

PT_LANE float splat(float f) { return f; }
PT_LANE Vec3 splat(Vec3 a) { return a; }
PT_LANE float load(const float* p) { return *p; }
PT_LANE float loadu(const float* p) { return *p; }
PT_LANE bool load_mask(const int* p) { return *p != 0; }
PT_LANE void store(float* p, float a) { *p = a; }
PT_LANE void store_mask(int* p, bool a) { *p = a ? -1 : 0; }

PT_LANE float select(bool m, float a, float b) { return m ? a : b; }
PT_LANE int32_t select(bool m, int32_t a, int32_t b) { return m ? a : b; }
// Two's-complement sum and negation, wrapping as the vector lanes' integer adds do (a signed
// int32_t overflow would be undefined behaviour: INT32_MIN from a NaN's truncate reaches here).
PT_LANE int32_t wrapping_add(int32_t a, int32_t b) { return int32_t(uint32_t(a) + uint32_t(b)); }
PT_LANE int32_t wrapping_neg(int32_t a) { return int32_t(0u - uint32_t(a)); }
PT_LANE Vec2 select(bool m, Vec2 a, Vec2 b) { return m ? a : b; }
PT_LANE Vec3 select(bool m, Vec3 a, Vec3 b) { return m ? a : b; }

PT_LANE int32_t as_int(float a) {
  int32_t i;
  std::memcpy(&i, &a, 4);
  return i;
}
PT_LANE float as_float(int32_t i) {
  float a;
  std::memcpy(&a, &i, 4);
  return a;
}
PT_LANE bool any(bool m) { return m; }
PT_LANE float sqrt(float a) { return std::sqrt(a); }
// int32_t(a) as cvttss2si computes it, defined for NaN and out-of-range values too (INT32_MIN, as
// the vector lanes' cvttps2dq), where the C++ conversion is undefined behaviour.
PT_LANE int32_t truncate(float a) { return _mm_cvttss_si32(_mm_set_ss(a)); }
PT_LANE float abs(float a) { return std::fabs(a); }
PT_LANE float copysign(float a, float s) { return std::copysign(a, s); }
PT_LANE bool is_finite(float a) { return std::isfinite(a); }
PT_LANE float min(float a, float b) { return std::min(a, b); }
PT_LANE float max(float a, float b) { return std::max(a, b); }

PT_LANE Vec3 load3(const float* x, const float* y, const float* z, int i) { return {x[i], y[i], z[i]}; }
PT_LANE void store3(float* x, float* y, float* z, int i, Vec3 a) { x[i] = a.x, y[i] = a.y, z[i] = a.z; }
PT_LANE Vec2 load2(const Vec2* p) { return *p; }

using U = uint32_t;  // unsigned lanes: the sampler's hashes (sobol.inc)
PT_LANE uint32_t load(const uint32_t* p) { return *p; }
PT_LANE uint32_t reverse_bits(uint32_t x) {
  x = __builtin_bswap32(x);
  x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
  x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
  x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
  return x;
}
PT_LANE float to_float(uint32_t x) { return float(x); }
PT_LANE Vec3 extract(Vec3 a, int) { return a; }

#include "lane_physics.inc"

}  // namespace pt::lane1

namespace pt::lane4 {
#define PT_LANE_WIDTH 4
#include "lane_ops.inc"
#undef PT_LANE_WIDTH
#include "lane_physics.inc"
}  // namespace pt::lane4

PT_BEGIN_AVX2
namespace pt::lane8 {
#define PT_LANE_WIDTH 8
#include "lane_ops.inc"
#undef PT_LANE_WIDTH
#include "lane_physics.inc"
}  // namespace pt::lane8
PT_END_AVX2

namespace pt {
using lane1::Frame;
}  // namespace pt
