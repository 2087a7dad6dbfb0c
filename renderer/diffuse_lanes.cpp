// Diffuse vertices in SSE2 or AVX2 lanes (see diffuse_lanes.h): diffuse_lanes_body.inc, compiled
// in lane_math.h's lane4 and lane8 namespaces. The scalar path_step runs the same text in lane1,
// so each lane computes its bits.
#include "diffuse_lanes.h"

#include "lane_math.h"
#include "loop_forms.h"

// SSE2: four lanes, the portable build.
namespace pt::lane4 {
using lanes::DiffuseVerticesN;
#include "diffuse_lanes_body.inc"
}  // namespace pt::lane4

// AVX2: eight lanes, for the CPUs that have it (PT_BEGIN_AVX2 in simd.h).
PT_BEGIN_AVX2
namespace pt::lane8 {
using lanes::DiffuseVerticesN;
#include "diffuse_lanes_body.inc"
}  // namespace pt::lane8
PT_END_AVX2

namespace pt::lanes {

using forms::use_avx2;

int lane_width() { return use_avx2() ? 8 : 4; }

void light_pass(DiffuseVertices& v, int n, const Light& light, int samples) {
  if (use_avx2()) return lane8::light_pass(v, n, light, samples);
  lane4::light_pass(v, n, light, samples);
}

void bounce_pass(DiffuseVertices& v, int n) {
  if (use_avx2()) return lane8::bounce_pass(v, n);
  lane4::bounce_pass(v, n);
}

}  // namespace pt::lanes
