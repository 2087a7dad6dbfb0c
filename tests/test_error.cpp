// Error against run time: the reference-free error estimate tracks the true error.
#include <gtest/gtest.h>

#include "collada.h"
#include "render.h"
#include "test_util.h"

using namespace pt;


class ErrorEstimate : public ::testing::TestWithParam<SamplerKind> {};

TEST_P(ErrorEstimate, StaysWithinAFactorOf1p5OfTheTrueErrorAcrossTheRun) {
  SceneDesc desc = load_collada(test::own_scene("dof.dae"));
  RenderParams p;
  p.file_camera = true;
  p.width = 40;
  p.height = 30;
  p.max_depth = 3;
  p.adaptive = false;
  p.threads = 2;
  p.spp = 4096;
  p.seed = 99;
  auto scene = make_render_scene(desc, p);
  RenderSession ref(*scene, p);
  ref.render_all();
  ImageRGB reference = ref.image();
  double ref_error = ref.error_estimate();  // the reference's own noise, removed from the truth

  p.spp = 256;
  p.seed = 1;
  p.sampler = GetParam();
  RenderSession s(*scene, p);
  int checked = 0;
  for (int target = 1; target <= p.spp; target *= 2) {
    s.render_pass(target);
    if (target < 8) continue;  // a per-pixel variance from fewer samples is too rough to judge
    double truth = relative_mse(s.image(), reference) - ref_error;
    double estimate = s.error_estimate();
    EXPECT_GT(estimate, truth / 1.5) << target << " spp";
    EXPECT_LT(estimate, truth * 1.5) << target << " spp";
    ++checked;
  }
  EXPECT_EQ(checked, 6);
}

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
