// Which vector lanes this CPU runs: the dispatch between the lanes of lane_math.h (SSE2, the
// portable build, and AVX2 where the CPU has it), and the pragmas that compile code for AVX2.
#pragma once

namespace pt::simd {

// Whether this CPU runs AVX2 (the code paths that use it dispatch on this).
inline bool avx2_available() {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
}

}  // namespace pt::simd

// Code between these is compiled for AVX2: a target pragma for GCC, an attribute pragma for clang
// (which the sanitizer build uses). Keep such code in namespaces of its own (see lane_math.h), so
// that no inline function of a header gets an AVX2 copy that the linker could pick for the
// portable code. AVX2 without FMA: the same roundings as SSE2.
#if defined(__clang__)
#define PT_BEGIN_AVX2 _Pragma("clang attribute push(__attribute__((target(\"avx2\"))), apply_to = function)")
#define PT_END_AVX2 _Pragma("clang attribute pop")
#else
#define PT_BEGIN_AVX2 _Pragma("GCC push_options") _Pragma("GCC target(\"avx2\")")
#define PT_END_AVX2 _Pragma("GCC pop_options")
#endif
