// Warps, discrete distributions, MIS weights, the random number generator and shading frames.
// Distribution checks are chi-square goodness-of-fit tests at significance 1e-3 with fixed seeds,
// so every run sees the same numbers.
#include "sampler.h"
#include "sampling.h"

#include <gtest/gtest.h>

#include <cstring>
#include <set>
#include <vector>

#include "rng.h"
#include "stat_util.h"

using namespace pt;
using pt::test::chi2_test;
using pt::test::SphereBins;

namespace {

constexpr double kAlpha = 1e-3;

// Corners and midpoints of the unit square, including the largest float below 1.
std::vector<Vec2> edge_inputs() {
  const float v[] = {0.0f, 1e-7f, 0.25f, 0.5f, 0.75f, 0x1.fffffep-1f};
  std::vector<Vec2> out;
  for (float a : v)
    for (float b : v) out.push_back({a, b});
  return out;
}

// Draws n directions from `warp`, checks that each is a unit vector satisfying `in_domain`, and
// runs the chi-square test of their (theta, phi) histogram against the integral of `pdf`.
template <class Warp, class Pdf, class Domain>
void check_direction_warp(Warp warp, Pdf pdf, Domain in_domain, uint64_t seed) {
  for (Vec2 u : edge_inputs()) {
    Vec3 w = warp(u);
    ASSERT_TRUE(is_finite(w)) << "u = " << u.x << ", " << u.y;
    EXPECT_NEAR(length(w), 1.0f, 1e-5f) << "u = " << u.x << ", " << u.y;
    EXPECT_TRUE(in_domain(w)) << "u = " << u.x << ", " << u.y;
  }
  SphereBins bins(24, 48);
  std::vector<double> observed(bins.size(), 0.0);
  const int n = 400000;
  Pcg32 rng(seed, 7);
  int bad = 0;
  for (int i = 0; i < n; ++i) {
    Vec3 w = warp(rng.next_2d());
    if (!is_finite(w) || std::fabs(length(w) - 1) > 1e-5f || !in_domain(w)) ++bad;
    observed[bins.index(w)] += 1;
  }
  EXPECT_EQ(bad, 0) << "samples outside the domain";
  std::vector<double> expected = bins.integrate(pdf, 8, 4);
  EXPECT_NEAR(test::sum(expected), 1.0, 1e-4) << "pdf does not integrate to 1 over the sphere";
  for (double& e : expected) e *= n;
  auto r = chi2_test(observed, expected, kAlpha);
  EXPECT_TRUE(r.passed) << r.message;
}

}  // namespace

// ---- continuous warps --------------------------------------------------------------------

TEST(Warps, CosineHemisphere) {
  check_direction_warp(sample_cosine_hemisphere, [](Vec3 w) { return cosine_hemisphere_pdf(w.z); },
                       [](Vec3 w) { return w.z >= 0; }, 1);
  EXPECT_EQ(cosine_hemisphere_pdf(-0.5f), 0.0f);
  EXPECT_EQ(cosine_hemisphere_pdf(0.0f), 0.0f);
  EXPECT_NEAR(cosine_hemisphere_pdf(1.0f), 1 / M_PI, 1e-7);
}

TEST(Warps, UniformHemisphere) {
  check_direction_warp(sample_uniform_hemisphere,
                       [](Vec3 w) { return w.z >= 0 ? uniform_hemisphere_pdf() : 0.0f; },
                       [](Vec3 w) { return w.z >= 0; }, 2);
}

TEST(Warps, UniformSphere) {
  check_direction_warp(sample_uniform_sphere, [](Vec3) { return uniform_sphere_pdf(); },
                       [](Vec3) { return true; }, 3);
}

// Uniform over the unit disk (pdf 1/pi): histogram on a square grid over [-1,1]^2, expected
// counts from the disk's area in each cell.
TEST(Warps, ConcentricDisk) {
  for (Vec2 u : edge_inputs()) {
    Vec2 d = sample_concentric_disk(u);
    EXPECT_LE(d.x * d.x + d.y * d.y, 1.0f + 1e-6f) << "u = " << u.x << ", " << u.y;
  }
  // The centre of the square maps to the centre, the square's edges to the circle.
  Vec2 c = sample_concentric_disk({0.5f, 0.5f});
  EXPECT_EQ(c.x, 0.0f);
  EXPECT_EQ(c.y, 0.0f);
  for (float t : {0.0f, 0.3f, 0.5f, 0.9f}) {
    Vec2 e = sample_concentric_disk({t, 0.0f});
    EXPECT_NEAR(e.x * e.x + e.y * e.y, 1.0f, 1e-5f);
  }

  const int g = 24, n = 400000;
  std::vector<double> observed(g * g, 0.0), expected(g * g, 0.0);
  Pcg32 rng(4, 7);
  int bad = 0;
  for (int i = 0; i < n; ++i) {
    Vec2 d = sample_concentric_disk(rng.next_2d());
    if (!(d.x * d.x + d.y * d.y <= 1.0f + 1e-6f)) ++bad;
    int ix = std::clamp(int((d.x + 1) / 2 * g), 0, g - 1), iy = std::clamp(int((d.y + 1) / 2 * g), 0, g - 1);
    observed[iy * g + ix] += 1;
  }
  EXPECT_EQ(bad, 0);
  const int sub = 64;
  double h = 2.0 / (g * sub), total = 0;
  for (int iy = 0; iy < g * sub; ++iy)
    for (int ix = 0; ix < g * sub; ++ix) {
      double x = -1 + (ix + 0.5) * h, y = -1 + (iy + 0.5) * h;
      if (x * x + y * y <= 1) {
        expected[(iy / sub) * g + ix / sub] += h * h / M_PI;
        total += h * h / M_PI;
      }
    }
  EXPECT_NEAR(total, 1.0, 1e-3);
  for (double& e : expected) e *= n;
  auto r = chi2_test(observed, expected, kAlpha);
  EXPECT_TRUE(r.passed) << r.message;
}

// Uniform barycentrics (density 2 on b0, b1 >= 0, b0 + b1 <= 1): on a g x g grid over the unit
// square the cells below the diagonal hold area h^2, the cells the diagonal cuts h^2 / 2.
TEST(Warps, UniformTriangle) {
  auto in_triangle = [](Vec2 b) { return b.x >= 0 && b.y >= 0 && b.x + b.y <= 1.0f + 1e-6f; };
  for (Vec2 u : edge_inputs()) EXPECT_TRUE(in_triangle(sample_uniform_triangle(u))) << u.x << ", " << u.y;
  const int g = 20, n = 200000;
  std::vector<double> observed(g * g, 0.0), expected(g * g, 0.0);
  Pcg32 rng(5, 7);
  int bad = 0;
  for (int i = 0; i < n; ++i) {
    Vec2 b = sample_uniform_triangle(rng.next_2d());
    if (!in_triangle(b)) ++bad;
    int ix = std::clamp(int(b.x * g), 0, g - 1), iy = std::clamp(int(b.y * g), 0, g - 1);
    observed[iy * g + ix] += 1;
  }
  EXPECT_EQ(bad, 0);
  double cell = 1.0 / (g * g), total = 0;
  for (int iy = 0; iy < g; ++iy)
    for (int ix = 0; ix < g; ++ix) {
      double p = ix + iy < g - 1 ? 2 * cell : (ix + iy == g - 1 ? cell : 0.0);
      expected[iy * g + ix] = p * n;
      total += p;
    }
  EXPECT_NEAR(total, 1.0, 1e-12);
  auto r = chi2_test(observed, expected, kAlpha);
  EXPECT_TRUE(r.passed) << r.message;
}

// ---- Distribution1D ----------------------------------------------------------------------

TEST(Distribution1D, PdfSumsToOneAndMatchesWeights) {
  std::vector<float> w = {0, 3, 1, 0, 0.5f, 2, 0, 7, 0.01f, 0};
  Distribution1D d(w);
  ASSERT_EQ(d.size(), w.size());
  double total = 0, sum = 0;
  for (float x : w) total += x;
  EXPECT_NEAR(d.total(), total, 1e-6);
  for (size_t i = 0; i < w.size(); ++i) {
    sum += d.discrete_pdf(i);
    EXPECT_NEAR(d.discrete_pdf(i), w[i] / total, 1e-7) << "bin " << i;
  }
  EXPECT_NEAR(sum, 1.0, 1e-6);
}

TEST(Distribution1D, FrequenciesMatchWeights) {
  std::vector<float> w = {0, 3, 1, 0, 0.5f, 2, 0, 7, 0.01f, 0};
  Distribution1D d(w);
  double total = 0;
  for (float x : w) total += x;
  const int n = 200000;
  std::vector<double> observed(w.size(), 0.0), expected(w.size());
  for (size_t i = 0; i < w.size(); ++i) expected[i] = n * w[i] / total;
  Pcg32 rng(11, 3);
  for (int i = 0; i < n; ++i) {
    float prob = -1;
    size_t k = d.sample_discrete(rng.next_float(), &prob);
    ASSERT_LT(k, w.size());
    EXPECT_EQ(prob, d.discrete_pdf(k));
    observed[k] += 1;
  }
  auto r = chi2_test(observed, expected, kAlpha);
  EXPECT_TRUE(r.passed) << r.message;
}

TEST(Distribution1D, ZeroWeightsAreNeverSampled) {
  // Leading, interior and trailing zeros, and weights the constructor must treat as zero.
  std::vector<float> w = {0, 0, 1, 0, 0, 2, 0, -3, NAN, INFINITY, 0.5f, 0, 0};
  Distribution1D d(w);
  auto positive = [&](size_t i) { return std::isfinite(w[i]) && w[i] > 0; };
  for (size_t i = 0; i < w.size(); ++i)
    if (!positive(i)) EXPECT_EQ(d.discrete_pdf(i), 0.0f) << "bin " << i;
  // A dense sweep of u (which hits the cdf steps themselves), the ends of [0,1), and the floats
  // around every cdf value.
  std::vector<float> us = {0.0f, 0x1.fffffep-1f};
  for (int i = 0; i < 1000000; ++i) us.push_back(float(i) / 1000000.0f);
  float acc = 0;
  for (size_t i = 0; i < w.size(); ++i) {
    acc += d.discrete_pdf(i);
    for (float v : {acc, std::nextafter(acc, 0.0f), std::nextafter(acc, 1.0f)})
      if (v >= 0 && v < 1) us.push_back(v);
  }
  for (float u : us) {
    float prob = 0, ur = -1;
    size_t k = d.sample_discrete(u, &prob, &ur);
    ASSERT_LT(k, w.size()) << "u = " << u;
    EXPECT_TRUE(positive(k)) << "zero-weight bin " << k << " sampled for u = " << u;
    EXPECT_GT(prob, 0.0f);
  }
}

// All-zero weights fall back to a uniform distribution: valid indices and usable probabilities.
TEST(Distribution1D, AllZeroWeightsDoNotCrash) {
  Distribution1D d(std::vector<float>{0, 0, 0, 0});
  EXPECT_EQ(d.total(), 0.0);
  double sum = 0;
  for (size_t i = 0; i < d.size(); ++i) sum += d.discrete_pdf(i);
  EXPECT_NEAR(sum, 1.0, 1e-6);
  for (float u : {0.0f, 0.3f, 0.5f, 0.99f, 0x1.fffffep-1f}) {
    float prob = -1, ur = -1;
    size_t k = d.sample_discrete(u, &prob, &ur);
    EXPECT_LT(k, d.size());
    EXPECT_TRUE(std::isfinite(prob) && prob > 0);
    EXPECT_GE(ur, 0.0f);
    EXPECT_LT(ur, 1.0f);
  }
}

// The remapped u is uniform in [0, 1) within the chosen bin (lights reuse it for a second sample).
TEST(Distribution1D, RemappedUStaysInUnitIntervalAndIsUniform) {
  std::vector<float> w = {1, 0, 5, 2, 0, 0.25f};
  Distribution1D d(w);
  std::vector<float> us = {0.0f, 0x1.fffffep-1f, 0.5f};
  float acc = 0;
  for (size_t i = 0; i < w.size(); ++i) {
    acc += d.discrete_pdf(i);
    for (float v : {acc, std::nextafter(acc, 0.0f), std::nextafter(acc, 1.0f)})
      if (v >= 0 && v < 1) us.push_back(v);
  }
  for (float u : us) {
    float ur = -1;
    d.sample_discrete(u, nullptr, &ur);
    EXPECT_GE(ur, 0.0f) << "u = " << u;
    EXPECT_LT(ur, 1.0f) << "u = " << u;
  }
  // The largest float below a bin's upper cdf value: when the cdf (a double) lies just above a
  // float, (u - cdf_lo) / width rounds to 1 in float unless it is clamped.
  Pcg32 wrng(15, 3);
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<float> ws(8);
    for (float& x : ws) x = wrng.next_float() + 0.01f;
    Distribution1D dd(ws);
    double total = 0, acc2 = 0;
    for (float x : ws) total += x;
    for (size_t k = 0; k + 1 < ws.size(); ++k) {
      acc2 += ws[k];
      double c = acc2 / total;
      float u = float(c);
      if (double(u) >= c) u = std::nextafter(u, 0.0f);
      float ur = -1;
      size_t got = dd.sample_discrete(u, nullptr, &ur);
      ASSERT_GE(ur, 0.0f);
      ASSERT_EQ(got, k);
      ASSERT_LT(ur, 1.0f) << "u = " << u << " just below the cdf " << c << " of bin " << k;
    }
  }
  const int n = 200000, nb = 20;
  std::vector<std::vector<double>> hist(w.size(), std::vector<double>(nb, 0.0));
  std::vector<double> count(w.size(), 0.0);
  Pcg32 rng(12, 3);
  for (int i = 0; i < n; ++i) {
    float ur = -1;
    size_t k = d.sample_discrete(rng.next_float(), nullptr, &ur);
    ASSERT_GE(ur, 0.0f);
    ASSERT_LT(ur, 1.0f);
    hist[k][std::min(int(ur * nb), nb - 1)] += 1;
    count[k] += 1;
  }
  for (size_t k = 0; k < w.size(); ++k) {
    if (count[k] == 0) continue;
    std::vector<double> expected(nb, count[k] / nb);
    auto r = chi2_test(hist[k], expected, kAlpha);
    EXPECT_TRUE(r.passed) << "bin " << k << ": " << r.message;
  }
}

// ---- power heuristic -------------------------------------------------------------------------

TEST(PowerHeuristic, Limits) {
  EXPECT_FLOAT_EQ(power_heuristic(1, 2), 1.0f / 5.0f);
  EXPECT_FLOAT_EQ(power_heuristic(3, 3), 0.5f);
  EXPECT_EQ(power_heuristic(1, 0), 1.0f);
  EXPECT_EQ(power_heuristic(0, 1), 0.0f);
  EXPECT_EQ(power_heuristic(0, 0), 0.0f);  // no NaN when neither technique can sample
  EXPECT_EQ(power_heuristic(kInf, 5), 1.0f);
  EXPECT_EQ(power_heuristic(kInf, 0), 1.0f);
  EXPECT_EQ(power_heuristic(kInf, kInf), 1.0f);
  EXPECT_EQ(power_heuristic(5, kInf), 0.0f);
  Pcg32 rng(13, 1);
  for (int i = 0; i < 10000; ++i) {
    // pdfs over many orders of magnitude, including ones whose squares overflow a float.
    float a = std::exp(rng.next_float() * 110 - 55), b = std::exp(rng.next_float() * 110 - 55);
    float wa = power_heuristic(a, b), wb = power_heuristic(b, a);
    ASSERT_TRUE(wa >= 0 && wa <= 1) << "a = " << a << ", b = " << b << ", w = " << wa;
    ASSERT_NEAR(wa + wb, 1.0f, 1e-6f) << "a = " << a << ", b = " << b;
  }
  EXPECT_NEAR(power_heuristic(1e20f, 1e19f), 100.0f / 101.0f, 1e-6f);
  EXPECT_NEAR(power_heuristic(1e-25f, 2e-25f), 0.2f, 1e-6f);
}

// ---- random numbers --------------------------------------------------------------------------

// pcg32_srandom_r(42, 54) from the reference implementation (pcg-c-basic, pcg32-demo).
TEST(Pcg32, MatchesReferenceStream) {
  Pcg32 rng(42, 54);
  const uint32_t ref[] = {0xa15c02b7u, 0x7b47f409u, 0xba1d3330u, 0x83d2f293u, 0xbfa4784bu, 0xcbed606eu};
  for (uint32_t r : ref) EXPECT_EQ(rng.next_u32(), r);
}

// A generator whose first next_u32() is 0xffffffff, the value most likely to round up to 1:
// choose the LCG state whose XSH-RR output is all ones (rotation 0, and bit j of
// state ^ (state >> 18) set for j = 27..58), then invert the seeding steps for init_state.
Pcg32 pcg_first_output_all_ones() {
  const uint64_t mult = 6364136223846793005ull, inc = 1;  // stream 0
  uint64_t x = 0;
  for (int j = 58; j >= 27; --j) {
    uint64_t above = j + 18 < 64 ? (x >> (j + 18)) & 1 : 0;
    x |= (1 ^ above) << j;
  }
  uint64_t inv = mult;  // Newton iteration for the inverse of an odd number modulo 2^64
  for (int i = 0; i < 6; ++i) inv *= 2 - mult * inv;
  // seed(): state = ((0 * mult + inc) + init) * mult + inc must equal x.
  uint64_t init = (x - inc) * inv - inc;
  return Pcg32(init, 0);
}

TEST(Pcg32, NextFloatNeverReachesOne) {
  Pcg32 a = pcg_first_output_all_ones();
  ASSERT_EQ(a.next_u32(), 0xffffffffu);
  Pcg32 b = pcg_first_output_all_ones();
  float f = b.next_float();
  EXPECT_LT(f, 1.0f);
  EXPECT_GT(f, 0.99999f);
}

TEST(Pcg32, NextFloatIsUniformInUnitInterval) {
  const int n = 1000000, nb = 100;
  std::vector<double> hist(nb, 0.0);
  for (uint64_t s = 0; s < 4; ++s) {
    Pcg32 rng = make_sample_rng(s, 17 * s, s);
    std::fill(hist.begin(), hist.end(), 0.0);
    for (int i = 0; i < n / 4; ++i) {
      float f = rng.next_float();
      ASSERT_GE(f, 0.0f);
      ASSERT_LT(f, 1.0f);
      hist[std::min(int(f * nb), nb - 1)] += 1;
    }
    auto r = chi2_test(hist, std::vector<double>(nb, double(n / 4) / nb), kAlpha);
    EXPECT_TRUE(r.passed) << "stream " << s << ": " << r.message;
  }
}

TEST(Pcg32, SampleStreamsAreReproducibleAndDistinct) {
  auto first = [](uint64_t seed, uint64_t pixel, uint64_t sample) {
    Pcg32 rng = make_sample_rng(seed, pixel, sample);
    std::vector<uint32_t> v(16);
    for (auto& x : v) x = rng.next_u32();
    return v;
  };
  EXPECT_EQ(first(7, 123, 4), first(7, 123, 4));
  EXPECT_NE(first(7, 123, 4), first(8, 123, 4));
  EXPECT_NE(first(7, 123, 4), first(7, 124, 4));
  EXPECT_NE(first(7, 123, 4), first(7, 123, 5));
  EXPECT_NE(first(0, 1, 2), first(0, 2, 1));  // pixel and sample are not interchangeable
  EXPECT_NE(first(1, 0, 0), first(0, 1, 0));
  EXPECT_NE(first(1, 0, 0), first(0, 0, 1));
  // Every (seed, pixel, sample) of a small grid starts a different stream.
  std::set<uint64_t> starts;
  int count = 0;
  for (uint64_t seed = 0; seed < 4; ++seed)
    for (uint64_t pixel = 0; pixel < 64; ++pixel)
      for (uint64_t sample = 0; sample < 64; ++sample, ++count) {
        Pcg32 rng = make_sample_rng(seed, pixel, sample);
        uint64_t a = rng.next_u32();
        starts.insert((a << 32) | rng.next_u32());
      }
  EXPECT_EQ(int(starts.size()), count);
}

// Neighbouring pixels (and neighbouring samples) must not give correlated numbers.
TEST(Pcg32, NeighbouringStreamsAreUncorrelated) {
  const int n = 20000;
  for (int which = 0; which < 2; ++which) {
    double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    for (int i = 0; i < n; ++i) {
      Pcg32 a = which == 0 ? make_sample_rng(3, i, 0) : make_sample_rng(3, 0, i);
      Pcg32 b = which == 0 ? make_sample_rng(3, i + 1, 0) : make_sample_rng(3, 0, i + 1);
      double x = a.next_float(), y = b.next_float();
      sx += x; sy += y; sxx += x * x; syy += y * y; sxy += x * y;
    }
    double cov = sxy / n - sx / n * sy / n;
    double corr = cov / std::sqrt((sxx / n - sx * sx / n / n) * (syy / n - sy * sy / n / n));
    EXPECT_LT(std::fabs(corr), 5 / std::sqrt(double(n))) << (which == 0 ? "pixels" : "samples");
  }
}

// ---- shading frame ---------------------------------------------------------------------------

TEST(Frame, OrthonormalAndInvertible) {
  std::vector<Vec3> normals = {{0, 0, 1},  {0, 0, -1}, {1, 0, 0},   {0, 1, 0},     {-1, 0, 0},
                               {0, -1, 0}, {1, 0, -0.0f}, {0, 1, -0.0f}};
  for (float e : {1e-8f, 1e-6f, 1e-4f, 1e-3f, 1e-2f})
    for (float sz : {-1.0f, 1.0f}) {
      normals.push_back(normalize(Vec3(e, 0, sz)));
      normals.push_back(normalize(Vec3(0, e, sz)));
      normals.push_back(normalize(Vec3(-e, e, sz)));
      normals.push_back(normalize(Vec3(e, -0.7f * e, sz)));
    }
  Pcg32 rng(21, 5);
  for (int i = 0; i < 100000; ++i) normals.push_back(sample_uniform_sphere(rng.next_2d()));
  for (Vec3 n : normals) {
    Frame f(n);
    SCOPED_TRACE(testing::Message() << "n = (" << n.x << ", " << n.y << ", " << n.z << ")");
    ASSERT_TRUE(is_finite(f.s) && is_finite(f.t));
    ASSERT_NEAR(length(f.s), 1.0f, 1e-5f);
    ASSERT_NEAR(length(f.t), 1.0f, 1e-5f);
    ASSERT_NEAR(dot(f.s, f.t), 0.0f, 1e-5f);
    ASSERT_NEAR(dot(f.s, f.n), 0.0f, 1e-5f);
    ASSERT_NEAR(dot(f.t, f.n), 0.0f, 1e-5f);
    Vec3 zl = f.to_local(n);
    ASSERT_NEAR(zl.z, 1.0f, 1e-5f);
    Vec3 v(rng.next_float() * 2 - 1, rng.next_float() * 2 - 1, rng.next_float() * 2 - 1);
    Vec3 back = f.to_local(f.to_world(v));
    ASSERT_NEAR(length(back - v), 0.0f, 1e-5f);
    Vec3 back2 = f.to_world(f.to_local(v));
    ASSERT_NEAR(length(back2 - v), 0.0f, 1e-5f);
  }
}

TEST(Distribution1D, EmptyDistributionHasNothingToSample) {
  pt::Distribution1D empty, from_empty(std::vector<float>{});
  for (const pt::Distribution1D* d : {&empty, &from_empty}) {
    float prob = 1, u = 1;
    EXPECT_EQ(d->sample_discrete(0.5f, &prob, &u), 0u);
    EXPECT_EQ(prob, 0.0f);
    EXPECT_EQ(d->discrete_pdf(0), 0.0f);
  }
}

// ---- the per-sample sampler (renderer/sampler.h) ----

TEST(Sampler, Dim1MatchesTheDirectionNumbers) {
  for (uint32_t i : {0u, 1u, 2u, 3u, 255u, 256u, 12345u, 0xdeadbeefu, 0xffffffffu}) {
    uint32_t r = 0, x = i;
    for (uint32_t v = 1u << 31; x; x >>= 1, v ^= v >> 1)
      if (x & 1) r ^= v;
    EXPECT_EQ(pt::sobol_dim1(i), r) << i;
  }
}

TEST(Sampler, EveryDimensionPairIsAStratifiedZeroTwoNet) {
  // Owen scrambling keeps the (0,2)-net property: for 2^k samples of one pixel, every elementary
  // interval of area 2^-k holds exactly one point, for each dimension pair.
  const int k = 6, n = 1 << k;
  for (uint64_t pixel : {0ull, 7ull, 123456ull}) {
    for (int pair = 0; pair < 3; ++pair) {
      for (int xbits = 0; xbits <= k; ++xbits) {
        int ybits = k - xbits;
        std::vector<int> cells(size_t(n), 0);
        for (int s = 0; s < n; ++s) {
          pt::Sampler smp(pt::SamplerKind::sobol, 42, pixel, uint32_t(s));
          pt::Vec2 u;
          for (int d = 0; d <= pair; ++d) u = smp.next_2d();
          int cx = int(u.x * (1 << xbits)), cy = int(u.y * (1 << ybits));
          ++cells[size_t(cy * (1 << xbits) + cx)];
        }
        for (int c : cells) ASSERT_EQ(c, 1) << "pixel " << pixel << " pair " << pair << " " << xbits << "x" << ybits;
      }
    }
  }
}

TEST(Sampler, DimensionsAreUniformAndUncorrelated) {
  // Over many pixels, each draw is uniform and draws of different dimensions are uncorrelated.
  const int pixels = 4096, spp = 8;
  std::vector<double> sum(8, 0), sum2(8, 0);
  double cross01 = 0, cross12 = 0, cross_xy = 0;
  int n = 0;
  for (int p = 0; p < pixels; ++p)
    for (int s = 0; s < spp; ++s) {
      pt::Sampler smp(pt::SamplerKind::sobol, 1, uint64_t(p), uint32_t(s));
      pt::Vec2 a = smp.next_2d(), b = smp.next_2d();
      float c = smp.next_float();
      pt::Vec2 d = smp.next_2d();
      double v[8] = {a.x, a.y, b.x, b.y, c, d.x, d.y, 0.5};
      for (int i = 0; i < 8; ++i) {
        sum[i] += v[i];
        sum2[i] += v[i] * v[i];
      }
      cross01 += (a.x - 0.5) * (b.x - 0.5);
      cross12 += (b.y - 0.5) * (c - 0.5);
      cross_xy += (a.x - 0.5) * (a.y - 0.5);
      ++n;
    }
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(sum[i] / n, 0.5, 5 * std::sqrt(1.0 / 12 / n)) << i;
    EXPECT_NEAR(sum2[i] / n, 1.0 / 3, 0.01) << i;
  }
  double tol = 5 * (1.0 / 12) / std::sqrt(double(n));
  EXPECT_NEAR(cross01 / n, 0, tol);
  EXPECT_NEAR(cross12 / n, 0, tol);
  EXPECT_NEAR(cross_xy / n, 0, tol);
}

TEST(Sampler, SameInputsSameNumbersAndIndependentModeIsPcg) {
  pt::Sampler a(pt::SamplerKind::sobol, 3, 10, 5), b(pt::SamplerKind::sobol, 3, 10, 5), c(pt::SamplerKind::sobol, 3, 11, 5);
  pt::Vec2 ua = a.next_2d(), ub = b.next_2d(), uc = c.next_2d();
  EXPECT_EQ(ua.x, ub.x);
  EXPECT_EQ(ua.y, ub.y);
  EXPECT_NE(ua.x, uc.x);
  pt::Sampler ind(pt::SamplerKind::independent, 3, 10, 5);
  pt::Pcg32 rng = pt::make_sample_rng(3, 10, 5);
  pt::Vec2 ui = ind.next_2d(), ur = rng.next_2d();
  EXPECT_EQ(ui.x, ur.x);
  EXPECT_EQ(ui.y, ur.y);
}

TEST(Sampling, QuarterRangeSinCosMatchesTheLibraryAndTheDiskMapIsUnchanged) {
  double worst = 0;
  for (int i = 0; i <= 100000; ++i) {
    float a = -kPi / 4 + (kPi / 2) * i / 100000.0f, s, c;
    sincos_quarter(a, s, c);
    worst = std::max({worst, std::fabs(s - std::sin(double(a))), std::fabs(c - std::cos(double(a)))});
  }
  EXPECT_LT(worst, 4e-7);
  // The textbook form of the map (explicit theta, library sin/cos) agrees to float rounding.
  Pcg32 rng(11, 3);
  for (int i = 0; i < 100000; ++i) {
    Vec2 u = rng.next_2d();
    float ox = 2 * u.x - 1, oy = 2 * u.y - 1;
    double r = std::fabs(ox) > std::fabs(oy) ? ox : oy;
    double theta = std::fabs(ox) > std::fabs(oy) ? (kPi / 4) * (oy / ox) : kPi / 2 - (kPi / 4) * (ox / oy);
    Vec2 d = sample_concentric_disk(u);
    ASSERT_NEAR(d.x, r * std::cos(theta), 1e-6);
    ASSERT_NEAR(d.y, r * std::sin(theta), 1e-6);
  }
}

// next_2d_many gives next_2d's numbers to each sampler, bit for bit, whatever their dimensions
// (Sobol ones in lanes, the independent stream past them) and kinds, in any grouping.
TEST(Sampler, ManyDrawsAtOnceAreEachSamplersOwnDraws) {
  for (bool lanes : {false, true}) {
    SCOPED_TRACE(lanes ? "lanes" : "one at a time");
    std::vector<Sampler> mine, ref;
    std::vector<int> skips;
    for (uint32_t k = 0; k < 61; ++k) {  // not a multiple of 8: a partial group
      SamplerKind kind = k % 13 == 5 ? SamplerKind::independent : SamplerKind::sobol;
      mine.emplace_back(kind, 7 + k % 3, 1000 + k / 4, k * 977u);
      ref.emplace_back(kind, 7 + k % 3, 1000 + k / 4, k * 977u);
      skips.push_back(int(k % 11));  // some lanes past the Sobol dimensions
    }
    for (size_t k = 0; k < mine.size(); ++k)
      for (int d = 0; d < skips[k]; ++d) mine[k].skip_1d(), ref[k].skip_1d();
    std::vector<Sampler*> every_other;
    for (size_t k = 0; k < mine.size(); k += 2) every_other.push_back(&mine[k]);
    std::vector<Vec2> out(mine.size());
    for (int round = 0; round < 6; ++round) {
      if (round % 2 == 0) {
        Sampler::next_2d_many(mine.data(), mine.size(), out.data(), lanes);
        for (size_t k = 0; k < mine.size(); ++k) {
          Vec2 want = ref[k].next_2d();
          ASSERT_EQ(std::memcmp(&want, &out[k], sizeof want), 0) << "sampler " << k << " round " << round;
        }
      } else {
        Sampler::next_2d_many(every_other.data(), every_other.size(), out.data(), lanes);
        for (size_t k = 0; k < every_other.size(); ++k) {
          Vec2 want = ref[2 * k].next_2d();
          ASSERT_EQ(std::memcmp(&want, &out[k], sizeof want), 0) << "sampler " << 2 * k << " round " << round;
        }
      }
    }
    for (size_t k = 0; k < mine.size(); ++k) {  // and the draws after them follow on
      float a = mine[k].next_float(), b = ref[k].next_float();
      ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << "sampler " << k;
    }
  }
  if (!Sampler::lanes_available()) GTEST_SKIP() << "no AVX2 here: only the one-at-a-time draws were checked";
}

// The camera's draws without samplers: sobol_draws from the pixel bases and sample indices gives
// each sampler's first and second next_2d(), and a sampler built past them draws on as one that
// took them itself.
TEST(Sampler, CameraDrawsFromPixelBasesAreTheSamplersDraws) {
  if (!Sampler::lanes_available()) GTEST_SKIP() << "no AVX2 here: sobol_draws needs it";
  const size_t n = 37;  // two whole blocks of sixteen and a partial one
  std::vector<uint32_t> base(n), sample(n);
  std::vector<uint64_t> pixel(n);
  for (size_t k = 0; k < n; ++k) {
    pixel[k] = 5000 + k / 3;
    sample[k] = uint32_t(k * 2654435761u);
    base[k] = Sampler::pixel_base(11, pixel[k]);
  }
  std::vector<Vec2> first(n), second(n);
  Sampler::sobol_draws(base.data(), sample.data(), n, 1, first.data());
  Sampler::sobol_draws(base.data(), sample.data(), n, 2, second.data());
  for (size_t k = 0; k < n; ++k) {
    SCOPED_TRACE(k);
    Sampler ref(SamplerKind::sobol, 11, pixel[k], sample[k]);
    Vec2 a = ref.next_2d(), b = ref.next_2d();
    EXPECT_EQ(std::memcmp(&a, &first[k], sizeof a), 0);
    EXPECT_EQ(std::memcmp(&b, &second[k], sizeof b), 0);
    Sampler past(SamplerKind::sobol, 11, pixel[k], sample[k], base[k], 2);
    for (int d = 0; d < 8; ++d) {  // through the Sobol dimensions into the independent stream
      Vec2 x = ref.next_2d(), y = past.next_2d();
      ASSERT_EQ(std::memcmp(&x, &y, sizeof x), 0) << "draw " << d + 3;
    }
  }
}

// skip_2d consumes what next_2d would: the draws after it are the same, in the Sobol dimensions,
// past them, and in the independent stream.
TEST(Sampler, SkippedPairLeavesTheLaterDrawsAsTheyWere) {
  for (SamplerKind kind : {SamplerKind::sobol, SamplerKind::independent})
    for (int before = 0; before < 10; ++before) {
      Sampler a(kind, 5, 77, 1234), b(kind, 5, 77, 1234);
      for (int d = 0; d < before; ++d) a.next_2d(), b.next_2d();
      a.skip_2d();
      b.next_2d();
      for (int d = 0; d < 4; ++d) {
        Vec2 x = a.next_2d(), y = b.next_2d();
        ASSERT_EQ(std::memcmp(&x, &y, sizeof x), 0) << (kind == SamplerKind::sobol ? "sobol" : "independent")
                                                    << " after " << before << " draws";
      }
    }
}
