// Accel's ray tests around Embree (renderer/accel_math.h) checked directly: the SSE forms give the
// scalar forms' bits, on random rays and on the cases where floats go wrong (NaN, infinities,
// rays parallel to a slab, grazing and inside a sphere, lanes switched off).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "accel_math.h"

using namespace pt;

namespace {

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The definition embree_accepts implements: every component within +-1.844e18, tmin and tmax numbers.
bool accepts_reference(const Ray& r) {
  const float k = 1.844e18f;
  const float v[6] = {r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z};
  for (float x : v)
    if (!(std::fabs(x) <= k)) return false;
  return !std::isnan(r.tmin) && !std::isnan(r.tmax);
}

// The scalar forms of refine_triangle and refine_sphere, the references their SSE must match bit
// for bit. The hit record of a hit on triangle `prim` at t with barycentrics (u, v): the point from the
// barycentrics (not o + t d, which drifts off the plane), the unit face normal (for a degenerate
// triangle, from `eng()`: Embree's unnormalised one), the interpolated shading normal, material, light.
// `Attributes`: the scene has meshes with uvs or colours (false skips even the check).
template <bool Attributes = true, class EmbreeNormal>
void refine_triangle_scalar(const TriangleData& m, unsigned prim, float t, float u, float v, EmbreeNormal&& eng,
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
void refine_sphere_scalar(const float* s, int material, const Ray& ray, float t, SurfaceHit& hit) {
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

// The scalar slab test, written out (Kay & Kajiya), with the NaN-skipping max and min.
bool bounds_reference(const Ray& r, const float lo[3], const float hi[3]) {
  auto mx = [](float a, float b) { return a > b ? a : b; };
  auto mn = [](float a, float b) { return a < b ? a : b; };
  if (r.o.x >= lo[0] && r.o.x <= hi[0] && r.o.y >= lo[1] && r.o.y <= hi[1] && r.o.z >= lo[2] && r.o.z <= hi[2])
    return true;
  float t0 = r.tmin, t1 = r.tmax;
  const float o[3] = {r.o.x, r.o.y, r.o.z}, d[3] = {r.d.x, r.d.y, r.d.z};
  for (int k = 0; k < 3; ++k) {
    const float inv = 1.0f / d[k], a = (lo[k] - o[k]) * inv, b = (hi[k] - o[k]) * inv;
    t0 = mx(t0, mn(a, b));
    t1 = mn(t1, mx(a, b));
  }
  return !(t0 > t1);
}

// A value from a mix of ordinary numbers and the ones that break arithmetic.
float wild(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-4.f, 4.f);
  switch (rng() % 12) {
    case 0: return NAN;
    case 1: return INFINITY;
    case 2: return -INFINITY;
    case 3: return 0.0f;
    case 4: return -0.0f;
    case 5: return (rng() % 2 ? 1 : -1) * 1.844e18f;
    case 6: return (rng() % 2 ? 1 : -1) * 1.845e18f;
    default: return u(rng);
  }
}

}  // namespace

TEST(AccelMath, EmbreeAcceptsExactlyItsRange) {
  std::mt19937 rng(3);
  int accepted = 0, refused = 0;
  for (int i = 0; i < 200000; ++i) {
    Ray r;
    r.o = Vec3(wild(rng), wild(rng), wild(rng));
    r.d = Vec3(wild(rng), wild(rng), wild(rng));
    r.tmin = wild(rng);
    r.tmax = wild(rng);
    const bool want = accepts_reference(r);
    ASSERT_EQ(embree_accepts(r), want) << "ray " << i;
    (want ? accepted : refused)++;
  }
  EXPECT_GT(accepted, 1000);
  EXPECT_GT(refused, 1000);
}

TEST(AccelMath, BoundsTestGivesTheScalarSlabsAnswer) {
  const float lo[4] = {-1, -0.5f, 2, -INFINITY}, hi[4] = {1, 0.5f, 3, INFINITY};
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-6.f, 6.f);
  int hits = 0, misses = 0;
  for (int i = 0; i < 200000; ++i) {
    Ray r;
    r.o = Vec3(u(rng), u(rng), u(rng));
    r.d = Vec3(u(rng), u(rng), u(rng));
    if (i % 2 == 0) r.d = Vec3(0.2f * u(rng), 0.1f * u(rng), 2.5f + 0.1f * u(rng)) - r.o;  // aimed near the box
    if (i % 5 == 0) r.d[int(rng() % 3)] = 0;                         // parallel to a slab: 0 * inf
    if (i % 7 == 0) r.o[int(rng() % 3)] = i % 2 ? lo[i % 3] : hi[i % 3];  // on a face
    if (i % 11 == 0) r.d[int(rng() % 3)] = wild(rng);
    r.tmin = i % 3 == 0 ? u(rng) : 0;
    r.tmax = i % 2 ? kInf : std::fabs(u(rng));
    const bool want = bounds_reference(r, lo, hi);
    ASSERT_EQ(may_hit_bounds(r, lo, hi), want) << "ray " << i;
    (want ? hits : misses)++;
  }
  EXPECT_GT(hits, 20000);
  EXPECT_GT(misses, 20000);
}

namespace {
// a * b + c where the compiler may use FMA: one rounding if it contracts, two if it does not.
__attribute__((target("fma"), noinline)) float mul_add(float a, float b, float c) { return a * b + c; }
}  // namespace

// The build keeps products and sums as written (-ffp-contract=off, CMakeLists.txt) even in code
// compiled for FMA, as -march=native compiles the renderer: the lanes' bit-for-bit tests rely on it.
TEST(AccelMath, ProductsAndSumsRoundAsWritten) {
  if (!__builtin_cpu_supports("fma")) GTEST_SKIP() << "no FMA on this CPU";
  const float a = 1.0f + 0x1p-12f;  // a * a = 1 + 2^-11 + 2^-24: the last term is lost when rounded
  EXPECT_EQ(mul_add(a, a, -(1.0f + 0x1p-11f)), 0.0f) << "a * b + c was fused into one FMA";
}

TEST(AccelMath, FourSphereTestsAtOnceGiveTheScalarTestsBits) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  int hits = 0, misses = 0;
  for (int group = 0; group < 50000; ++group) {
    const float s[4] = {3 * u(rng), 3 * u(rng), 3 * u(rng), 0.1f + std::fabs(2 * u(rng))};
    float ox[4], oy[4], oz[4], dx[4], dy[4], dz[4], tnear[4], tfar[4];
    int valid[4];
    for (int k = 0; k < 4; ++k) {
      const int kind = int(rng() % 6);
      Vec3 o(4 * u(rng), 4 * u(rng), 4 * u(rng)), target(s[0] + s[3] * u(rng), s[1] + s[3] * u(rng), s[2] + s[3] * u(rng));
      if (kind == 1) o = Vec3(s[0], s[1], s[2]) + Vec3(0.5f * s[3] * u(rng), 0.5f * s[3] * u(rng), 0);  // inside
      Vec3 d = (target - o) * (0.25f + std::fabs(u(rng)));  // unnormalised
      if (kind == 2) {  // grazing: through a point on the sphere, perpendicular to its radius there
        Vec3 n = normalize(Vec3(u(rng), u(rng), u(rng)) + Vec3(0, 0, 1e-3f));
        Vec3 side = normalize(cross(n, Vec3(0.3f, 0.5f, 0.8f)));
        o = Vec3(s[0], s[1], s[2]) + n * s[3] - side * 5.0f;
        d = side;
      }
      if (kind == 3) d = Vec3(0.0f);
      if (kind == 4) d[int(rng() % 3)] = wild(rng);
      ox[k] = o.x, oy[k] = o.y, oz[k] = o.z, dx[k] = d.x, dy[k] = d.y, dz[k] = d.z;
      tnear[k] = rng() % 4 == 0 ? std::fabs(u(rng)) : 0;
      tfar[k] = rng() % 3 == 0 ? 0.5f + 4 * std::fabs(u(rng)) : INFINITY;
      valid[k] = kind == 5 ? 0 : -1;
    }
    float t4[4];
    const int mask = sphere_hit4(s, {ox, oy, oz, dx, dy, dz, tnear, tfar, valid}, t4);
    for (int k = 0; k < 4; ++k) {
      float t = 0;
      const bool want =
          valid[k] == -1 && sphere_hit(s, ox[k], oy[k], oz[k], dx[k], dy[k], dz[k], tnear[k], tfar[k], t);
      ASSERT_EQ((mask >> k) & 1, want ? 1 : 0) << "group " << group << " lane " << k;
      if (want) ASSERT_TRUE(same_bits(t4[k], t)) << "group " << group << " lane " << k << ": " << t4[k] << " vs " << t;
      (want ? hits : misses)++;
    }
  }
  EXPECT_GT(hits, 30000);
  EXPECT_GT(misses, 30000);
}

namespace {

bool same_record(const SurfaceHit& a, const SurfaceHit& b) {
  const float fa[] = {a.p.x, a.p.y, a.p.z, a.ng.x, a.ng.y, a.ng.z, a.ns.x, a.ns.y, a.ns.z, a.offset};
  const float fb[] = {b.p.x, b.p.y, b.p.z, b.ng.x, b.ng.y, b.ng.z, b.ns.x, b.ns.y, b.ns.z, b.offset};
  for (size_t k = 0; k < sizeof fa / sizeof fa[0]; ++k)
    if (!same_bits(fa[k], fb[k])) return false;
  return a.material == b.material && a.light == b.light;
}

}  // namespace

// refine_triangle's SSE loads read one float past each vertex, and it stores 16 bytes at a time
// into the record: the records must still match the scalar form's bits field by field, for flat
// and smooth meshes, degenerate triangles (the face normal from Embree's) and shading normals
// that cancel out (the face normal instead).
TEST(AccelMath, TriangleRefinementGivesTheScalarRecordsBits) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> u01(0.f, 1.f), u(-3.f, 3.f);
  const size_t nv = 64;
  std::vector<float> positions(3 * nv + 1), normals(3 * nv + 1);  // one float of padding, as Accel keeps
  for (size_t i = 0; i < 3 * nv; ++i) positions[i] = u(rng), normals[i] = u(rng);
  for (size_t i = 0; i < 3; ++i) positions[3 * 5 + i] = positions[3 * 4 + i];  // vertices 4 and 5 coincide
  for (size_t i = 0; i < 3; ++i) normals[3 * 7 + i] = -normals[3 * 6 + i];     // normals 6 and 7 cancel
  std::vector<uint32_t> indices;
  std::vector<TriangleInfo> tris;
  for (int t = 0; t < 400; ++t) {
    uint32_t a = rng() % nv, b = rng() % nv, c = rng() % nv;
    if (t % 10 == 0) a = 4, b = 5;  // degenerate: two corners at one point
    if (t % 10 == 1) a = 6, b = 7;  // the shading normal cancels halfway along edge ab
    if (t == 399) a = b = c = uint32_t(nv - 1);  // the last vertex: its load reaches the padding
    indices.insert(indices.end(), {a, b, c});
    auto P = [&](uint32_t i) { return Vec3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]); };
    tris.push_back({normalize(cross(P(b) - P(a), P(c) - P(a))), int(rng() % 5), t % 3 == 0 ? int(rng() % 4) : -1});
  }
  int degenerate = 0, cancelled = 0;
  for (const float* shading : {static_cast<const float*>(nullptr), static_cast<const float*>(normals.data())}) {
    const TriangleData mesh{positions.data(), indices.data(), shading, tris.data(), 0, false};
    for (int k = 0; k < 20000; ++k) {
      const unsigned prim = rng() % tris.size();
      float bu = u01(rng), bv = u01(rng);
      if (bu + bv > 1) bu = 1 - bu, bv = 1 - bv;
      if (k % 7 == 0) bu = 0.5f, bv = 0;  // halfway along the first edge
      const float t = 10 * u01(rng);
      const Vec3 eng = k % 5 == 0 ? Vec3(0.0f) : Vec3(u(rng), u(rng), u(rng));  // a zero one: the fallback's fallback
      SurfaceHit fast, slow;
      refine_triangle(mesh, prim, t, bu, bv, [&] { return eng; }, fast);
      refine_triangle_scalar(mesh, prim, t, bu, bv, [&] { return eng; }, slow);
      ASSERT_TRUE(same_record(fast, slow)) << "triangle " << prim << " at (" << bu << ", " << bv << ")";
      degenerate += is_black(tris[prim].ng);
      if (shading && prim % 10 == 1 && k % 7 == 0) {  // the normals cancel: the face normal shades
        ASSERT_EQ(slow.ns, slow.ng);
        ++cancelled;
      }
    }
  }
  EXPECT_GT(degenerate, 1000);
  EXPECT_GT(cancelled, 100);  // about 20000 / 7 / 10
}

// refine_sphere's record against the scalar form's, including a hit at the very centre (no
// direction to normalise: the fallback normal) and rays far from the origin.
TEST(AccelMath, SphereRefinementGivesTheScalarRecordsBits) {
  std::mt19937 rng(22);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  for (int k = 0; k < 50000; ++k) {
    const float scale = k % 4 == 0 ? 1e4f : 1.0f;
    const float s[4] = {scale * u(rng), scale * u(rng), scale * u(rng), 0.01f + std::fabs(scale * u(rng))};
    Ray ray;
    ray.o = Vec3(s[0], s[1], s[2]) + Vec3(u(rng), u(rng), u(rng)) * (3 * s[3]);
    ray.d = normalize(Vec3(u(rng), u(rng), u(rng)));
    ray.tmin = 0, ray.tmax = INFINITY;
    float t = s[3] * (1 + u(rng));
    if (k % 9 == 0) ray.o = Vec3(s[0], s[1], s[2]), t = 0;  // the hit point is the centre
    const int material = int(rng() % 3);
    SurfaceHit fast, slow;
    refine_sphere(s, material, ray, t, fast);
    refine_sphere_scalar(s, material, ray, t, slow);
    ASSERT_TRUE(same_record(fast, slow)) << "sphere " << k;
    if (k % 9 == 0) ASSERT_EQ(slow.ng, Vec3(0, 1, 0));
  }
}
