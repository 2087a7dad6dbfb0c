// Denoising: the features the path loop gathers (albedo and normal at the first surface that is
// not a perfect mirror or glass), the film that sums, merges and checkpoints them, the denoiser
// (Intel Open Image Denoise, loaded at run time) and the CLI's --denoise.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cstdlib>
#include <fstream>

#include "binary_io.h"
#include "collada.h"
#include "film_denoise.h"
#include "film_pass.h"
#include "loop_forms.h"
#include "session.h"
#include "test_util.h"

using namespace pt;

namespace {

RenderParams small_params(int spp) {
  RenderParams p;
  p.width = 64, p.height = 48, p.spp = spp, p.max_depth = 5, p.adaptive = false, p.threads = 2, p.keep_fov = true;
  return p;
}

// The denoiser, or a skip here and a failure under CI=true (scripts/test.sh installs it).
bool need_denoiser() {
  if (Denoiser::shared().available()) return true;
  if (test::under_ci()) ADD_FAILURE() << "under CI=true the denoiser must be installed: " << Denoiser::shared().description();
  return false;
}

size_t differing(const ImageRGB& a, const ImageRGB& b) {
  size_t n = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) n += !(a.pixels[i] == b.pixels[i]);
  return n;
}

}  // namespace

TEST(DenoiseFeatures, GatheringThemLeavesTheImageBitsAsTheyAre) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  RenderParams p = small_params(8);
  auto scene = make_render_scene(desc, p);
  RenderSession plain(*scene, p);
  plain.render_all();
  RenderParams pf = p;
  pf.features = true;
  RenderSession with(*scene, pf);
  with.render_all();
  EXPECT_FALSE(plain.film().has_features());  // leave-out: nothing allocated without denoising
  ASSERT_TRUE(with.film().has_features());
  EXPECT_EQ(differing(plain.image(), with.image()), 0u);
  EXPECT_EQ(plain.stats().rays, with.stats().rays);
}

// The pool (packets, diffuse lanes) and the one-path-at-a-time loop gather the same features, up
// to the packet kernel's rare rounding of a hit (test_packets.cpp).
TEST(DenoiseFeatures, BothLoopsGatherTheSameFeatures) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  RenderParams p = small_params(4);
  p.features = true;
  auto scene = make_render_scene(desc, p);
  RenderSession batched(*scene, p), single(*scene, p);
  batched.render_all();
  {
    forms::Scoped one_by_one;
    one_by_one->packets = false;
    single.render_all();
  }
  const FilmFeatures a = batched.film().features(), b = single.film().features();
  const size_t n = a.albedo.pixels.size();
  EXPECT_LE(differing(a.albedo, b.albedo), n / 200);
  EXPECT_LE(differing(a.normal, b.normal), n / 200);
  size_t lit = 0;  // the box's walls fill much of the view
  for (const Vec3& v : a.albedo.pixels) lit += max_component(v) > 0.05f;
  EXPECT_GT(lit, n / 3);
}

// A diffuse sphere of albedo 0.6 seen head-on: its centre's albedo is 0.6 and its normal faces the
// camera; the background's features are zero (no surface, no environment).
TEST(DenoiseFeatures, ADiffuseSphereShowsItsAlbedoAndNormal) {
  const std::string path = (test::temp_dir() + "/" + "denoise_sphere.dae");
  std::ofstream(path) << test::diffuse_sphere_scene(0.6f, 4, 40, "<point><color>1 1 1</color></point>");
  SceneDesc desc = load_collada(path);
  RenderParams p = small_params(4);
  p.features = true;
  p.file_camera = true;
  auto scene = make_render_scene(desc, p);
  RenderSession s(*scene, p);
  s.render_all();
  const FilmFeatures f = s.film().features();
  const Vec3 centre_albedo = f.albedo.at(32, 24), centre_normal = f.normal.at(32, 24);
  EXPECT_NEAR(centre_albedo.x, 0.6f, 1e-4f);
  EXPECT_NEAR(centre_albedo.y, 0.6f, 1e-4f);
  EXPECT_NEAR(centre_normal.z, 1.0f, 0.01f);  // towards the camera at +z
  EXPECT_EQ(f.albedo.at(0, 0), Vec3(0.0f));
  EXPECT_EQ(f.normal.at(0, 0), Vec3(0.0f));
}

// Passes merged carry their features, the parts keep their colour, a checkpoint keeps them all, and
// a film of the other kind refuses it by name.
TEST(DenoiseFilm, FeaturesMergeAndRestoreExactly) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  RenderParams p = small_params(8);
  p.features = true;
  p.caustic_tracing = false;  // the parts' colour alone (splats add their own parts)
  auto scene = make_render_scene(desc, p);
  const std::vector<uint8_t> none;
  const FilmPass a = render_film_pass(*scene, p, 0, 4, none, nullptr), b = render_film_pass(*scene, p, 4, 4, none, nullptr);
  ASSERT_EQ(a.albedo_sum.size(), size_t(64 * 48));
  const FilmPass back = FilmPass::decode(a.encode(), 64, 48);
  EXPECT_EQ(back.albedo_sum, a.albedo_sum);
  EXPECT_EQ(back.normal_sum, a.normal_sum);
  Film film(64, 48, 8, adaptive_rule(p), false, true);
  film.merge(a), film.merge(b);
  const FilmFeatures f = film.features();
  for (size_t i = 0; i < f.albedo.pixels.size(); i += 97)
    EXPECT_EQ(f.albedo.pixels[i], (a.albedo_sum[i] + b.albedo_sum[i]) / 8.0f);
  ImageRGB first, rest;
  ASSERT_TRUE(film.part_images(first, rest));
  for (size_t i = 0; i < first.pixels.size(); i += 97) {
    EXPECT_EQ(first.pixels[i], a.sum[i] / 4.0f);  // the first pass went to the first part
    EXPECT_NEAR(rest.pixels[i].y, b.sum[i].y / 4.0f, 1e-6f + 1e-6f * b.sum[i].y);  // (a + b) - a
  }
  BinaryWriter out;
  film.save(out);
  Film restored(64, 48, 8, adaptive_rule(p), false, true);
  BinaryReader in(out.bytes(), "test checkpoint");
  restored.restore(in);
  EXPECT_EQ(restored.features().albedo.pixels, f.albedo.pixels);
  EXPECT_EQ(restored.features().normal.pixels, f.normal.pixels);
  Film plain(64, 48, 8, adaptive_rule(p), false, false);
  BinaryReader again(out.bytes(), "test checkpoint");
  try {
    plain.restore(again);
    ADD_FAILURE() << "a film without features took a checkpoint with them";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("denoiser's features"), std::string::npos) << e.what();
  }
}

// A pass whose features could not come from its samples (an albedo mean above 1) is refused.
TEST(DenoiseFilm, AForgedFeatureSumIsRefused) {
  FilmPass p;
  p.width = 2, p.height = 1, p.first = 0, p.count = 4;
  p.sum.assign(2, Vec3(1.0f)), p.lum2.assign(2, 1.0f), p.samples.assign(2, 4u);
  p.albedo_sum.assign(2, Vec3(4.0f)), p.normal_sum.assign(2, Vec3(0.0f));
  EXPECT_NO_THROW(FilmPass::decode(p.encode(), 2, 1));
  p.albedo_sum[1] = Vec3(40.0f);
  EXPECT_THROW(FilmPass::decode(p.encode(), 2, 1), std::runtime_error);
}

TEST(DenoiseEstimate, TheDenoisedHalvesNoiseIsTheirWeightedSquaredDifference) {
  ImageRGB a = make_image(2, 1, [](size_t) { return Vec3(1.0f); });
  ImageRGB b = make_image(2, 1, [](size_t i) { return Vec3(i ? 3.0f : 1.0f); });
  ImageRGB whole = make_image(2, 1, [](size_t) { return Vec3(2.0f); });
  EXPECT_DOUBLE_EQ(denoised_noise(a, a, whole, {0.25f, 0.25f}), 0.0);
  // Pixel 1: 0.25 (1 - 3)^2 / (4 + eps), averaged over two pixels.
  EXPECT_NEAR(denoised_noise(a, b, whole, {0.25f, 0.25f}), 0.5 * 1.0 / (4 + kRelMseEpsilon), 1e-6);
}

TEST(Denoiser, RefusesVersionsOutsideTwoPointThreeToTwo) {
  EXPECT_EQ(oidn_version_problem(20501), "");
  EXPECT_EQ(oidn_version_problem(20300), "");
  EXPECT_NE(oidn_version_problem(20200).find("2.2.0 is not supported"), std::string::npos);
  EXPECT_NE(oidn_version_problem(30000), "");
}

// At 8 spp the denoised image is much nearer a 256-spp reference than the raw one, and the
// denoising leaves the film's raw image and estimate as they were.
TEST(Denoiser, BringsALowSampleRenderNearerTheReference) {
  if (!need_denoiser()) GTEST_SKIP() << Denoiser::shared().description();
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  RenderParams p = small_params(256);
  auto scene = make_render_scene(desc, p);
  RenderSession reference(*scene, p);
  reference.render_all();
  RenderParams lo = p;
  lo.spp = 8, lo.features = true, lo.seed = 7;
  RenderSession s(*scene, lo);
  s.render_all();
  const ImageRGB raw = s.image();
  const double raw_estimate = s.error_estimate();
  for (DenoiseQuality q : {DenoiseQuality::preview, DenoiseQuality::final}) {
    SCOPED_TRACE(denoise_quality_name(q));
    const DenoisedFilm d = denoise_film(s.film(), q, 2, true);
    ASSERT_TRUE(d.ok) << d.error;
    const double raw_err = relative_mse(raw, reference.image()), den_err = relative_mse(d.image, reference.image());
    EXPECT_LT(den_err, raw_err / 3) << "raw " << raw_err << ", denoised " << den_err;
    EXPECT_TRUE(std::isfinite(d.noise));
    EXPECT_LT(d.noise, raw_estimate);  // the denoised halves differ less than the raw ones
    EXPECT_EQ(differing(s.image(), raw), 0u);
    EXPECT_EQ(s.error_estimate(), raw_estimate);
  }
}

// --denoise: the denoised image, and in an EXR the raw colour, albedo and normal as layers.
TEST(DenoiseCli, WritesTheDenoisedImageWithTheRawAndTheFeaturesAsLayers) {
  if (!need_denoiser()) GTEST_SKIP() << Denoiser::shared().description();
  const std::string out = (test::temp_dir() + "/" + "denoise_cli.exr");
  const test::RunResult r = test::run_command(std::string(PT_PATHTRACER) + " -t 2 -s 8 -m 4 -r 64 48 --quiet --denoise -f " +
                                              out + " " + test::own_scene("cornell.dae"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("denoised in"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(raw)"), std::string::npos) << r.output;
  auto in = OIIO::ImageInput::open(out);
  ASSERT_TRUE(in);
  const OIIO::ImageSpec& spec = in->spec();
  ASSERT_EQ(spec.nchannels, 12);
  const std::vector<std::string> want = {"R", "G", "B", "albedo.R", "albedo.G", "albedo.B",
                                         "normal.X", "normal.Y", "normal.Z", "raw.R", "raw.G", "raw.B"};
  for (int c = 0; c < 12; ++c) EXPECT_EQ(spec.channelnames[size_t(c)], want[size_t(c)]);
  EXPECT_NE(spec.get_string_attribute("pathtracer:denoised").find("Open Image Denoise"), std::string::npos);
  std::vector<float> px(size_t(64 * 48 * 12));
  ASSERT_TRUE(in->read_image(0, 0, 0, 12, OIIO::TypeDesc::FLOAT, px.data()));
  double diff = 0;
  for (size_t i = 0; i < size_t(64 * 48); ++i) diff += std::fabs(px[i * 12] - px[i * 12 + 9]);
  EXPECT_GT(diff, 0.0) << "the denoised colour is the raw one";
}

TEST(DenoiseCli, AMissingLibraryIsOneClearMessage) {
  const test::RunResult r = test::run_command("PT_OIDN_LIB=/nonexistent/libOpenImageDenoise.so.2 " + std::string(PT_PATHTRACER) +
                                              " -s 1 -r 8 8 --denoise -f " + (test::temp_dir() + "/" + "x.png") + " " +
                                              test::own_scene("cornell.dae"));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("not installed"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("scripts/install-oidn.sh"), std::string::npos) << r.output;
  EXPECT_FALSE(test::file_exists((test::temp_dir() + "/" + "x.png")));
}

TEST(DenoiseCli, AWrongVersionIsOneClearMessage) {
  const test::RunResult r = test::run_command(std::string("FAKE_OIDN_VERSION=10700 PT_OIDN_LIB=") + PT_FAKE_OIDN + " " +
                                              PT_PATHTRACER + " -s 1 -r 8 8 --denoise -f " + (test::temp_dir() + "/" + "v.png") +
                                              " " + test::own_scene("cornell.dae"));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("1.7.0 is not supported"), std::string::npos) << r.output;
}

// A denoiser that fails (out of memory) costs the denoised image, not the render.
TEST(DenoiseCli, AFailingDenoiserLeavesTheRawImageWithAWarning) {
  const std::string out = (test::temp_dir() + "/" + "failing.png");
  const test::RunResult r = test::run_command(std::string("FAKE_OIDN_FAIL=1 PT_OIDN_LIB=") + PT_FAKE_OIDN + " " +
                                              PT_PATHTRACER + " -s 2 -r 16 12 --quiet --denoise -f " + out + " " +
                                              test::own_scene("cornell.dae"));
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("warning: denoiser: out of memory"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("writing the raw image"), std::string::npos) << r.output;
  EXPECT_TRUE(test::file_exists(out));
}

// The error log denoises every pass at both qualities: each quality keeps its filters, so a whole
// render makes one fast filter and the final quality's three (albedo, normal, colour), however many
// passes it logs.
TEST(DenoiseCli, EachQualityKeepsItsFiltersFromPassToPass) {
  const std::string dir = test::temp_dir();
  const test::RunResult r = test::run_command(std::string("FAKE_OIDN_COUNT=1 PT_OIDN_LIB=") + PT_FAKE_OIDN + " " +
                                              PT_PATHTRACER + " -t 2 -s 16 -r 16 12 --quiet --no-adaptive --denoise --error-log " +
                                              dir + "/filters.csv -f " + dir + "/filters.exr " + test::own_scene("cornell.dae"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("fake-oidn: 4 filters made"), std::string::npos) << r.output;
}

// Whatever the library writes, no NaN reaches the image: its pixel keeps the raw colour.
TEST(DenoiseCli, ANonFiniteDenoiserOutputNeverReachesTheImage) {
  const std::string out = test::temp_dir() + "/nan.exr";
  const test::RunResult r = test::run_command(std::string("FAKE_OIDN_NAN=1 PT_OIDN_LIB=") + PT_FAKE_OIDN + " " +
                                              PT_PATHTRACER + " -s 2 -r 16 12 --quiet --denoise -f " + out + " " +
                                              test::own_scene("cornell.dae"));
  ASSERT_EQ(r.status, 0) << r.output;
  const ImageRGB img = read_image(out);
  for (const Vec3& v : img.pixels) ASSERT_TRUE(is_finite(v));
}

// A non-finite feature (a NaN normal from a degenerate triangle) counts as zero, as a non-finite
// sample does: nothing non-finite reaches the denoiser.
TEST(DenoiseFilm, NonFiniteFeaturesAndSamplesNeverReachTheDenoiser) {
  Film film(2, 1, 4, AdaptiveRule{false}, false, true);
  uint64_t nonfinite = 0;
  film.add_sample(0, 0, Vec3(NAN, 1, 1), nonfinite);
  film.add_features(0, Vec3(NAN, 0.5f, 0.5f), Vec3(0, INFINITY, 0));
  film.add_sample(0, 1, Vec3(0.5f), nonfinite);
  film.add_features(0, Vec3(0.5f), Vec3(0, 0, 1));
  EXPECT_EQ(nonfinite, 1u);
  const FilmFeatures f = film.features();
  EXPECT_EQ(f.albedo.at(0, 0), Vec3(0.25f));  // (0 + 0.5) / 2
  EXPECT_EQ(f.normal.at(0, 0), Vec3(0, 0, 0.5f));
  for (const Vec3& v : film.image().pixels) EXPECT_TRUE(is_finite(v));
}
