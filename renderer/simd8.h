// Eight floats at a time in AVX2: simd_ops.inc's helpers in pt::simd8, compiled for AVX2. Only
// code that runs after simd::use_avx2() may call them; see PT_BEGIN_AVX2 in simd.h.
#pragma once

#include "simd.h"

PT_BEGIN_AVX2
namespace pt::simd8 {
#define PT_SIMD_WIDTH 8
#include "simd_ops.inc"
#undef PT_SIMD_WIDTH
}  // namespace pt::simd8
PT_END_AVX2
