// Accel's ray tests around Embree (renderer/accel_math.h) checked directly: the SSE forms give the
// scalar forms' bits, on random rays and on the cases where floats go wrong (NaN, infinities,
// rays parallel to a slab, grazing and inside a sphere, lanes switched off).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

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
