// Diffuse vertices in SSE2 or AVX2 lanes (see diffuse_lanes.h); the code is diffuse_lanes_body.inc,
// compiled once per width. Every expression keeps the scalar code's operation order (a dot product
// is (x x' + y y') + z z', a / s is a * (1 / s)), and the vector add, multiply, divide and square
// root round as the scalar instructions do, so each lane computes the scalar path_step's bits. No
// FMA: the portable build has none, and contraction would change them.
#include "diffuse_lanes.h"

#include "simd.h"
#include "simd8.h"

// SSE2: four lanes, the portable build.
namespace pt::lanes::sse2 {
using namespace pt::simd;
#include "diffuse_lanes_body.inc"
}  // namespace pt::lanes::sse2

// AVX2: eight lanes, for the CPUs that have it (simd8.h, PT_BEGIN_AVX2 in simd.h).
PT_BEGIN_AVX2
namespace pt::lanes::avx2 {
using namespace pt::simd8;
#include "diffuse_lanes_body.inc"
}  // namespace pt::lanes::avx2
PT_END_AVX2

namespace pt::lanes {

using simd::use_avx2;

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
