// Warps, discrete distributions, MIS weights and shading frames (the random numbers: test_sampler.cpp).
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

// Its 10 chi-square tests fail by chance together with probability 0.01.
const double kAlpha = pt::test::sidak_alpha(0.01, 10);

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
