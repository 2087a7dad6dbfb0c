// Sample passes for distributed rendering (renderer/film.h): disjoint passes merge into the image
// one session renders; the wire encoding round-trips and refuses damaged buffers; adaptive
// convergence and the error estimate work on merged statistics.
#include <gtest/gtest.h>

#include <cmath>

#include "collada.h"
#include "film.h"
#include "test_util.h"

namespace pt {
namespace {

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
  FilmAccumulator film(f.params, 48, 36);
  FilmAccumulator asked_once(f.params, 48, 36);  // the same merges, its estimate asked for only at the end
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
  EXPECT_EQ(film.samples(), 48u * 36u * 16u);
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
  FilmAccumulator other(f.params, 48, 36);
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
  FilmAccumulator film(f.params, 48, 36);
  uint64_t taken = 0;
  for (uint32_t first = 0; first < 1024 && !film.finished(); first += 64) {
    FilmPass p = render_film_pass(*f.scene, f.params, first, 64, film.done(), nullptr);
    for (uint32_t c : p.samples) taken += c;
    film.merge(p);
  }
  EXPECT_EQ(film.samples(), taken);
  // Converged pixels (the flat walls) stop early: far fewer samples than the budget.
  EXPECT_LT(double(taken), 0.8 * 48 * 36 * 1024);
  EXPECT_GT(film.progress(), 0.99);
}

}  // namespace
}  // namespace pt
