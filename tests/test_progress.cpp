// The render's progress and ETA (ProgressEstimate, driver.h): the work left is what the running
// pixels' adaptive stops will still take, timed at the recent sample rate, and it says something
// sensible at every edge. Films are fed synthetic samples on a synthetic clock: nothing here
// depends on how fast the machine is.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <vector>

#include "driver.h"
#include "rng.h"

using namespace pt;

namespace {

// A film fed as the session's tiles feed it (render_tile's loop), as a PassSource: passes of 1, 2,
// 4, ... samples, each running pixel taking samples up to the pass's count or its adaptive stop.
// Samples come from `draw(pixel, rng)`; each costs `cost(pixel)` seconds on the synthetic clock,
// and the tiles (the left and right halves) keep their time and samples of the last pass, as the
// session's do. It keeps its own luminance sums beside the film's, added in the same order, to
// predict each pixel's stop itself.
struct SyntheticRender : PassSource {
  Film m_film;
  std::vector<Pcg32> rng;
  std::vector<double> s1, s2;
  std::vector<Tile> tile_list;
  std::vector<uint64_t> tile_ns, tile_samples;
  double clock = 0, light_clock = 0;  // light_clock: the part of clock spent on light paths
  SyntheticRender(int w, int h, int spp, AdaptiveRule rule)
      : m_film(w, h, spp, rule, false), rng(size_t(w) * h), s1(rng.size()), s2(rng.size()),
        tile_list{{0, 0, w / 2, h}, {w / 2, 0, w, h}}, tile_ns(2), tile_samples(2) {
    for (size_t i = 0; i < rng.size(); ++i) rng[i] = Pcg32(i, 7);
  }
  template <class Draw, class Cost>
  void pass(uint32_t target, Draw draw, Cost cost) {
    uint64_t nonfinite = 0;
    for (size_t t = 0; t < tile_list.size(); ++t) {
      const double start = clock;
      tile_samples[t] = 0;
      for (int y = tile_list[t].y0; y < tile_list[t].y1; ++y)
        for (int x = tile_list[t].x0; x < tile_list[t].x1; ++x) {
          const size_t i = size_t(y) * m_film.width() + x;
          while (!m_film.done(i) && m_film.count(i) < target) {
            const Vec3 l(float(draw(i, rng[i])));
            const double lum = luminance(l);
            s1[i] += lum, s2[i] += lum * lum;
            clock += cost(i);
            ++tile_samples[t];
            if (m_film.add_sample(i, m_film.count(i), l, nonfinite)) m_film.set_done(i);
          }
          if (m_film.count(i) >= uint32_t(m_film.spp())) m_film.set_done(i);
        }
      tile_ns[t] = uint64_t(std::llround((clock - start) * 1e9));
    }
  }
  uint32_t predicted_stop(size_t i) const {
    return m_film.rule().predicted_stop(s1[i], s2[i], m_film.count(i), uint32_t(m_film.spp()));
  }
  // PassSource: what ProgressEstimate reads.
  bool advance(int, const std::atomic<bool>*, const TileCallback&) override { return false; }
  void set_deadline(std::chrono::steady_clock::time_point) override {}
  const Film& film() const override { return m_film; }
  double seconds() const override { return clock; }
  Film::Work work() const override { return m_film.work(tile_list, tile_ns, tile_samples); }
  RenderCounts counts() const override { return {}; }
  const std::vector<Tile>& tiles() const override { return tile_list; }
  void save(BinaryWriter& out) const override { m_film.save(out); }
  void restore(BinaryReader& in) override { m_film.restore(in); }
  double light_seconds() const override { return light_clock; }
  // Caustic light paths for a pass from `from` to `to` samples a pixel: `per_sample` a sample,
  // `cost` seconds each.
  void light_paths(uint32_t from, uint32_t to, uint64_t per_sample, double cost) {
    m_film.add_light_paths(per_sample * (to - from));
    clock += cost * double(per_sample * (to - from)), light_clock += cost * double(per_sample * (to - from));
  }
};

// The left half flat (its pixels stop at the first test, 33 samples), the right half noisy: uniform
// on [0.25, 1.75], whose (sigma/mu)^2 = 0.1875 stops them near (1.96/0.05)^2 x 0.1875 = 288
// samples. A noisy sample costs 4 us, a flat one 1 us, as in a scene whose noisy pixels trace
// longer paths.
struct HalfNoisy {
  int width;
  bool flat(size_t i) const { return int(i % size_t(width)) < width / 2; }
  double operator()(size_t i, Pcg32& r) const { return flat(i) ? 0.5 : 0.25 + 1.5 * double(r.next_float()); }
  double cost(size_t i) const { return flat(i) ? 1e-6 : 4e-6; }
};

}  // namespace

// The rule's prediction is its own test solved for n: at the predicted count (a test count) the
// pixel's statistics would pass, at the test before they would not; the budget clips it.
TEST(AdaptiveRule, PredictedStopIsTheTestThatWouldPass) {
  const AdaptiveRule rule;  // batch 32, tolerance 0.05
  auto passes = [&](double mu, double var, uint32_t n) { return 1.96 * std::sqrt(var / n) <= rule.tolerance * mu; };
  Pcg32 r(3, 1);
  for (int k = 0; k < 1000; ++k) {
    const uint32_t n = 2 + r.next_u32() % 500;
    const double mu = 0.01 + 10 * r.next_float(), cv = 2 * r.next_float();
    const double var = (cv * mu) * (cv * mu);
    const double s1 = mu * n, s2 = var * (n - 1) + s1 * s1 / n;
    const uint32_t stop = rule.predicted_stop(s1, s2, n, 4096);
    SCOPED_TRACE(testing::Message() << "n " << n << ", mu " << mu << ", cv " << cv << ", stop " << stop);
    ASSERT_GT(stop, n);
    if (stop == 4096) {
      EXPECT_FALSE(passes(mu, var * (1 - 1e-9), 4096 - (4096 - 1) % rule.batch));
      continue;
    }
    EXPECT_TRUE(rule.test_due(stop));
    EXPECT_TRUE(passes(mu, var * (1 - 1e-9), stop));
    if (stop - rule.batch > n) EXPECT_FALSE(passes(mu, var * (1 + 1e-9), stop - rule.batch));
    else EXPECT_EQ(stop, rule.next_test(n));
  }
  // Edges: too few samples, no spread (black included), a mean that cannot pass, the rule off.
  EXPECT_EQ(rule.predicted_stop(1, 1, 1, 1024), 1024u);
  EXPECT_EQ(rule.predicted_stop(0, 0, 5, 1024), 33u);
  EXPECT_EQ(rule.predicted_stop(8, 8, 8, 1024), 33u);
  EXPECT_EQ(rule.predicted_stop(0, 8, 8, 1024), 1024u);
  EXPECT_EQ(rule.predicted_stop(-1, 8, 8, 1024), 1024u);
  EXPECT_EQ(rule.predicted_stop(0, 0, 5, 20), 20u);      // the budget comes first
  EXPECT_EQ(rule.predicted_stop(3, 5, 64, 64), 64u);     // spent
  AdaptiveRule off = rule;
  off.enabled = false;
  EXPECT_EQ(off.predicted_stop(8, 8, 8, 1024), 1024u);
}

// Once the flat pixels have stopped, the budget fraction says half the render is done; the work
// left says far less, and it is what the render then takes: its prediction errs by no more than
// the pixels' own stop noise allows, and its ETA (the noisy samples left at their tile's cost)
// by a few per cent, where the budget fraction's misses most of the time left.
TEST(ProgressEstimate, CountsTheSamplesTheNoisyPixelsStillTake) {
  SyntheticRender r(64, 32, 1024, AdaptiveRule());
  const HalfNoisy noisy{64};
  auto cost = [&](size_t i) { return noisy.cost(i); };
  ProgressEstimate estimate;
  for (uint32_t target = 1; target <= 64; target *= 2) {
    r.pass(target, noisy, cost);
    estimate.update(r, r.clock, INFINITY);
  }
  const Film& film = r.film();
  for (size_t i = 0; i < film.pixels(); ++i)
    if (noisy.flat(i)) ASSERT_TRUE(film.done(i)) << i;
  const double t = r.clock, budget = film.progress(), progress = estimate.progress(t);
  const Film::Work work = estimate.work();
  EXPECT_NEAR(budget, 0.5 + 0.5 * 64 / 1024.0, 1e-9);
  EXPECT_LT(progress, 0.6 * budget);
  EXPECT_DOUBLE_EQ(progress, double(work.taken) / double(work.taken + work.left));

  std::vector<uint32_t> predicted(film.pixels());
  uint64_t left = 0;
  for (size_t i = 0; i < film.pixels(); ++i)
    if (!film.done(i)) predicted[i] = r.predicted_stop(i), left += predicted[i] - film.count(i);
  EXPECT_EQ(work.left, left);  // the film's sum is the rule's prediction, pixel by pixel
  EXPECT_EQ(film.work().left, left);
  // The last pass's mean sample was part flat (the 33rd), so a noisy one costs a little more.
  EXPECT_GT(work.cost_left, 1.01 * double(left));
  EXPECT_LT(work.cost_left, 1.05 * double(left));

  const double eta = estimate.remaining_seconds(t), old_eta = t * (1 - budget) / budget;
  for (uint32_t target = 128; target <= 1024; target *= 2) r.pass(target, noisy, cost);
  ASSERT_TRUE(film.finished());
  // Each noisy pixel's actual stop against its prediction: their sum within 4 standard errors.
  double sum = 0, sum2 = 0, m = 0;
  for (size_t i = 0; i < film.pixels(); ++i) {
    if (noisy.flat(i)) continue;
    const double d = double(film.count(i)) - double(predicted[i]);
    sum += d, sum2 += d * d, ++m;
  }
  const double sd = std::sqrt((sum2 - sum * sum / m) / (m - 1));
  EXPECT_GT(sd, 0);
  EXPECT_LT(std::abs(sum), 4 * sd * std::sqrt(m)) << "mean error " << sum / m << " samples a pixel, sd " << sd;
  const double actual = r.clock - t;
  EXPECT_NEAR(eta / actual, 1.0, 4 * sd / std::sqrt(m) / (double(left) / m) + 0.01) << "ETA " << eta << ", actual " << actual;
  EXPECT_LT(old_eta / actual, 0.5) << "the budget fraction's ETA " << old_eta;
}

// Progress counts on between updates at the recent rate, and the ETA counts down; neither passes
// the work the last update predicted.
TEST(ProgressEstimate, CountsOnBetweenPasses) {
  SyntheticRender r(16, 16, 1024, AdaptiveRule());
  const HalfNoisy noisy{16};
  ProgressEstimate estimate;
  for (uint32_t target = 1; target <= 64; target *= 2) {
    r.pass(target, noisy, [&](size_t i) { return noisy.cost(i); });
    estimate.update(r, r.clock, INFINITY);
  }
  const double t = r.clock, eta = estimate.remaining_seconds(t), p = estimate.progress(t);
  ASSERT_GT(eta, 0);
  EXPECT_NEAR(estimate.remaining_seconds(t + eta / 2), eta / 2, 1e-9 * eta);
  EXPECT_GT(estimate.progress(t + eta / 2), p);
  EXPECT_LT(estimate.progress(t + eta / 2), 1);
  EXPECT_EQ(estimate.remaining_seconds(t + 2 * eta), 0);
  EXPECT_LT(estimate.progress(t + 2 * eta), 1);  // done only when the film says so
  EXPECT_GT(estimate.progress(t + 2 * eta), 0.99);
}

// Edges: nothing known yet, a render with no rate, black pixels, a finished film, an empty one.
TEST(ProgressEstimate, IsFiniteAtTheEdgesAndZeroWhenDone) {
  ProgressEstimate none;
  EXPECT_EQ(none.progress(1), 0);
  EXPECT_LT(none.remaining_seconds(1), 0);

  SyntheticRender black(8, 8, 256, AdaptiveRule());
  ProgressEstimate e;
  auto zero = [](size_t, Pcg32&) { return 0.0; };
  auto free_sample = [](size_t) { return 0.0; };  // samples that take no time: no rate
  for (uint32_t target = 1; target <= 16; target *= 2) {
    black.pass(target, zero, free_sample);
    e.update(black, 0, INFINITY);
    EXPECT_TRUE(std::isfinite(e.progress(0))) << target;
    EXPECT_LT(e.remaining_seconds(0), 0) << target;
  }
  EXPECT_EQ(e.work().left, 64u * (33 - 16));  // black pixels stop at the first test
  EXPECT_EQ(e.work().cost_left, 64.0 * (33 - 16));  // tiles that took no time: no weights
  EXPECT_NEAR(e.progress(0), 16.0 / 33, 1e-12);
  black.pass(64, zero, free_sample);
  e.update(black, 0, INFINITY);
  ASSERT_TRUE(black.film().finished());
  EXPECT_EQ(e.progress(0), 1);
  EXPECT_EQ(e.remaining_seconds(0), 0);

  SyntheticRender empty(0, 0, 16, AdaptiveRule());
  ProgressEstimate nothing;
  nothing.update(empty, 0, INFINITY);
  EXPECT_EQ(nothing.progress(0), 1);
  EXPECT_EQ(nothing.remaining_seconds(0), 0);
}

// Without adaptive sampling every pixel takes its budget: progress is the budget fraction exactly,
// as before, and the ETA the budget left at the last pass's rate.
TEST(ProgressEstimate, IsTheBudgetFractionWithoutAdaptiveSampling) {
  AdaptiveRule off;
  off.enabled = false;
  SyntheticRender r(16, 8, 100, off);
  const HalfNoisy noisy{16};
  ProgressEstimate estimate;
  for (uint32_t target = 1; target < 100; target *= 2) {
    r.pass(target, noisy, [](size_t) { return 1e-3; });
    estimate.update(r, r.clock, INFINITY);
    const double t = r.clock;
    EXPECT_DOUBLE_EQ(estimate.progress(t), r.film().progress()) << target;
    EXPECT_NEAR(estimate.remaining_seconds(t), 1e-3 * 128 * (100 - target), 1e-6) << target;
  }
}

// The rate is the last passes', not the whole run's: after cheap early passes, a pass whose
// samples cost ten times as much sets it alone.
TEST(ProgressEstimate, TimesTheWorkAtTheRecentRate) {
  AdaptiveRule off;
  off.enabled = false;
  SyntheticRender r(10, 10, 64, off);
  const HalfNoisy noisy{10};
  ProgressEstimate estimate;
  double unit = 1e-4;
  for (uint32_t target = 1; target <= 16; target *= 2) {
    if (target == 16) unit = 1e-3;
    r.pass(target, noisy, [&](size_t) { return unit; });
    estimate.update(r, r.clock, INFINITY);
  }
  EXPECT_NEAR(estimate.rate(), 1e3, 1e-6);
  EXPECT_NEAR(estimate.remaining_seconds(r.clock), 100 * (64 - 16) * 1e-3, 1e-6);
}

// Samples left weigh their tile's time per sample in the last pass against the pass's mean: dear
// pixels left take longer than the mean sample, cheap ones less.
TEST(ProgressEstimate, WeighsTheSamplesLeftByTheirTilesCost) {
  AdaptiveRule off;
  off.enabled = false;
  SyntheticRender r(10, 10, 64, off);
  const HalfNoisy noisy{10};
  auto cost = [&](size_t i) { return i % 10 < 5 ? 1e-3 : 3e-3; };  // right half 3x dearer
  ProgressEstimate estimate;
  for (uint32_t target = 1; target <= 16; target *= 2) {
    r.pass(target, noisy, cost);
    estimate.update(r, r.clock, INFINITY);
  }
  EXPECT_NEAR(estimate.work().cost_left, double(estimate.work().left), 1e-6);  // both halves left
  EXPECT_NEAR(estimate.remaining_seconds(r.clock), 50 * 48 * (1e-3 + 3e-3), 1e-6);
  // The tiles' costs alone, as the film reads them: the dear half's samples weigh 1.5, the
  // cheap half's 0.5.
  const std::vector<uint64_t> ns{1000, 3000}, samples{10, 10};
  const Film::Work w = r.film().work(r.tile_list, ns, samples);
  EXPECT_EQ(w.left, 100u * 48);
  EXPECT_NEAR(w.cost_left, 50 * 48 * 0.5 + 50 * 48 * 1.5, 1e-9);
}

// Caustic light paths go on for the whole frame until the last pixel stops, at their own rate:
// timed apart, they neither slow the samples' rate nor go uncounted.
TEST(ProgressEstimate, TimesTheLightPathsLeftAtTheirOwnRate) {
  AdaptiveRule off;
  off.enabled = false;
  SyntheticRender r(10, 10, 64, off);
  const HalfNoisy noisy{10};
  ProgressEstimate estimate;
  for (uint32_t target = 1, from = 0; target <= 16; from = target, target *= 2) {
    r.light_paths(from, target, 50, 1e-4);
    r.pass(target, noisy, [](size_t) { return 1e-3; });
    estimate.update(r, r.clock, INFINITY);
  }
  EXPECT_NEAR(estimate.rate(), 1e3, 1e-6);
  // 100 pixels x 48 samples at 1 ms, and 50 x 48 light paths at 0.1 ms.
  EXPECT_NEAR(estimate.remaining_seconds(r.clock), 4.8 + 0.24, 1e-9);
  EXPECT_DOUBLE_EQ(estimate.progress(r.clock), r.film().progress());  // progress counts samples
}

// With an error target the error estimate's 1/time decay may end the render first; a time limit
// sooner still; progress is then the share of the expected time gone.
TEST(ProgressEstimate, EndsSoonerAtTheErrorTargetOrTheTimeLimit) {
  AdaptiveRule off;
  off.enabled = false;
  SyntheticRender r(10, 10, 1000, off);
  const HalfNoisy noisy{10};
  r.pass(10, noisy, [](size_t) { return 2e-3; });  // 2 s for 1%: 198 s left by the budget
  RunLimits target;
  target.target_error = 0.01;
  ProgressEstimate e(target);
  e.update(r, r.clock, 0.04);  // 0.04 at 2 s meets 0.01 at 8 s
  EXPECT_NEAR(e.remaining_seconds(2), 6, 1e-9);
  EXPECT_NEAR(e.remaining_seconds(3), 5, 1e-9);
  EXPECT_NEAR(e.progress(2), 0.25, 1e-9);
  e.update(r, r.clock, 0.005);  // already below
  EXPECT_EQ(e.remaining_seconds(2), 0);
  e.update(r, r.clock, INFINITY);  // no estimate yet: the budget
  EXPECT_NEAR(e.remaining_seconds(2), 198, 1e-6);
  EXPECT_NEAR(e.progress(2), 0.01, 1e-12);
  RunLimits limit;
  limit.time_limit = 3;
  ProgressEstimate l(limit);
  EXPECT_NEAR(l.remaining_seconds(2), 1, 1e-9);  // before any pass, too
  l.update(r, r.clock, 0.04);
  EXPECT_NEAR(l.remaining_seconds(2), 1, 1e-9);
  EXPECT_NEAR(l.progress(2), 2.0 / 3, 1e-9);
  EXPECT_EQ(l.remaining_seconds(5), 0);  // past the limit
}
