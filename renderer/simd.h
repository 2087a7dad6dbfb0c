// Four floats at a time with GCC vector extensions on SSE2 (the portable build's vectors), for
// the loops that repeat scalar code lane by lane (diffuse_lanes.cpp, Camera::pinhole_rays). The
// helpers are in simd_ops.inc, which diffuse_lanes.cpp also instantiates eight wide for AVX2.
#pragma once

#include <immintrin.h>

#include <cstdint>

#include "math.h"

namespace pt::simd {

#define PT_SIMD_WIDTH 4
#include "simd_ops.inc"
#undef PT_SIMD_WIDTH

// Whether this CPU runs AVX2 (the code paths that use it dispatch on this).
inline bool avx2_available() {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
}

}  // namespace pt::simd
