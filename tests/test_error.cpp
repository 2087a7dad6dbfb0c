// Error against run time: the reference-free error estimate tracks the true error.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "collada.h"
#include "loop_forms.h"
#include "session.h"
#include "test_util.h"

using namespace pt;


// A small render through the scene's own camera: depth 3, no adaptive sampling, 2 threads.
RenderParams small_render(int width, int height, int spp) {
  RenderParams p;
  p.file_camera = true;
  p.width = width;
  p.height = height;
  p.max_depth = 3;
  p.adaptive = false;
  p.threads = 2;
  p.spp = spp;
  return p;
}

// The estimate against the true error pass by pass (2, 4, ... 256 spp): their ratio as a geometric
// mean over `seeds` renders, since one small render's true error is itself noisy (on dof 40x30 one
// seed's ratio at 16 spp reached 2.2 against a mean of 1.4). The truth is the relMSE against a
// `ref_spp` render, less that render's own estimated error.
std::vector<double> estimate_over_truth_by_pass(const SceneDesc& desc, RenderParams p, int ref_spp, int seeds) {
  p.spp = ref_spp;
  p.seed = 99;
  auto scene = make_render_scene(desc, p);
  RenderSession ref(*scene, p);
  ref.render_all();
  const ImageRGB reference = ref.image();
  const double ref_error = ref.error_estimate();
  std::vector<double> log_sum;
  p.spp = 256;
  for (int seed = 1; seed <= seeds; ++seed) {
    p.seed = uint64_t(seed);
    RenderSession s(*scene, p);
    size_t pass = 0;
    for (int target = 2; target <= p.spp; target *= 2, ++pass) {
      s.render_pass(target);
      const double truth = relative_mse(s.image(), reference) - ref_error;
      if (log_sum.size() <= pass) log_sum.push_back(0);
      log_sum[pass] += std::log(s.error_estimate() / truth);
    }
  }
  for (double& l : log_sum) l = std::exp(l / seeds);
  return log_sum;
}

// The estimate over the truth, pass by pass from `first_spp`: within 1.5x either way; and from
// 16 spp within [0.85, 1.5], the README's claim (the Cornell box at m = 100 and 64x48 reads 0.89
// at 128 spp; the course scenes at 480x360 0.93-1.36: docs/performance.md, "Error estimate").
void expect_within_1p5_from(const std::vector<double>& ratio, int first_spp) {
  int spp = 2, checked = 0;
  for (double r : ratio) {
    if (spp >= first_spp) {
      EXPECT_GT(r, spp >= 16 ? 0.85 : 1 / 1.5) << spp << " spp";
      EXPECT_LT(r, 1.5) << spp << " spp";
      ++checked;
    }
    spp *= 2;
  }
  EXPECT_GT(checked, 4);
}

class ErrorEstimate : public ::testing::TestWithParam<SamplerKind> {};

// dof at 80x60 over four seeds. From 8 spp: below that, halves of one to four Sobol samples cannot
// see the stratification of the whole (the Sobol estimate is about 2x the truth at 2 spp).
TEST_P(ErrorEstimate, StaysWithinAFactorOf1p5OfTheTrueErrorAcrossTheRun) {
  RenderParams p = small_render(80, 60, 0);
  p.sampler = GetParam();
  expect_within_1p5_from(estimate_over_truth_by_pass(load_collada(test::own_scene("dof.dae")), p, 4096, 4), 8);
}

// Where a pixel's own mean is a poor denominator: the Cornell box with its glass and mirror spheres
// at 64x48, Sobol. At m = 100 rare bright paths lift a pixel's mean in one half of its samples, and
// the own-mean estimate fell to 0.6 of the truth from 64 spp; at m = 5 small noisy means of few
// samples inflated it (4.7x at 4 spp, 2.3x at 16). Within 1.5 from the first pass at m = 100, and
// from 4 spp at m = 5 (1.7x at 2).
class ErrorEstimateCornell : public ::testing::TestWithParam<int> {};

TEST_P(ErrorEstimateCornell, StaysWithinAFactorOf1p5OfTheTrueErrorFromTheFirstPasses) {
  RenderParams p = small_render(64, 48, 0);
  p.max_depth = GetParam();
  expect_within_1p5_from(estimate_over_truth_by_pass(load_collada(test::own_scene("cornell.dae")), p, 2048, 6),
                         p.max_depth == 100 ? 2 : 4);
}

INSTANTIATE_TEST_SUITE_P(Depths, ErrorEstimateCornell, ::testing::Values(5, 100),
                         [](const ::testing::TestParamInfo<int>& i) { return "m" + std::to_string(i.param); });

INSTANTIATE_TEST_SUITE_P(Samplers, ErrorEstimate, ::testing::Values(SamplerKind::sobol, SamplerKind::independent),
                         [](const ::testing::TestParamInfo<SamplerKind>& i) {
                           return std::string(i.param == SamplerKind::sobol ? "Sobol" : "Independent");
                         });

TEST(ErrorEstimateMc, FallsLikeOneOverSamplesAndIsFiniteOnBlackImages) {
  SceneDesc desc = load_collada(test::own_scene("dof.dae"));
  RenderParams p;
  p.file_camera = true;
  p.width = 32;
  p.height = 24;
  p.max_depth = 2;
  p.adaptive = false;
  p.spp = 64;
  p.sampler = SamplerKind::independent;  // plain Monte Carlo: error exactly ~ 1/spp
  auto scene = make_render_scene(desc, p);
  RenderSession s(*scene, p);
  s.render_pass(8);
  double e8 = s.error_estimate();
  s.render_pass(64);
  double e64 = s.error_estimate();
  EXPECT_NEAR(e64 / e8, 8.0 / 64.0, 0.5 * 8.0 / 64.0);  // unbiased estimator: error ~ 1/spp

  p.max_depth = 0;  // emitters only: every pixel here is black
  auto dark = make_render_scene(desc, p);
  RenderSession d(*dark, p);
  d.render_all();
  EXPECT_TRUE(std::isfinite(d.error_estimate()));
  EXPECT_LT(d.error_estimate(), 1e-3);
}

// A 5x5 film of 64 samples a pixel, halves of 32: every pixel's halves have means 0.49 and 0.51
// but the centre's, which are given.
namespace centre_of_five {
constexpr int w = 5, h = 5, n = 64, p = 32;
double estimate_with_centre(double first_half_mean, double second_half_mean) {
  std::vector<uint32_t> count(w * h, n), half_n(w * h, p);
  std::vector<double> s1(w * h), half(w * h);
  for (int i = 0; i < w * h; ++i) {
    half[i] = 0.49 * p;
    s1[i] = half[i] + 0.51 * (n - p);
  }
  half[12] = first_half_mean * p;
  s1[12] = half[12] + second_half_mean * (n - p);
  return halves_error_estimate(w, count, half_n, s1, half);
}
// Var[mean] of a pixel whose halves' means are a and b.
double var_of_mean(double a, double b) { return (a - b) * (a - b) * p * (n - p) / double(n * n); }
}  // namespace centre_of_five

// The estimate's denominator: a firefly (a pixel far above its neighbours, from one half of its
// samples) divides by its neighbourhood, not by its inflated mean; a bright edge (in both halves)
// keeps its own level, the smaller of its halves' means.
TEST(ErrorEstimateDenominator, FireflyUsesItsNeighbourhoodBrightEdgeKeepsItsOwnLevel) {
  using namespace centre_of_five;
  double quiet = estimate_with_centre(0.49, 0.51);
  // Firefly: one sample of 620 in the second half lifts that half's mean to about 20.
  double firefly = estimate_with_centre(0.5, 20.0);
  double var_mean = var_of_mean(0.5, 20.0);
  double own = var_mean / (10.25 * 10.25 + kRelMseEpsilon) / (w * h);   // divided by its own mean
  double neighbourhood = var_mean / (0.5 * 0.5 + kRelMseEpsilon) / (w * h);
  EXPECT_NEAR(firefly - quiet, neighbourhood, 0.01 * neighbourhood) << "own-mean figure: " << own;
  // Bright edge: both halves about 10, no more noisy than its neighbours relative to its mean.
  double edge = estimate_with_centre(9.8, 10.2);
  double edge_var = var_of_mean(9.8, 10.2);
  EXPECT_NEAR(edge - quiet, edge_var / (9.8 * 9.8 + kRelMseEpsilon) / (w * h) - quiet / (w * h), 1e-8);
}

// A dark pixel whose mean is within its standard error of its neighbourhood's level (the mean of
// its 3x3 means less the largest: here (0.3 + 7 x 0.5) / 8) divides by that level, not by its own
// small and noisy mean (which inflates the estimate at low spp); one that is surely darker (an
// edge) is lifted by at most its standard error.
TEST(ErrorEstimateDenominator, ANoisyDarkPixelTakesItsNeighbourhoodsLevelASurelyDarkOneKeepsItsOwn) {
  using namespace centre_of_five;
  const double quiet_pixel = var_of_mean(0.49, 0.51) / (0.5 * 0.5 + kRelMseEpsilon) / (w * h);
  const double quiet = estimate_with_centre(0.49, 0.51);
  // Mean 0.3, standard error 0.25: the neighbourhood's 0.475 is within reach.
  const double noisy = estimate_with_centre(0.05, 0.55);
  EXPECT_NEAR(noisy - quiet, var_of_mean(0.05, 0.55) / (0.475 * 0.475 + kRelMseEpsilon) / (w * h) - quiet_pixel, 1e-9)
      << "own-mean figure: " << var_of_mean(0.05, 0.55) / (0.3 * 0.3 + kRelMseEpsilon) / (w * h) - quiet_pixel;
  // Mean 0.1, standard error 0.01: divided by 0.1 + 0.01.
  const double dark = estimate_with_centre(0.09, 0.11);
  EXPECT_NEAR(dark - quiet, var_of_mean(0.09, 0.11) / (0.11 * 0.11 + kRelMseEpsilon) / (w * h) - quiet_pixel, 1e-12);
}

// The estimate runs in blocks of pixels on the render's threads and adds the blocks' sums in
// order: any thread count gives the same bits, on a film of several blocks with fireflies.
TEST(ErrorEstimateThreads, TheSameBitsOnAnyThreadCount) {
  const int w = 400, h = 300;
  std::vector<uint32_t> count(w * h), half_n(w * h);
  std::vector<double> s1(w * h), half(w * h);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < w * h; ++i) {
    count[i] = 2 + rng() % 63;
    half_n[i] = 1u << (31 - __builtin_clz(count[i] - 1));
    half[i] = u(rng) * half_n[i];
    s1[i] = half[i] + (u(rng) < 0.01 ? 50.0 : u(rng)) * (count[i] - half_n[i]);  // 1% fireflies
  }
  const double one = halves_error_estimate(w, count, half_n, s1, half, {}, 1);
  EXPECT_TRUE(std::isfinite(one) && one > 0) << one;
  for (int threads : {2, 3, 8}) EXPECT_EQ(halves_error_estimate(w, count, half_n, s1, half, {}, threads), one) << threads;
}

// Pixels that see only background add their samples as zeros in one step (add_zero_samples);
// they still keep the halves the estimate compares. A frame of background only is exactly black
// and converged: its estimate is unknown after one sample (INFINITY) and 0 from two on.
TEST(ErrorEstimateBackground, AFrameOfBackgroundOnlyIsConvergedFromTwoSamples) {
  SceneDesc d;
  d.materials.resize(1);
  d.spheres.push_back({"aside", Vec3(50, 0, -5), 1.0f, 0});  // in front (-z) but far out of view
  d.camera.present = true;
  for (bool packets : {true, false})
    for (float lens : {0.0f, 0.05f}) {
      RenderParams p;
      p.file_camera = true;
      p.width = 24;
      p.height = 16;
      p.adaptive = false;
      p.spp = 16;
      p.lens_radius = lens;
      p.focal_distance = 2;
      auto scene = make_render_scene(d, p);
      forms::Scoped forms;
      forms->packets = packets;
      RenderSession s(*scene, p);
      for (int fy = 0; fy < p.height; ++fy)
        for (int fx = 0; fx < p.width; ++fx) ASSERT_TRUE(s.sees_only_background(fx, fy)) << fx << " " << fy;
      for (int target = 1; target <= p.spp; target *= 2) {
        s.render_pass(target);
        if (target == 1) EXPECT_EQ(s.error_estimate(), INFINITY) << "packets " << packets << ", lens " << lens;
        else EXPECT_EQ(s.error_estimate(), 0.0) << target << " spp, packets " << packets << ", lens " << lens;
      }
      EXPECT_EQ(s.stats().samples, uint64_t(p.width) * p.height * p.spp);
    }
}

TEST(ErrorEstimateText, ANumberOrNotAvailableNeverInf) {
  EXPECT_EQ(format_error_estimate(0.00123), "0.00123");
  EXPECT_EQ(format_error_estimate(0), "0");
  EXPECT_EQ(format_error_estimate(INFINITY), "n/a");
  EXPECT_EQ(format_error_estimate(NAN), "n/a");
}

// Towards an error target a pass aims where the estimate's 1/spp decay meets the target when that
// comes sooner than doubling, so that the render stops near the target, not up to a doubling past.
TEST(NextPassTarget, AimsWhereTheErrorMeetsTheTargetWhenThatIsSoonerThanDoubling) {
  EXPECT_EQ(next_pass_target(64, 4096, 0.1, 0), 128);          // no target: doubling
  EXPECT_EQ(next_pass_target(64, 100, 0.1, 0), 100);           // never past the budget
  EXPECT_EQ(next_pass_target(64, 4096, 0.1, 0.01), 128);       // 640 needed: doubling comes first
  EXPECT_EQ(next_pass_target(64, 4096, 0.013, 0.01), 88);      // 83.2 needed, 5% past it: 87.4
  EXPECT_EQ(next_pass_target(64, 4096, 0.0101, 0.01), 80);     // 64.6 needed: a quarter more at least
  EXPECT_EQ(next_pass_target(1, 4096, 0.0101, 0.01), 2);       // one more at least
  EXPECT_EQ(next_pass_target(64, 4096, INFINITY, 0.01), 128);  // no estimate yet
  EXPECT_EQ(next_pass_target(64, 70, 0.013, 0.01), 70);        // the budget still caps it
}

TEST(NextPassTarget, ARenderStopsNearItsErrorTargetNotADoublingPast) {
  SceneDesc desc = load_collada(test::own_scene("dof.dae"));
  const RenderParams p = small_render(64, 48, 4096);
  auto scene = make_render_scene(desc, p);
  // The error at 64 spp, then a target a quarter below it: 1/spp reaches it near 85 spp, where
  // doubling passes would render 128.
  double error64 = 0;
  {
    RenderSession s(*scene, p);
    s.render_pass(64);
    error64 = s.error_estimate();
  }
  RunLimits limits;
  limits.target_error = 0.75 * error64;
  RenderSession s(*scene, p);
  std::vector<PassReport> passes;
  const StopReason why = run_progressive(s, limits, nullptr, {}, [&](const PassReport& r) { passes.push_back(r); });
  EXPECT_EQ(why, StopReason::target_error);
  ASSERT_GE(passes.size(), 8u);
  EXPECT_EQ(passes[6].target_spp, 64);  // 1, 2, 4, ... 64 as before
  EXPECT_LT(passes.back().target_spp, 128);
  EXPECT_LE(passes.back().error, limits.target_error);
}

// The estimate is computed once for the statistics of each pass and asked for again at the end of
// a render (the CLI's summary line and EXR header, a job's final report). A render cut short in
// the middle of a pass (here a cancel after some tiles of the fourth pass) still reports what its
// last samples say, and an estimate asked for before a pass is never the one given after it.
TEST(ErrorEstimateCache, OncePerPassNeverStaleAfterAPassEvenACutOne) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  RenderParams p = small_render(64, 48, 64);
  p.threads = 1;  // so that the cancel falls after a known number of tiles
  auto scene = make_render_scene(desc, p);

  RenderSession cut(*scene, p);
  ASSERT_GT(cut.tiles().size(), 2u);
  std::atomic<bool> cancel{false};
  std::vector<PassReport> passes;
  size_t tiles = 0;
  const size_t cancel_at = 3 * cut.tiles().size() + cut.tiles().size() / 2;  // midway through pass 4
  const StopReason why = run_progressive(cut, {}, &cancel, [&](const Tile&) { if (++tiles == cancel_at) cancel = true; },
                                         [&](const PassReport& r) { passes.push_back(r); });
  EXPECT_EQ(why, StopReason::cancelled);
  ASSERT_EQ(passes.size(), 4u);
  EXPECT_EQ(cut.film().error_estimates_computed(), 4u) << "one estimate a pass";
  EXPECT_EQ(cut.error_estimate(), passes.back().error) << "the last pass's samples, the half-pass included";
  EXPECT_EQ(cut.film().error_estimates_computed(), 4u) << "asked again with no new samples: not computed again";
  EXPECT_NE(passes[2].error, passes[3].error) << "the cut pass added samples, and its estimate saw them";

  // Asked after every pass or only at the end, the same statistics give the same estimate.
  RenderSession every(*scene, p), once(*scene, p);
  std::vector<double> each;
  for (int target : {2, 4, 8}) {
    every.render_pass(target);
    each.push_back(every.error_estimate());
    once.render_pass(target);
  }
  EXPECT_EQ(once.error_estimate(), each.back());
  EXPECT_EQ(once.film().error_estimates_computed(), 1u);
  EXPECT_NE(each[0], each[1]);
  EXPECT_NE(each[1], each[2]);
}
