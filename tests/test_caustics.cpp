// Caustics by light tracing (renderer/caustics.h): the light tracer and the path tracer split the
// caustic paths between them, so the image converges to the path tracer's alone; the light tracer
// applies only where it can; images stay independent of the thread count.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <thread>

#include "caustics.h"
#include "collada.h"
#include "loop_forms.h"
#include "materials.h"
#include "session.h"
#include "test_util.h"

namespace pt {
namespace {

RenderParams cornell_params() {
  RenderParams p;
  p.width = 64;
  p.height = 48;
  p.spp = 64;
  p.max_depth = 4;
  p.adaptive = false;
  p.threads = 2;
  p.keep_fov = true;  // the whole view: a crop of the course's 800x600 view gets few splats
  return p;
}

// Independent renders (seeds) of one setting: per 16x16 block the mean luminance and its standard
// error, and the estimator's true relative variance per pixel (across seeds, as relMSE weighs it).
struct SeedStats {
  std::vector<double> mean, stderr_;
  double rel_variance = 0;
  uint64_t light_paths = 0;
  ImageRGB caustics;  // the first seed's light-traced part
};
constexpr int kBlock = 16;

std::vector<double> block_means(const ImageRGB& img) {
  std::vector<double> out;
  for (int by = 0; by + kBlock <= img.height; by += kBlock)
    for (int bx = 0; bx + kBlock <= img.width; bx += kBlock)
      out.push_back(test::region_stats(img, bx, by, bx + kBlock, by + kBlock).mean);
  return out;
}

SeedStats over_seeds(const SceneDesc& desc, RenderParams p, int seeds) {
  SeedStats st;
  std::vector<std::vector<double>> blocks;
  std::vector<double> s1, s2;
  for (int s = 0; s < seeds; ++s) {
    p.seed = uint64_t(100 + s);
    auto scene = make_render_scene(desc, p);
    RenderSession session(*scene, p);
    EXPECT_TRUE(session.render_all());
    ImageRGB img = session.image();
    blocks.push_back(block_means(img));
    s1.resize(img.pixels.size()), s2.resize(img.pixels.size());
    for (size_t i = 0; i < img.pixels.size(); ++i) {
      double l = luminance(img.pixels[i]);
      s1[i] += l, s2[i] += l * l;
    }
    if (s == 0) st.caustics = session.film().caustic_image();
    st.light_paths += session.stats().light_paths;
  }
  for (size_t k = 0; k < blocks[0].size(); ++k) {
    double a = 0, b = 0;
    for (const auto& r : blocks) a += r[k], b += r[k] * r[k];
    double m = a / seeds, var = std::max(0.0, (b - a * a / seeds) / (seeds - 1));
    st.mean.push_back(m);
    st.stderr_.push_back(std::sqrt(var / seeds));
  }
  for (size_t i = 0; i < s1.size(); ++i) {
    double m = s1[i] / seeds, var = std::max(0.0, (s2[i] - s1[i] * s1[i] / seeds) / (seeds - 1));
    st.rel_variance += var / (m * m + kRelMseEpsilon) / double(s1.size());
  }
  return st;
}

// The Cornell box with its area light turned into an emissive mesh (a mesh light: the light tracer
// samples its triangles) and the white surfaces into rough metal (splats evaluate a microfacet BRDF).
SceneDesc mesh_light_metal_cornell() {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  test::area_lights_as_meshes(desc);
  for (Material& m : desc.materials)
    if (m.name == "white") {
      m.type = MaterialType::microfacet;
      m.alpha = 0.3f;
      m.eta = Vec3(1.66f, 0.88f, 0.52f);  // aluminium
      m.k = Vec3(9.2f, 6.3f, 4.8f);
    }
  return desc;
}

// The Cornell box with an emissive quad in its area light's place: two emitters in one plane (as
// in the course's CBdragon), of which the path tracer sees one along each ray.
SceneDesc coplanar_emitters_cornell() {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  SceneDesc both = desc;
  test::area_lights_as_meshes(both);  // adds the quads and their material
  both.lights = desc.lights;          // and keeps the area lights
  return both;
}

enum class SplitScene { cornell, mesh_light_metal, coplanar_emitters };

struct SplitCase {
  const char* name;
  float lens_radius;  // 0: pinhole; else splats through the lens map to pixels as its rays do
  SplitScene scene;
};

class CausticSplit : public ::testing::TestWithParam<SplitCase> {
 protected:
  void SetUp() override {
    const SplitScene which = GetParam().scene;
    SceneDesc desc = which == SplitScene::mesh_light_metal    ? mesh_light_metal_cornell()
                     : which == SplitScene::coplanar_emitters ? coplanar_emitters_cornell()
                                                              : load_collada(test::own_scene("cornell.dae"));  // mirror, glass, area light
    RenderParams p = cornell_params();
    p.spp = 256;
    p.lens_radius = GetParam().lens_radius;
    p.focal_distance = 4.0f;  // the glass sphere sharp, the back wall blurred
    split = std::make_unique<SeedStats>(over_seeds(desc, p, 10));
    p.caustic_tracing = false;
    alone = std::make_unique<SeedStats>(over_seeds(desc, p, 10));
  }
  std::unique_ptr<SeedStats> split;  // light-traced caustics
  std::unique_ptr<SeedStats> alone;  // path tracing alone
};
INSTANTIATE_TEST_SUITE_P(Cases, CausticSplit,
                         ::testing::Values(SplitCase{"Pinhole", 0, SplitScene::cornell},
                                           SplitCase{"ThinLens", 0.12f, SplitScene::cornell},
                                           SplitCase{"MeshLightRoughMetal", 0, SplitScene::mesh_light_metal},
                                           SplitCase{"CoplanarEmitters", 0, SplitScene::coplanar_emitters}),
                         [](const auto& info) { return std::string(info.param.name); });

TEST_P(CausticSplit, SplitWithThePathTracerConvergesToThePathTracersImageAndRemovesMostOfItsNoise) {
  // The light tracer carries a share of some block far above the noise: were its paths lost,
  // counted twice, or their splats 25% off, that block would be off by over 6 standard errors.
  std::vector<double> share = block_means(split->caustics);
  double most = 0;
  for (size_t k = 0; k < share.size(); ++k) {
    double noise = std::hypot(split->stderr_[k], alone->stderr_[k]);
    EXPECT_LE(std::fabs(split->mean[k] - alone->mean[k]), 4.5 * noise + 1e-5)
        << "block " << k << ": with light tracing " << split->mean[k] << " +- " << split->stderr_[k]
        << ", path tracing alone " << alone->mean[k] << " +- " << alone->stderr_[k];
    most = std::max(most, share[k] / (noise + 1e-9));
  }
  EXPECT_GT(most, 25) << "the light-traced caustics must be a share of the image well above its noise";
  std::printf("largest light-traced share of a block: %.1f standard errors\n", most);

  EXPECT_GT(split->light_paths, 0u);
  EXPECT_EQ(alone->light_paths, 0u);
  // True variance across seeds (the path tracer's own estimate misses rare caustic paths).
  EXPECT_LT(split->rel_variance, 0.6 * alone->rel_variance) << split->rel_variance << " vs " << alone->rel_variance;
  std::printf("relative variance per pixel: %.4g with light tracing, %.4g without\n", split->rel_variance, alone->rel_variance);
}

TEST(Caustics, SameImageAtAnyThreadCount) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  RenderParams p = cornell_params();
  p.spp = 8;
  p.threads = 1;
  auto scene = make_render_scene(desc, p);
  RenderSession one(*scene, p);
  one.render_all();
  p.threads = 3;
  RenderSession three(*scene, p);
  three.render_all();
  ImageRGB a = one.image(), b = three.image();
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  for (size_t i = 0; i < a.pixels.size(); ++i) ASSERT_EQ(a.pixels[i], b.pixels[i]) << i;
  EXPECT_GT(one.stats().light_paths, 0u);
}

// A pass cut short anywhere (its light paths or its tiles) and then resumed ends on the
// uninterrupted render's film, bit for bit: the light paths of a cut are traced again, not skipped,
// and each pass opens the error estimate's light-path part once. Where each cut lands depends on
// the timing; the result must not.
TEST(Caustics, APassCutShortAndResumedEndsOnTheSameImage) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  RenderParams p = cornell_params();
  p.spp = 32;
  auto scene = make_render_scene(desc, p);
  RenderSession whole(*scene, p);
  whole.render_all();
  RenderSession cut(*scene, p);
  int cuts = 0;
  for (int target = 1; target <= p.spp; target *= 2)
    for (int delay_us : {0, 200, 2000}) {  // cuts early in the light paths, later, in the tiles
      std::atomic<bool> stop{delay_us == 0};
      std::thread stopper([&] {
        std::this_thread::sleep_for(std::chrono::microseconds(delay_us));
        stop = true;
      });
      cuts += !cut.render_pass(target, &stop);
      stopper.join();
      ASSERT_TRUE(cut.render_pass(target));  // resumed to the pass's end
    }
  EXPECT_GT(cuts, 0);
  EXPECT_EQ(cut.stats().light_paths, whole.stats().light_paths);
  const ImageRGB a = whole.image(), b = cut.image();
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(Vec3)), 0);
  EXPECT_EQ(cut.error_estimate(), whole.error_estimate());
}

// The pool of light paths makes the splats that one path after another makes: the same splats in
// path order, bit for bit (one-ray queries here, so the hits are the same), across refills.
TEST(Caustics, PooledLightPathsSplatAsOnePathAtATime) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  RenderParams p = cornell_params();
  auto scene = make_render_scene(desc, p);
  forms::Scoped one_ray_queries;
  one_ray_queries->packets = false;
  ASSERT_TRUE(scene->features.caustic_tracing);
  const CausticFilm film{p.width, p.height, 0, 0, p.width, p.height};
  std::vector<CausticSplat> pooled, single;
  uint64_t pooled_rays = 0, single_rays = 0;
  const uint64_t first = 1000, count = 700;  // more paths than the pool's slots
  trace_caustic_paths(*scene, p, film, first, count, pooled, pooled_rays);
  for (uint64_t i = first; i < first + count; ++i) trace_caustic_paths(*scene, p, film, i, 1, single, single_rays);
  ASSERT_GT(pooled.size(), 50u);
  ASSERT_EQ(pooled.size(), single.size());
  for (size_t k = 0; k < pooled.size(); ++k) {
    ASSERT_EQ(pooled[k].pixel, single[k].pixel) << k;
    ASSERT_EQ(std::memcmp(&pooled[k].value, &single[k].value, sizeof(Vec3)), 0) << k;
  }
  EXPECT_EQ(pooled_rays, single_rays);
}

// Light paths check what a ray sees at their light only where an emitter shares its plane with
// another surface; other scenes do not pay that ray.
TEST(Caustics, OnlyEmittersThatShareAPlaneCostTheCheck) {
  SceneDesc cornell = load_collada(test::own_scene("cornell.dae"));
  EXPECT_FALSE(emitters_share_a_plane(cornell, cornell.materials));
  SceneDesc both = coplanar_emitters_cornell();
  EXPECT_TRUE(emitters_share_a_plane(both, both.materials));
  SceneDesc meshed = cornell;
  test::area_lights_as_meshes(meshed);  // one quad: its two triangles are one emitter
  EXPECT_FALSE(emitters_share_a_plane(meshed, meshed.materials));
  // A quad of the ceiling's material laid over the light, in its plane.
  SceneDesc covered = meshed;
  MeshDesc cover = covered.meshes.back();
  cover.tri_material.assign(cover.tri_material.size(), 0);
  ASSERT_FALSE(is_emissive(covered.materials[0]));
  covered.meshes.push_back(cover);
  EXPECT_TRUE(emitters_share_a_plane(covered, covered.materials));
  // Lifted off the plane by more than a spawned ray's offset, it no longer does.
  Vec3 normal = normalize(cross(cover.positions[1] - cover.positions[0], cover.positions[2] - cover.positions[0]));
  for (Vec3& v : covered.meshes.back().positions) v = v + normal * 0.01f;
  EXPECT_FALSE(emitters_share_a_plane(covered, covered.materials));
  for (const char* f : {"CBdragon.dae", "CBspheres.dae", "CBbunny.dae"}) {
    std::string path = test::optional_shared_scene(f);
    if (path.empty()) continue;
    SceneDesc desc = load_collada(path);
    EXPECT_EQ(emitters_share_a_plane(desc, desc.materials), std::string(f) == "CBdragon.dae") << f;
  }
}

TEST(Caustics, AppliesOnlyWhereItCan) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  auto applies = [&](RenderParams p) {
    auto scene = make_render_scene(desc, p);
    return scene->features.caustic_tracing;
  };
  RenderParams p = cornell_params();
  EXPECT_TRUE(applies(p));
  RenderParams q = p;
  q.caustic_tracing = false;
  EXPECT_FALSE(applies(q));
  q = p;
  q.lens_radius = 0.05f;  // splats through the lens
  EXPECT_TRUE(applies(q));
  q.focal_distance = 0;  // a lens focused on itself maps nothing to the sensor
  EXPECT_FALSE(applies(q));
  q = p;
  q.spp = 1;  // one sample is the pixel centre
  EXPECT_FALSE(applies(q));
  q = p;
  q.hemisphere = true;
  EXPECT_FALSE(applies(q));
  q = p;
  q.max_depth = 1;  // no room for a delta bounce
  EXPECT_FALSE(applies(q));
  // An emissive mesh is a light the light tracer samples too.
  auto mesh_lit = make_render_scene(mesh_light_metal_cornell(), p);
  ASSERT_TRUE(mesh_lit->features.caustic_tracing);
  ASSERT_EQ(mesh_lit->caustic_lights.size(), 1u);
  EXPECT_EQ(mesh_lit->lights[mesh_lit->caustic_lights[0]].kind, LightKind::mesh);
  // Without delta materials there is nothing to aim at.
  SceneDesc diffuse = desc;
  for (Material& m : diffuse.materials)
    if (is_delta(m)) m.type = MaterialType::diffuse;
  EXPECT_FALSE(make_render_scene(diffuse, p)->features.caustic_tracing);
}

// Light paths are counted per pixel of the scene's projected bounds inside the frame. A close
// view (the course's framing crops the middle of its 800x600 view) projects the box far past the
// frame; counted unclipped, that once traced one light path per camera sample, 44% of the render
// time on CBspheres for no better image.
TEST(Caustics, LightPathsFollowTheSceneAreaInsideTheFrame) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  auto light_paths = [&](RenderParams p) {
    p.spp = 8;
    auto scene = make_render_scene(desc, p);
    RenderSession s(*scene, p);
    s.render_all();
    return double(s.stats().light_paths) / (double(p.width) * p.height * p.spp);
  };
  RenderParams p = cornell_params();
  p.keep_fov = false;  // the box covers the whole frame and reaches far past it
  double close = light_paths(p);
  EXPECT_GT(close, 0.14);
  EXPECT_LT(close, 0.16);  // 0.15 per visible scene pixel, not per pixel of the unclipped box
  p.keep_fov = true;  // the whole view: the box covers part of the frame
  double whole = light_paths(p);
  EXPECT_GT(whole, 0.01);
  EXPECT_LT(whole, 0.9 * close);
}

TEST(Caustics, ManyDeltaObjectsShareOneTargetThatHoldsThemAll) {
  SceneDesc desc;
  Material glass;
  glass.type = MaterialType::glass;
  desc.materials = {glass};
  for (int i = 0; i < 100; ++i) desc.spheres.push_back({"s", Vec3(float(i % 10), 0.5f, float(i / 10)), 0.25f, 0});
  std::vector<CausticTarget> t = find_caustic_targets(desc, desc.materials);
  ASSERT_EQ(t.size(), 1u) << "light paths weigh every cone: past the limit one sphere holds them all";
  for (const SphereDesc& s : desc.spheres) EXPECT_LE(length(s.center - t[0].center) + s.radius, t[0].radius);
  desc.spheres.resize(3);
  EXPECT_EQ(find_caustic_targets(desc, desc.materials).size(), 3u);
}

}  // namespace
}  // namespace pt
