// Each running pixel's predicted stop (AdaptiveRule::predicted_stop, film.h): the adaptive rule's
// own test solved for the sample count.
#include <gtest/gtest.h>

#include <cmath>

#include "film.h"
#include "rng.h"

using namespace pt;

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
