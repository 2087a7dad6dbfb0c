// Diffuse vertices in SSE2 or AVX2 lanes (see diffuse_lanes.h); the code is diffuse_lanes_body.inc,
// compiled once per width. Every expression keeps the scalar code's operation order (a dot product
// is (x x' + y y') + z z', a / s is a * (1 / s)), and the vector add, multiply, divide and square
// root round as the scalar instructions do, so each lane computes the scalar path_step's bits. No
// FMA: the portable build has none, and contraction would change them.
#include "diffuse_lanes.h"

#include "simd.h"

// SSE2: four lanes, the portable build.
namespace pt::lanes::sse2 {
using namespace pt::simd;
#include "diffuse_lanes_body.inc"
}  // namespace pt::lanes::sse2

// AVX2: eight lanes, for the CPUs that have it. Everything in this region is compiled for AVX2 (a
// target pragma for GCC, an attribute pragma for clang, which the sanitizer build uses) and
// lives in its own namespaces, so no inline function of a header gets an AVX2 copy that the linker
// could pick for the portable code. AVX2 without FMA: the same roundings as SSE2.
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace pt::simd8 {
#define PT_SIMD_WIDTH 8
#include "simd_ops.inc"
#undef PT_SIMD_WIDTH
}  // namespace pt::simd8
namespace pt::lanes::avx2 {
using namespace pt::simd8;
#include "diffuse_lanes_body.inc"
}  // namespace pt::lanes::avx2
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

namespace pt::lanes {

namespace {
bool g_allow_avx2 = true;
bool use_avx2() { return g_allow_avx2 && simd::avx2_available(); }
}  // namespace

void allow_avx2(bool allow) { g_allow_avx2 = allow; }
int lane_width() { return use_avx2() ? 8 : 4; }

void light_pass(DiffuseVertices& v, int n, const Light& light, int samples) {
  if (use_avx2()) return avx2::light_pass(v, n, light, samples);
  sse2::light_pass(v, n, light, samples);
}

void bounce_pass(DiffuseVertices& v, int n) {
  if (use_avx2()) return avx2::bounce_pass(v, n);
  sse2::bounce_pass(v, n);
}

}  // namespace pt::lanes
