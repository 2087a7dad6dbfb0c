// The random numbers: the PCG32 generator and the per-sample sampler (Owen-scrambled Sobol, its
// draws in lanes). Distribution checks are chi-square goodness-of-fit tests at significance 1e-3
// with fixed seeds, so every run sees the same numbers.
#include "loop_forms.h"
#include "sampler.h"

#include <gtest/gtest.h>

#include <cstring>
#include <set>
#include <vector>

#include "rng.h"
#include "stat_util.h"

using namespace pt;
using pt::test::chi2_test;

namespace {

// Its 4 chi-square tests fail by chance together with probability 0.01.
const double kAlpha = pt::test::sidak_alpha(0.01, 4);

}  // namespace

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


// next_2d_many gives next_2d's numbers to each sampler, bit for bit, whatever their dimensions
// (Sobol ones in lanes, the independent stream past them) and kinds, in any grouping.
TEST(Sampler, ManyDrawsAtOnceAreEachSamplersOwnDraws) {
  for (bool lanes : {false, true}) {
    SCOPED_TRACE(lanes ? "lanes" : "one at a time");
    forms::Scoped forms;
    forms->lanes = lanes;
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
        Sampler::next_2d_many(mine.data(), mine.size(), out.data());
        for (size_t k = 0; k < mine.size(); ++k) {
          Vec2 want = ref[k].next_2d();
          ASSERT_EQ(std::memcmp(&want, &out[k], sizeof want), 0) << "sampler " << k << " round " << round;
        }
      } else {
        Sampler::next_2d_many(every_other.data(), every_other.size(), out.data());
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
