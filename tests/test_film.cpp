// Sample passes for distributed rendering (renderer/film.h): disjoint passes merge into the image
// one session renders; the wire encoding round-trips and refuses damaged buffers; adaptive
// convergence and the error estimate work on merged statistics.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "collada.h"
#include "session.h"
#include "test_util.h"

namespace pt {
namespace {

uint64_t samples_in(const Film& film) {
  uint64_t n = 0;
  for (size_t i = 0; i < film.pixels(); ++i) n += film.count(i);
  return n;
}

struct Fixture {
  RenderParams params;
  std::unique_ptr<RenderScene> scene;
  Fixture(int spp, bool adaptive) {
    params.width = 48;
    params.height = 36;
    params.spp = spp;
    params.max_depth = 4;
    params.adaptive = adaptive;
    params.threads = 2;
    params.seed = 11;
    params.tile_size = 16;
    SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
    scene = make_render_scene(desc, params);
  }
};

TEST(Film, DisjointPassesMergeIntoTheSessionImage) {
  Fixture f(16, false);
  RenderSession session(*f.scene, f.params);
  ASSERT_TRUE(session.render_all());
  ImageRGB whole = session.image();

  // Out of order and uneven, as workers return them.
  Film film(48, 36, f.params.spp, adaptive_rule(f.params), false);
  Film asked_once(48, 36, f.params.spp, adaptive_rule(f.params), false);  // the same merges, its estimate asked for only at the end
  std::vector<double> estimates;
  for (auto [first, count] : {std::pair<uint32_t, uint32_t>{8, 8}, {0, 1}, {2, 2}, {1, 1}, {4, 4}}) {
    const FilmPass pass = render_film_pass(*f.scene, f.params, first, count, {}, nullptr);
    film.merge(pass);
    asked_once.merge(pass);
    estimates.push_back(film.error_estimate());
  }
  // Each merge's estimate sees its samples (it is computed once per merge, never left stale).
  for (size_t k = 1; k < estimates.size(); ++k) EXPECT_NE(estimates[k], estimates[k - 1]) << k;
  EXPECT_EQ(asked_once.error_estimate(), estimates.back());
  EXPECT_TRUE(film.finished());
  EXPECT_EQ(samples_in(film), 48u * 36u * 16u);
  EXPECT_DOUBLE_EQ(film.progress(), 1.0);
  ImageRGB merged = film.image();
  double worst = 0;
  for (size_t i = 0; i < whole.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, double(std::abs(merged.pixels[i][c] - whole.pixels[i][c])) / (whole.pixels[i][c] + 1e-3));
  EXPECT_LT(worst, 1e-4) << "merged passes must hold the same samples as the session";
  // Light-traced caustics split by the same shares: the same light paths, none twice.
  EXPECT_GT(session.stats().light_paths, 0u);
  EXPECT_EQ(film.light_paths(), session.stats().light_paths);
  // Different samples make a visibly different image: the check above can fail.
  Film other(48, 36, f.params.spp, adaptive_rule(f.params), false);
  other.merge(render_film_pass(*f.scene, f.params, 16, 16, {}, nullptr));
  double diff = 0;
  for (size_t i = 0; i < whole.pixels.size(); ++i) diff = std::max(diff, double(std::abs(other.image().pixels[i][0] - whole.pixels[i][0])));
  EXPECT_GT(diff, 1e-3);
  EXPECT_TRUE(std::isfinite(film.error_estimate()));
  EXPECT_GT(film.error_estimate(), 0);
}

TEST(Film, EncodingRoundTripsAndRefusesDamage) {
  Fixture f(4, false);
  FilmPass p = render_film_pass(*f.scene, f.params, 0, 4, {}, nullptr);
  std::string bytes = p.encode();
  FilmPass q = FilmPass::decode(bytes, 48, 36);
  EXPECT_EQ(q.first, 0u);
  EXPECT_EQ(q.count, 4u);
  EXPECT_EQ(q.rays, p.rays);
  EXPECT_GT(p.light_paths, 0u);
  EXPECT_EQ(q.light_paths, p.light_paths);
  ASSERT_EQ(q.sum.size(), p.sum.size());
  ASSERT_EQ(q.caustic_sum.size(), p.caustic_sum.size());
  for (size_t i = 0; i < p.sum.size(); ++i) {
    EXPECT_EQ(q.sum[i][1], p.sum[i][1]);
    EXPECT_EQ(q.samples[i], p.samples[i]);
    EXPECT_EQ(q.caustic_sum[i][0], p.caustic_sum[i][0]);
  }
  FilmPass plain = p;  // a job with path-traced caustics sends none
  plain.caustic_sum.clear();
  plain.light_paths = 0;
  EXPECT_TRUE(FilmPass::decode(plain.encode(), 48, 36).caustic_sum.empty());
  EXPECT_EQ(plain.encode().size() + 48 * 36 * sizeof(Vec3), bytes.size());
  EXPECT_THROW(FilmPass::decode(bytes, 36, 48), std::runtime_error);                       // another film
  EXPECT_THROW(FilmPass::decode(bytes.substr(0, bytes.size() - 1), 48, 36), std::runtime_error);  // truncated
  EXPECT_THROW(FilmPass::decode(bytes.substr(0, 10), 48, 36), std::runtime_error);
  std::string bad = bytes;
  bad[0] = 'X';
  EXPECT_THROW(FilmPass::decode(bad, 48, 36), std::runtime_error);  // not a pass
  FilmPass nan = p;
  nan.sum[5] = Vec3(NAN, 0, 0);
  EXPECT_THROW(FilmPass::decode(nan.encode(), 48, 36), std::runtime_error);  // impossible values
  FilmPass nan_splat = p;
  nan_splat.caustic_sum[7] = Vec3(0, INFINITY, 0);
  EXPECT_THROW(FilmPass::decode(nan_splat.encode(), 48, 36), std::runtime_error);
  FilmPass many = p;
  many.samples[3] = 99;
  EXPECT_THROW(FilmPass::decode(many.encode(), 48, 36), std::runtime_error);
}

TEST(Film, SkippedPixelsTakeNoSamplesAndMasksRoundTrip) {
  Fixture f(8, false);
  std::vector<uint8_t> mask(48 * 36, 0);
  for (size_t i = 0; i < mask.size(); i += 3) mask[i] = 1;
  std::vector<uint8_t> back = unpack_mask(pack_mask(mask), mask.size());
  EXPECT_EQ(back, mask);
  EXPECT_EQ(pack_mask(mask).size(), (mask.size() + 7) / 8);
  FilmPass p = render_film_pass(*f.scene, f.params, 0, 8, back, nullptr);
  for (size_t i = 0; i < mask.size(); ++i) EXPECT_EQ(p.samples[i], mask[i] ? 0u : 8u) << i;
}

TEST(Film, AdaptiveSamplingConvergesOnMergedStatistics) {
  Fixture f(1024, true);
  Film film(48, 36, f.params.spp, adaptive_rule(f.params), false);
  uint64_t taken = 0;
  for (uint32_t first = 0; first < 1024 && !film.finished(); first += 64) {
    FilmPass p = render_film_pass(*f.scene, f.params, first, 64, film.done_mask(), nullptr);
    for (uint32_t c : p.samples) taken += c;
    film.merge(p);
  }
  EXPECT_EQ(samples_in(film), taken);
  // Converged pixels (the flat walls) stop early: far fewer samples than the budget.
  EXPECT_LT(double(taken), 0.8 * 48 * 36 * 1024);
  EXPECT_GT(film.progress(), 0.99);
  // The one rule: a pixel stopped before the budget crossed a test count (65, 129, ... for a batch
  // of 32) in its last pass of 64.
  for (size_t i = 0; i < film.pixels(); ++i)
    if (film.done(i) && film.count(i) < 1024u)
      EXPECT_TRUE(film.rule().test_due_within(film.count(i) - 64, film.count(i))) << i << ": " << film.count(i);
}

TEST(Film, AdaptiveRuleTestsAfterEachBatch) {
  AdaptiveRule rule{true, 32, 0.05};
  EXPECT_FALSE(rule.test_due(1));
  EXPECT_FALSE(rule.test_due(32));
  EXPECT_TRUE(rule.test_due(33));
  EXPECT_TRUE(rule.test_due(65));
  EXPECT_EQ(rule.next_test(0), 33u);
  EXPECT_EQ(rule.next_test(32), 33u);
  EXPECT_EQ(rule.next_test(33), 65u);
  EXPECT_TRUE(rule.test_due_within(32, 64));
  EXPECT_FALSE(rule.test_due_within(33, 64));
  EXPECT_TRUE(rule.test_due_within(33, 65));
  AdaptiveRule every{true, 1, 0.05};
  EXPECT_TRUE(every.test_due(2));
  EXPECT_EQ(every.next_test(5), 6u);
  AdaptiveRule off{false, 32, 0.05};
  EXPECT_FALSE(off.test_due(33));
  EXPECT_FALSE(off.test_due_within(0, 1000));
  // 1.96 sqrt(var / n) <= tolerance x mean: luminances 1 and 3, n = 2: mean 2, var 2, half-width 1.96.
  EXPECT_FALSE(rule.converged(4, 10, 2));
  EXPECT_TRUE((AdaptiveRule{true, 32, 0.98}.converged(4, 10, 2)));
  EXPECT_TRUE(rule.converged(2 * 40, 4 * 40, 40)) << "a constant pixel has converged";
}

TEST(Film, SessionPixelsStopOnlyAtTestCounts) {
  Fixture f(256, true);
  f.params.adaptive_batch = 8;
  RenderSession session(*f.scene, f.params);
  ASSERT_TRUE(session.render_all());
  const Film& film = session.film();
  size_t stopped = 0;
  for (size_t i = 0; i < film.pixels(); ++i) {
    ASSERT_TRUE(film.done(i));
    if (film.count(i) == 256u) continue;
    ++stopped;
    EXPECT_TRUE(film.rule().test_due(film.count(i))) << i << ": " << film.count(i);
  }
  EXPECT_GT(stopped, film.pixels() / 4) << "the walls converge early";
}

}  // namespace
}  // namespace pt

namespace pt {
namespace {

// A film saved and restored (checkpoints) holds the same statistics: the same image, mask and
// error estimate; a film of another size or a smaller budget, or a cut record, is refused.
TEST(Film, SaveAndRestoreKeepEveryStatistic) {
  Fixture f(64, true);
  RenderSession session(*f.scene, f.params);
  ASSERT_TRUE(session.render_all());
  const Film& film = session.film();
  ASSERT_TRUE(film.has_caustics());
  BinaryWriter out;
  film.save(out);
  Film back(48, 36, 64, adaptive_rule(f.params), true);
  BinaryReader in(out.bytes(), "film.bin");
  back.restore(in);
  EXPECT_TRUE(in.at_end());
  const ImageRGB a = film.image(), b = back.image();
  EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(Vec3)), 0);
  EXPECT_EQ(back.done_mask(), film.done_mask());
  EXPECT_EQ(back.light_paths(), film.light_paths());
  EXPECT_EQ(back.error_estimate(), film.error_estimate());
  for (auto [w, spp] : {std::pair{48, 32}, std::pair{64, 64}}) {  // a smaller budget, another size
    Film other(w, 36, spp, adaptive_rule(f.params), true);
    BinaryReader again(out.bytes(), "film.bin");
    EXPECT_THROW(other.restore(again), std::runtime_error) << w << " " << spp;
  }
  // A larger budget takes the film on: its budget-stopped pixels reopen; a merged film (made
  // without splat sums) gains the saved ones.
  Film larger(48, 36, 128, adaptive_rule(f.params), false);
  BinaryReader more(out.bytes(), "film.bin");
  larger.restore(more);
  EXPECT_TRUE(larger.has_caustics());
  EXPECT_EQ(larger.light_paths(), film.light_paths());
  EXPECT_TRUE(film.finished());
  EXPECT_FALSE(larger.finished());
  const ImageRGB c = larger.image();
  EXPECT_EQ(std::memcmp(a.pixels.data(), c.pixels.data(), a.pixels.size() * sizeof(Vec3)), 0);
  const std::string cut = out.bytes().substr(0, out.bytes().size() - 9);
  BinaryReader short_in(cut, "film.bin");
  try {
    back.restore(short_in);
    ADD_FAILURE() << "a cut record was restored";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("film.bin: damaged (cut short"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pt
