// The ray tests and hit refinement Accel runs around Embree, in plain maths (no Embree types, so
// that tests can check them directly): Embree's input range, the scene-bounds slab test, the
// analytic sphere and the hit records of triangles and spheres, each with an SSE form that gives
// the scalar form's bits.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstring>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "accel.h"
#include "math.h"

namespace pt {

// Embree asserts, aborting the whole process (Debian builds it with assertions), on a ray it deems
// invalid: a NaN, or an origin or direction component beyond FLT_LARGE (1.844e18). A scene with
// coordinates near 1e38 makes such rays (the course camera backs off 1.5 bounding-box diagonals);
// they are treated as misses instead. Found by the scene fuzzer (tests/fuzz-regressions).
inline bool embree_accepts(const Ray& r) {
  constexpr float kLarge = 1.844e18f;
#if defined(__SSE2__)
  // Both halves of the ray at once: |o.x o.y o.z d.x| and |d.y d.z tmin tmax| against the limit
  // (infinity for tmin and tmax, which only have to be numbers). A NaN fails every compare.
  static_assert(sizeof(Ray) == 8 * sizeof(float), "Ray is o, d, tmin, tmax without padding");
  const float* f = reinterpret_cast<const float*>(&r);
  const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  const __m128 lo = _mm_and_ps(_mm_loadu_ps(f), abs_mask), hi = _mm_and_ps(_mm_loadu_ps(f + 4), abs_mask);
  const __m128 ok = _mm_and_ps(_mm_cmple_ps(lo, _mm_set1_ps(kLarge)),
                               _mm_cmple_ps(hi, _mm_setr_ps(kLarge, kLarge, INFINITY, INFINITY)));
  return _mm_movemask_ps(ok) == 0xF;
#else
  return std::fabs(r.o.x) <= kLarge && std::fabs(r.o.y) <= kLarge && std::fabs(r.o.z) <= kLarge &&
         std::fabs(r.d.x) <= kLarge && std::fabs(r.d.y) <= kLarge && std::fabs(r.d.z) <= kLarge &&
         !std::isnan(r.tmin) && !std::isnan(r.tmax);
#endif
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
#if defined(__SSE2__)
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
#else
  if (r.o.x >= lo[0] && r.o.x <= hi[0] && r.o.y >= lo[1] && r.o.y <= hi[1] && r.o.z >= lo[2] && r.o.z <= hi[2])
    return true;
  const float ix = 1.0f / r.d.x, iy = 1.0f / r.d.y, iz = 1.0f / r.d.z;
  const float ax = (lo[0] - r.o.x) * ix, bx = (hi[0] - r.o.x) * ix;
  const float ay = (lo[1] - r.o.y) * iy, by = (hi[1] - r.o.y) * iy;
  const float az = (lo[2] - r.o.z) * iz, bz = (hi[2] - r.o.z) * iz;
  const float t0 = mx(mx(mx(r.tmin, mn(ax, bx)), mn(ay, by)), mn(az, bz));
  const float t1 = mn(mn(mn(r.tmax, mx(ax, bx)), mx(ay, by)), mx(az, bz));
#endif
  return !(t0 > t1);
}

// Spheres are Embree user geometry with this analytic test, not RTC_GEOMETRY_TYPE_SPHERE_POINT:
// Embree's sphere points are built for many small spheres (point clouds), and on the course's few
// large spheres they cost more than a scalar quadratic. The roots follow Haines et al., "Precision
// Improvements for Ray/Sphere Intersection", Ray Tracing Gems ch. 7 (2019): the discriminant from
// the distance of the centre to the ray line, and the smaller root from c / q, which avoid the
// cancellation of the textbook formula far from the sphere and for rays that graze it.
// s: centre x y z and radius.
inline bool sphere_roots(const float* s, float ox, float oy, float oz, float dx, float dy, float dz, float& t0,
                         float& t1) {
  float fx = ox - s[0], fy = oy - s[1], fz = oz - s[2], r = s[3];
  float a = dx * dx + dy * dy + dz * dz;
  float b = -(fx * dx + fy * dy + fz * dz);  // b' = -f.d
  float k = b / a;
  float lx = fx + k * dx, ly = fy + k * dy, lz = fz + k * dz;  // centre-to-line offset
  float disc = a * (r * r - (lx * lx + ly * ly + lz * lz));
  if (!(disc >= 0) || !(a > 0)) return false;
  float c = fx * fx + fy * fy + fz * fz - r * r;
  float q = b + std::copysign(std::sqrt(disc), b);
  t0 = q != 0 ? c / q : 0;
  t1 = q / a;
  if (t0 > t1) std::swap(t0, t1);
  return true;
}

// The nearest root of sphere_roots inside (tnear, tfar), if any.
inline bool sphere_hit(const float* s, float ox, float oy, float oz, float dx, float dy, float dz, float tnear,
                       float tfar, float& t) {
  float t0, t1;
  if (!sphere_roots(s, ox, oy, oz, dx, dy, dz, t0, t1)) return false;
  t = t0 > tnear ? t0 : t1;
  return t > tnear && t < tfar;
}

// Four rays in SoA layout (each pointer at four consecutive lanes, as in Embree's packets).
struct RayLanes4 {
  const float *ox, *oy, *oz, *dx, *dy, *dz, *tnear, *tfar;
  const int* valid;  // -1: a lane to test
};

// sphere_hit for four rays at once: the same operations in the same order, so the same bits.
// Returns the mask of valid lanes with a hit (bit k: lane k), and their t in t[k].
inline int sphere_hit4(const float* s, const RayLanes4& r, float t[4]) {
#if defined(__SSE2__)
  const __m128 valid = _mm_castsi128_ps(
      _mm_cmpeq_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(r.valid)), _mm_set1_epi32(-1)));
  if (_mm_movemask_ps(valid) == 0) return 0;
  const __m128 dx = _mm_loadu_ps(r.dx), dy = _mm_loadu_ps(r.dy), dz = _mm_loadu_ps(r.dz);
  const __m128 fx = _mm_sub_ps(_mm_loadu_ps(r.ox), _mm_set1_ps(s[0]));
  const __m128 fy = _mm_sub_ps(_mm_loadu_ps(r.oy), _mm_set1_ps(s[1]));
  const __m128 fz = _mm_sub_ps(_mm_loadu_ps(r.oz), _mm_set1_ps(s[2]));
  const __m128 radius = _mm_set1_ps(s[3]), rr = _mm_mul_ps(radius, radius), zero = _mm_setzero_ps();
  const __m128 sign = _mm_set1_ps(-0.0f);
  auto dot = [](__m128 ax, __m128 ay, __m128 az, __m128 bx, __m128 by, __m128 bz) {
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(ax, bx), _mm_mul_ps(ay, by)), _mm_mul_ps(az, bz));
  };
  const __m128 a = dot(dx, dy, dz, dx, dy, dz);
  const __m128 b = _mm_xor_ps(dot(fx, fy, fz, dx, dy, dz), sign);
  const __m128 k = _mm_div_ps(b, a);
  const __m128 lx = _mm_add_ps(fx, _mm_mul_ps(k, dx)), ly = _mm_add_ps(fy, _mm_mul_ps(k, dy)),
               lz = _mm_add_ps(fz, _mm_mul_ps(k, dz));
  const __m128 disc = _mm_mul_ps(a, _mm_sub_ps(rr, dot(lx, ly, lz, lx, ly, lz)));
  __m128 ok = _mm_and_ps(valid, _mm_and_ps(_mm_cmpge_ps(disc, zero), _mm_cmpgt_ps(a, zero)));
  if (_mm_movemask_ps(ok) == 0) return 0;
  const __m128 c = _mm_sub_ps(dot(fx, fy, fz, fx, fy, fz), rr);
  const __m128 q = _mm_add_ps(b, _mm_or_ps(_mm_sqrt_ps(disc), _mm_and_ps(b, sign)));  // b + copysign(sqrt, b)
  const __m128 t0q = _mm_and_ps(_mm_div_ps(c, q), _mm_cmpneq_ps(q, zero));         // q != 0 ? c / q : 0
  const __m128 t1q = _mm_div_ps(q, a);
  const __m128 t0 = _mm_min_ps(t1q, t0q), t1 = _mm_max_ps(t0q, t1q);  // if (t0 > t1) swap
  const __m128 tnear = _mm_loadu_ps(r.tnear), tfar = _mm_loadu_ps(r.tfar);
  const __m128 first = _mm_cmpgt_ps(t0, tnear);
  const __m128 th = _mm_or_ps(_mm_and_ps(first, t0), _mm_andnot_ps(first, t1));  // t0 > tnear ? t0 : t1
  ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpgt_ps(th, tnear), _mm_cmplt_ps(th, tfar)));
  _mm_storeu_ps(t, th);
  return _mm_movemask_ps(ok);
#else
  int mask = 0;
  for (int k = 0; k < 4; ++k)
    if (r.valid[k] == -1 && sphere_hit(s, r.ox[k], r.oy[k], r.oz[k], r.dx[k], r.dy[k], r.dz[k], r.tnear[k], r.tfar[k], t[k]))
      mask |= 1 << k;
  return mask;
#endif
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

// The hit record of a hit on triangle `prim` at t with barycentrics (u, v): the point from the
// barycentrics (not o + t d, which drifts off the plane), the unit face normal (for a degenerate
// triangle, from `eng()`: Embree's unnormalised one), the interpolated shading normal, material, light.
// `Attributes`: the scene has meshes with uvs or colours (false skips even the check).
template <bool Attributes = true, class EmbreeNormal>
inline void refine_triangle_scalar(const TriangleData& m, unsigned prim, float t, float u, float v, EmbreeNormal&& eng,
                                   SurfaceHit& hit) {
  (void)t;  // the point comes from the barycentrics
  const uint32_t* tri = m.indices + 3 * size_t(prim);
  const TriangleInfo& info = m.tris[prim];
  auto at = [&](const float* base, uint32_t i) { return Vec3(base[3 * size_t(i)], base[3 * size_t(i) + 1], base[3 * size_t(i) + 2]); };
  const float w = 1 - u - v;
  hit.p = at(m.positions, tri[0]) * w + at(m.positions, tri[1]) * u + at(m.positions, tri[2]) * v;
  Vec3 ng = info.ng;
  if (is_black(ng)) {
    ng = normalize(eng());
    if (is_black(ng)) ng = Vec3(0, 1, 0);
  }
  hit.ng = ng;
  hit.ns = ng;
  if (m.normals) {
    Vec3 ns = normalize(at(m.normals, tri[0]) * w + at(m.normals, tri[1]) * u + at(m.normals, tri[2]) * v);
    if (!is_black(ns)) hit.ns = ns;
  }
  hit.material = info.material;
  hit.light = info.light;
  hit.offset = 0;
  if (Attributes && m.attributes) note_attributes(m, prim, u, v, hit);
}

// The hit record of a hit on sphere s (centre x y z, radius) at t: the point re-projected onto the
// sphere, which removes the error of o + t d, and the outward normal.
inline void refine_sphere_scalar(const float* s, int material, const Ray& ray, float t, SurfaceHit& hit) {
  const Vec3 c(s[0], s[1], s[2]);
  const float r = s[3];
  Vec3 n = normalize(ray.o + ray.d * t - c);
  if (is_black(n)) n = Vec3(0, 1, 0);
  hit.p = c + n * r;
  hit.ng = hit.ns = n;
  hit.material = material;
  hit.light = -1;
  // Embree's sphere test loses ~ulp(r)/cos near the surface; push far enough to clear it.
  hit.offset = 1e-5f * r;
}

#if defined(__SSE2__)
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
#endif

// refine_triangle_scalar's record with SSE: its bits, in about half the instructions (the hit
// loop's refinement was a tenth of a mesh scene's pass; docs/performance.md, "Design choices that pay").
template <bool Attributes = true, class EmbreeNormal>
[[gnu::always_inline]] inline void refine_triangle(const TriangleData& m, unsigned prim, float t, float u, float v,
                                                   EmbreeNormal&& eng, SurfaceHit& hit) {
#if defined(__SSE2__)
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
#else
  refine_triangle_scalar<Attributes>(m, prim, t, u, v, eng, hit);
#endif
}

// refine_sphere_scalar's record with SSE: its bits.
[[gnu::always_inline]] inline void refine_sphere(const float* s, int material, const Ray& ray, float t,
                                                 SurfaceHit& hit) {
#if defined(__SSE2__)
  static_assert(sizeof(Ray) == 8 * sizeof(float), "Ray is o, d, tmin, tmax without padding");
  const __m128 sphere = _mm_loadu_ps(s);  // centre, radius
  const __m128 o = _mm_loadu_ps(&ray.o.x), d = _mm_loadu_ps(&ray.d.x);
  __m128 n = sse::normalize3(_mm_sub_ps(_mm_add_ps(o, _mm_mul_ps(d, _mm_set1_ps(t))), sphere));
  if (sse::is_black3(n)) n = _mm_setr_ps(0, 1, 0, 0);
  const float r = s[3];
  sse::store_vectors(hit, _mm_add_ps(sphere, _mm_mul_ps(n, _mm_set1_ps(r))), n, n);
  hit.material = material;
  hit.light = -1;
  hit.offset = 1e-5f * r;
#else
  refine_sphere_scalar(s, material, ray, t, hit);
#endif
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
