// The ray tests and hit refinement Accel runs around Embree, in plain maths (no Embree types, so
// that tests can check them directly against scalar references): Embree's input range, the
// scene-bounds slab test and the hit records of triangles and spheres in SSE (x86-64's baseline,
// as lane_math.h assumes), and the analytic sphere in the lane vocabulary at widths 1 and 4
// (sphere_hit.inc).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstring>
#include <utility>

#include <emmintrin.h>

#include "accel.h"
#include "lane_math.h"
#include "math.h"

namespace pt {

// Embree asserts, aborting the whole process (Debian builds it with assertions), on a ray it deems
// invalid: a NaN, or an origin or direction component beyond FLT_LARGE (1.844e18). A scene with
// coordinates near 1e38 makes such rays (the course camera backs off 1.5 bounding-box diagonals);
// they are treated as misses instead. Found by the scene fuzzer (tests/fuzz-regressions).
inline bool embree_accepts(const Ray& r) {
  constexpr float kLarge = 1.844e18f;
  // Both halves of the ray at once: |o.x o.y o.z d.x| and |d.y d.z tmin tmax| against the limit
  // (infinity for tmin and tmax, which only have to be numbers). A NaN fails every compare.
  static_assert(sizeof(Ray) == 8 * sizeof(float), "Ray is o, d, tmin, tmax without padding");
  const float* f = reinterpret_cast<const float*>(&r);
  const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  const __m128 lo = _mm_and_ps(_mm_loadu_ps(f), abs_mask), hi = _mm_and_ps(_mm_loadu_ps(f + 4), abs_mask);
  const __m128 ok = _mm_and_ps(_mm_cmple_ps(lo, _mm_set1_ps(kLarge)),
                               _mm_cmple_ps(hi, _mm_setr_ps(kLarge, kLarge, INFINITY, INFINITY)));
  return _mm_movemask_ps(ok) == 0xF;
}

// Slab test (Kay & Kajiya, "Ray tracing complex scenes", SIGGRAPH 1986) of the ray's segment
// against a box. Rays that start inside the box (every bounce in a closed scene) pass at once; the
// rest run the slabs branch-free. A NaN from 0 * inf leaves the interval as it was: never a false
// miss. lo and hi hold four floats, the fourth -inf and +inf, so that SSE compares four at once.
inline bool may_hit_bounds(const Ray& r, const float lo[4], const float hi[4]) {
  // max/min written so that a NaN operand yields the other one (the interval is left as it was);
  // SSE's maxps and minps are these exact expressions.
  auto mx = [](float a, float b) { return a > b ? a : b; };
  auto mn = [](float a, float b) { return a < b ? a : b; };
  const float* f = reinterpret_cast<const float*>(&r);
  const __m128 o = _mm_loadu_ps(f), l = _mm_loadu_ps(lo), h = _mm_loadu_ps(hi);  // lane 3: d.x within (-inf, inf)
  if (_mm_movemask_ps(_mm_and_ps(_mm_cmpge_ps(o, l), _mm_cmple_ps(o, h))) == 0xF) return true;
  const __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), _mm_loadu_ps(f + 3));  // 1/d (lane 3: 1/tmin, unused)
  const __m128 a = _mm_mul_ps(_mm_sub_ps(l, o), inv), b = _mm_mul_ps(_mm_sub_ps(h, o), inv);
  alignas(16) float near[4], far[4];
  _mm_store_ps(near, _mm_min_ps(a, b));
  _mm_store_ps(far, _mm_max_ps(a, b));
  const float t0 = mx(mx(mx(r.tmin, near[0]), near[1]), near[2]);
  const float t1 = mn(mn(mn(r.tmax, far[0]), far[1]), far[2]);
  return !(t0 > t1);
}

// The analytic sphere test (sphere_hit.inc) at width 1 and at width 4.
namespace lane1 {
#include "sphere_hit.inc"
}  // namespace lane1
namespace lane4 {
#include "sphere_hit.inc"
}  // namespace lane4

// The nearest root inside (tnear, tfar) of sphere s (centre x y z, radius) along o + t d, if any.
inline bool sphere_hit(const float* s, float ox, float oy, float oz, float dx, float dy, float dz, float tnear,
                       float tfar, float& t) {
  return lane1::sphere_hit(s, true, Vec3(ox, oy, oz), Vec3(dx, dy, dz), tnear, tfar, t);
}

// Four rays in SoA layout (each pointer at four consecutive lanes, as in Embree's packets).
struct RayLanes4 {
  const float *ox, *oy, *oz, *dx, *dy, *dz, *tnear, *tfar;
  const int* valid;  // -1: a lane to test
};

// sphere_hit for four rays at once: the same text, so the same bits. Returns the mask of valid
// lanes with a hit (bit k: lane k), and their t in t[k].
inline int sphere_hit4(const float* s, const RayLanes4& r, float t[4]) {
  using namespace lane4;
  I valid;
  std::memcpy(&valid, r.valid, sizeof valid);  // Embree's lanes: -1 to test, 0 not
  F th;
  const M hit = lane4::sphere_hit(s, valid == -1, {loadu(r.ox), loadu(r.oy), loadu(r.oz)},
                                  {loadu(r.dx), loadu(r.dy), loadu(r.dz)}, loadu(r.tnear), loadu(r.tfar), th);
  std::memcpy(t, &th, sizeof th);
  return lane4::bits(hit);
}

// What a hit on a triangle needs besides its vertices, in one record so that one cache line
// serves the fetch: the unit face normal is computed once at load instead of at every hit.
struct TriangleInfo {
  Vec3 ng;        // normalize(cross(p1 - p0, p2 - p0)); zero for a degenerate triangle
  int material;
  int light;      // -1 unless the triangle is an emitter registered as a light
};
static_assert(offsetof(TriangleInfo, material) == 12 && offsetof(TriangleInfo, light) == 16,
              "TriangleInfo: refine_triangle loads ng with one 16-byte load and copies material and light together");

// A triangle mesh as hit refinement reads it. Positions and normals hold 3 floats a vertex, and
// each vertex must be readable with one 16-byte load (Embree pads its vertex buffers so; Accel
// pads the normals): the SSE form loads x y z and one float beyond.
struct TriangleData {
  const float* positions;
  const uint32_t* indices;
  const float* normals;  // shading normals, or null for a flat mesh
  const TriangleInfo* tris;
  uint32_t geom_id;   // Embree's id of the mesh
  bool attributes;    // the mesh has uvs, colours or tangents (Accel::attributes reads them)
};

// Where a hit lies, for Accel::attributes, on meshes that have attributes.
inline void note_attributes(const TriangleData& m, unsigned prim, float u, float v, SurfaceHit& hit) {
  hit.geom = m.geom_id;
  hit.prim = prim;
  hit.bu = u;
  hit.bv = v;
}

namespace sse {

// normalize() of lanes x y z, with its operations in its order: the same bits (lane 3 is zero or
// garbage).
[[gnu::always_inline]] inline __m128 normalize3(__m128 a) {
  const __m128 sq = _mm_mul_ps(a, a);
  const __m128 d = _mm_add_ss(_mm_add_ss(sq, _mm_shuffle_ps(sq, sq, _MM_SHUFFLE(1, 1, 1, 1))), _mm_movehl_ps(sq, sq));
  const float l = _mm_cvtss_f32(_mm_sqrt_ss(d));
  return l > 0 ? _mm_mul_ps(a, _mm_set1_ps(1.0f / l)) : _mm_setzero_ps();
}
[[gnu::always_inline]] inline bool is_black3(__m128 a) {
  return (_mm_movemask_ps(_mm_cmpeq_ps(a, _mm_setzero_ps())) & 7) == 7;
}
// a0 w + a1 u + a2 v of the vertices' x y z, in the scalar form's order.
[[gnu::always_inline]] inline __m128 interpolate(const float* base, const uint32_t* tri, __m128 w, __m128 u, __m128 v) {
  return _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_loadu_ps(base + 3 * size_t(tri[0])), w),
                               _mm_mul_ps(_mm_loadu_ps(base + 3 * size_t(tri[1])), u)),
                    _mm_mul_ps(_mm_loadu_ps(base + 3 * size_t(tri[2])), v));
}

// The record's three vectors stored 16 bytes at a time, in field order: each store's fourth float
// spills into the next field, which the next store (or the caller's) then writes.
static_assert(offsetof(SurfaceHit, ng) == offsetof(SurfaceHit, p) + 12 &&
                  offsetof(SurfaceHit, ns) == offsetof(SurfaceHit, ng) + 12 &&
                  offsetof(SurfaceHit, material) == offsetof(SurfaceHit, ns) + 12 &&
                  offsetof(SurfaceHit, light) == offsetof(SurfaceHit, material) + 4,
              "SurfaceHit: p, ng, ns, material and light back to back");
[[gnu::always_inline]] inline void store_vectors(SurfaceHit& hit, __m128 p, __m128 ng, __m128 ns) {
  _mm_storeu_ps(&hit.p.x, p);
  _mm_storeu_ps(&hit.ng.x, ng);
  _mm_storeu_ps(&hit.ns.x, ns);
}

}  // namespace sse

// The hit record of a hit on triangle `prim` at t with barycentrics (u, v): the point from the
// barycentrics (not o + t d, which drifts off the plane), the unit face normal (for a degenerate
// triangle, from `eng()`: Embree's unnormalised one), the interpolated shading normal, material,
// light. `Attributes`: the scene has meshes with uvs or colours (false skips even the check). In
// SSE, three floats a register: half the instructions of the scalar form, with its bits (the hit
// loop's refinement was a tenth of a mesh scene's pass; docs/performance.md, "Design choices that
// pay"; tests/test_accel_math.cpp keeps the scalar form as the reference).
template <bool Attributes = true, class EmbreeNormal>
[[gnu::always_inline]] inline void refine_triangle(const TriangleData& m, unsigned prim, float t, float u, float v,
                                                   EmbreeNormal&& eng, SurfaceHit& hit) {
  (void)t;  // the point comes from the barycentrics
  const uint32_t* tri = m.indices + 3 * size_t(prim);
  const TriangleInfo& info = m.tris[prim];
  const __m128 W = _mm_set1_ps(1 - u - v), U = _mm_set1_ps(u), V = _mm_set1_ps(v);
  const __m128 p = sse::interpolate(m.positions, tri, W, U, V);
  __m128 ng = _mm_loadu_ps(&info.ng.x);  // ng and the material's bits in lane 3
  if (__builtin_expect(sse::is_black3(ng), 0)) {
    Vec3 n = normalize(eng());
    if (is_black(n)) n = Vec3(0, 1, 0);
    ng = _mm_setr_ps(n.x, n.y, n.z, 0);
  }
  __m128 ns = ng;
  if (m.normals) {
    const __m128 n = sse::normalize3(sse::interpolate(m.normals, tri, W, U, V));
    if (!sse::is_black3(n)) ns = n;
  }
  sse::store_vectors(hit, p, ng, ns);
  std::memcpy(&hit.material, &info.material, 2 * sizeof(int));  // material and light, adjacent in both
  hit.offset = 0;
  if (Attributes && m.attributes) note_attributes(m, prim, u, v, hit);
}

// The hit record of a hit on sphere s (centre x y z, radius) at t: the point re-projected onto the
// sphere, which removes the error of o + t d, and the outward normal. In SSE, with the scalar
// form's bits (tests/test_accel_math.cpp).
[[gnu::always_inline]] inline void refine_sphere(const float* s, int material, const Ray& ray, float t,
                                                 SurfaceHit& hit) {
  static_assert(sizeof(Ray) == 8 * sizeof(float), "Ray is o, d, tmin, tmax without padding");
  const __m128 sphere = _mm_loadu_ps(s);  // centre, radius
  const __m128 o = _mm_loadu_ps(&ray.o.x), d = _mm_loadu_ps(&ray.d.x);
  __m128 n = sse::normalize3(_mm_sub_ps(_mm_add_ps(o, _mm_mul_ps(d, _mm_set1_ps(t))), sphere));
  if (sse::is_black3(n)) n = _mm_setr_ps(0, 1, 0, 0);
  const float r = s[3];
  sse::store_vectors(hit, _mm_add_ps(sphere, _mm_mul_ps(n, _mm_set1_ps(r))), n, n);
  hit.material = material;
  hit.light = -1;
  // The sphere test loses ~ulp(r)/cos near the surface; push far enough to clear it.
  hit.offset = 1e-5f * r;
}

// A uniform number in [0, 1) from a ray and a triangle: the same ray meets the same triangle with
// the same answer (packets and single rays agree, renders repeat), different rays independently.
inline uint32_t mix32(uint32_t h) {  // a 32-bit finaliser (Wellons' "lowbias32")
  h ^= h >> 16, h *= 0x7feb352du, h ^= h >> 15, h *= 0x846ca68bu, h ^= h >> 16;
  return h;
}
inline float ray_uniform(const float* f, int n, uint32_t prim) {
  uint32_t h = mix32(prim * 0x9e3779b9u + 1);
  for (int i = 0; i < n; ++i) {
    uint32_t bits;
    std::memcpy(&bits, &f[i], 4);
    h = mix32(h ^ bits);
  }
  return float(h >> 8) * 0x1p-24f;
}

}  // namespace pt
