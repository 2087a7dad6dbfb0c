// The forms the path loop runs in: camera paths in Embree packets or one at a time, diffuse
// vertices and Sobol draws in SIMD lanes or by the generic code, lanes of 8 (AVX2) or 4 (SSE2),
// Embree packets of the CPU's native width or the other. They render the same images, bit for bit
// where the tests say so. A user's render always runs the best form its CPU has: in the renderer
// every form is a constant (loop_forms.cpp). Only the test build of the library (`renderer_forms`,
// the same objects but loop_forms.cpp compiled with PT_LOOP_FORMS) makes them switches, for the
// tests and benchmarks that compare the forms.
#pragma once

namespace pt::forms {

bool packets();      // camera paths many at once, their rays in Embree packets (-H: never)
bool lanes();        // diffuse vertices by the lanes' text (diffuse_lanes.h), packets' draws in lanes
bool use_avx2();     // lanes of 8 in AVX2 where the CPU has it (else 4, SSE2); camera rays too
int packet_width();  // Embree packets of 8 or 16 rays; 0: the CPU's native width

#ifdef PT_LOOP_FORMS
struct Switches {
  bool packets = true, lanes = true, avx2 = true;
  int packet_width = 0;
};
Switches& switches();
// The forms for a scope (one render at a time), back to the defaults after it.
class Scoped {
 public:
  Scoped() = default;
  Scoped(const Scoped&) = delete;
  Scoped& operator=(const Scoped&) = delete;
  ~Scoped() { switches() = {}; }
  Switches* operator->() { return &switches(); }
};
#endif

}  // namespace pt::forms
