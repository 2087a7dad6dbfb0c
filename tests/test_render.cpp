// Image tests: analytic furnaces, estimator agreement, the course's depth sequence (our Cornell
// box, and CBspheres where ../shared has it), determinism across thread counts and cells. Tolerances come from the images' own noise.
#include <gtest/gtest.h>

#include <cstring>
#include <algorithm>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>

#include "collada.h"
#include "loop_forms.h"
#include "session.h"
#include "test_util.h"

using namespace pt;
using test::RegionStats;
using test::region_stats;

namespace {

ImageRGB render(const SceneDesc& desc, const RenderParams& p, SessionStats* stats = nullptr) {
  auto scene = make_render_scene(desc, p);
  RenderSession s(*scene, p);
  s.render_all();
  if (stats) *stats = s.stats();
  EXPECT_EQ(s.stats().nonfinite, 0u);
  return s.image();
}

// A diffuse sphere (albedo rho, radius 1, at the origin) with a camera node at `camera_z`
// looking down -z and optionally a point light of intensity 1 at the origin.
std::string sphere_scene(float rho, float camera_z, bool point_light) {
  return test::diffuse_sphere_scene(rho, camera_z, 30, point_light ? "<point><color>1 1 1</color>"
      "<constant_attenuation>1</constant_attenuation><linear_attenuation>0</linear_attenuation>"
      "<quadratic_attenuation>0</quadratic_attenuation></point>" : "");
}

// Mean over the whole image with a tolerance of `sigmas` standard errors (pixels are independent).
void expect_image_mean(const ImageRGB& img, double expected, double sigmas, const std::string& what) {
  RegionStats r = region_stats(img, 0, 0, img.width, img.height);
  double tol = sigmas * r.stderr_ + 1e-4 * expected;
  EXPECT_NEAR(r.mean, expected, tol) << what << " (stderr " << r.stderr_ << ")";
}

struct Pixel {
  int x, y;
};
Pixel project(const Camera& c, Vec3 p) {
  Vec3 v = p - c.position;
  float z = -dot(v, c.back);
  float sx = (dot(v, c.right) / z / c.tan_half_w + 1) / 2, sy = (dot(v, c.up) / z / c.tan_half_h + 1) / 2;
  return {int(sx * c.width), int((1 - sy) * c.height)};
}
RegionStats around(const ImageRGB& img, Pixel c, int half) {
  return region_stats(img, std::max(0, c.x - half), std::max(0, c.y - half), std::min(img.width, c.x + half + 1),
                      std::min(img.height, c.y + half + 1));
}

// Per-pixel difference of two renders with the same expectation: its mean is zero within its
// own standard error, free of the scene's spatial variation.
RegionStats difference(const ImageRGB& a, const ImageRGB& b, int x0, int y0, int x1, int y1) {
  ImageRGB d = a;
  for (size_t i = 0; i < d.pixels.size(); ++i) d.pixels[i] = a.pixels[i] - b.pixels[i];
  return region_stats(d, x0, y0, x1, y1);
}

// Median luminance of a square region: robust to a small highlight inside it.
double median_around(const ImageRGB& img, Pixel c, int half) {
  std::vector<double> v;
  for (int y = std::max(0, c.y - half); y < std::min(img.height, c.y + half + 1); ++y)
    for (int x = std::max(0, c.x - half); x < std::min(img.width, c.x + half + 1); ++x) v.push_back(luminance(img.at(x, y)));
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

// Inside a closed diffuse sphere of albedo rho and radius R with a point light of intensity I at
// its centre, every wall point receives E0 = I / R^2 directly and the same radiosity from the
// rest of the sphere, so L_m = rho E0 / pi * sum_{k < m} rho^k and L_inf = rho E0 / (pi (1 - rho)).
TEST(Furnace, PointLightInsideADiffuseSphere) {
  const float rho = 0.5f;
  SceneDesc desc = parse_collada(sphere_scene(rho, 0, true), "furnace.dae");
  RenderParams p;
  p.file_camera = true;
  p.width = p.height = 12;
  p.adaptive = false;
  p.threads = 2;
  const double e0 = 1.0 / kPi * rho;
  for (int m : {0, 1, 2, 3, 1000}) {
    p.max_depth = m;
    p.spp = m <= 1 ? 4 : 512;
    double expected = 0, term = e0;
    for (int k = 0; k < std::min(m, 200); ++k, term *= rho) expected += term;
    ImageRGB img = render(desc, p);
    expect_image_mean(img, expected, 4.5, "depth " + std::to_string(m));
  }
}

// A convex diffuse sphere under a uniform environment of radiance 1 reflects rho; the
// background shows the environment itself.
TEST(Furnace, DiffuseSphereUnderAUniformEnvironment) {
  ImageRGB env;
  env.width = 64;
  env.height = 32;
  env.pixels.assign(size_t(env.width) * env.height, Vec3(1.0f));
  std::string env_path = test::temp_dir() + "/white_env.exr";
  write_image(env, env_path);

  const float rho = 0.8f;
  SceneDesc desc = parse_collada(sphere_scene(rho, 20, false), "env_furnace.dae");
  RenderParams p;
  p.file_camera = true;
  p.env_map = env_path;
  p.width = p.height = 64;
  p.adaptive = false;
  p.threads = 2;
  p.spp = 64;
  for (int m : {0, 1, 4}) {
    p.max_depth = m;
    ImageRGB img = render(desc, p);
    // The sphere (radius 1 at distance 20, 30 degree FOV) covers the central ~14 pixels.
    RegionStats sphere = region_stats(img, 28, 28, 36, 36);
    RegionStats corner = region_stats(img, 0, 0, 6, 6);
    double expected = m == 0 ? 0.0 : rho;
    EXPECT_NEAR(sphere.mean, expected, 4.5 * sphere.stderr_ + 2e-3) << "depth " << m;
    EXPECT_NEAR(corner.mean, 1.0, 1e-3) << "background, depth " << m;
  }
}

// Light sampling with MIS and the course's uniform-hemisphere estimator are both unbiased:
// they must agree within noise on a scene lit by an area light (our Cornell box: it needs no
// ../shared).
TEST(Estimators, LightSamplingAgreesWithHemisphereSampling) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  RenderParams p;
  p.width = 96;
  p.height = 72;
  p.adaptive = false;
  p.threads = 2;
  p.max_depth = 2;
  p.spp = 64;
  ImageRGB light = render(desc, p);
  p.hemisphere = true;
  p.spp = 512;
  ImageRGB hemi = render(desc, p);
  RegionStats a = region_stats(light, 0, 0, p.width, p.height);
  RegionStats d = difference(light, hemi, 0, 0, p.width, p.height);
  EXPECT_NEAR(d.mean, 0, 4.5 * d.stderr_) << "light sampling " << a.mean << " vs hemisphere " << a.mean - d.mean;
  EXPECT_LT(4.5 * d.stderr_, 0.05 * a.mean);  // sharp enough to catch a wrong pdf
  EXPECT_GT(a.mean, 0.05);
}

namespace {

// The course's depth sequence: m = 0 only the light; m = 1 both spheres dark; m >= 3 the glass
// sphere transmits and a caustic appears under it. For a scene with one area light, one glass and
// one mirror sphere: `wall` is a point of a wall in view, `caustic` where the glass sphere's
// caustic lands on the floor, relative to the sphere's centre.
void check_depth_sequence(const SceneDesc& desc, Vec3 wall, Vec3 caustic) {
  RenderParams p;
  p.width = 480;  // smaller sizes crop the light out of the course's view
  p.height = 360;
  p.adaptive = false;
  p.threads = 2;
  auto scene = make_render_scene(desc, p);
  const Camera& cam = scene->camera;
  ASSERT_EQ(desc.spheres.size(), 2u);
  ASSERT_EQ(desc.lights.size(), 1u);
  const SphereDesc* glass = nullptr;
  const SphereDesc* mirror = nullptr;
  for (const SphereDesc& s : desc.spheres)
    (desc.materials[s.material].type == MaterialType::glass ? glass : mirror) = &s;
  ASSERT_TRUE(glass && mirror);
  Pixel glass_px = project(cam, glass->center), mirror_px = project(cam, mirror->center);
  Pixel light_px = project(cam, desc.lights[0].position);
  Pixel wall_px = project(cam, wall);
  Pixel caustic_px = project(cam, glass->center + caustic);
  int disk = int(glass->radius / (length(glass->center - cam.position) * cam.tan_half_h) * p.height / 2);
  int r = int(0.3f * disk);  // the centre, where the glass sphere shows what lies behind it
  int rm = int(0.7f * disk);  // most of the mirror sphere, which reflects the walls
  ASSERT_GT(r, 2);

  std::vector<ImageRGB> img(6);
  for (int m = 0; m <= 5; ++m) {
    p.max_depth = m;
    p.spp = m == 0 ? 4 : 16;
    img[m] = render(desc, p);
  }
  // m = 0: the light panel and nothing else.
  EXPECT_GT(around(img[0], light_px, 2).mean, 5.0);
  EXPECT_EQ(around(img[0], wall_px, 5).mean, 0.0);
  EXPECT_EQ(around(img[0], glass_px, r).mean, 0.0);
  EXPECT_EQ(around(img[0], mirror_px, rm).mean, 0.0);
  // m = 1: walls lit directly, both spheres dark apart from the light panel's reflection.
  RegionStats wall1 = around(img[1], wall_px, 5);
  EXPECT_GT(wall1.mean, 0.2);
  EXPECT_LT(median_around(img[1], glass_px, rm), 0.1 * wall1.mean);
  EXPECT_LT(median_around(img[1], mirror_px, rm), 0.1 * wall1.mean);
  // m = 2: the mirror shows the lit room; the glass still shows only emitters through it.
  EXPECT_GT(median_around(img[2], mirror_px, rm), 0.15 * wall1.mean);
  EXPECT_GT(median_around(img[2], mirror_px, rm), 5 * median_around(img[1], mirror_px, rm));
  RegionStats glass2 = around(img[2], glass_px, r), glass3 = around(img[3], glass_px, r);
  EXPECT_LT(median_around(img[2], glass_px, r), 0.1 * wall1.mean);
  // m >= 3: the glass transmits the lit room behind it.
  EXPECT_GT(glass3.mean, glass2.mean + 5 * (glass3.stderr_ + glass2.stderr_));
  EXPECT_GT(glass3.mean, 0.3 * wall1.mean);
  // ... and focuses the light into a caustic on the floor that m = 2 lacks.
  RegionStats caustic2 = around(img[2], caustic_px, 3), caustic3 = around(img[3], caustic_px, 3);
  EXPECT_GT(caustic3.mean, caustic2.mean + 4 * (caustic3.stderr_ + caustic2.stderr_))
      << "caustic m=3 " << caustic3.mean << " vs m=2 " << caustic2.mean;
  // Each depth adds light (all bounce orders are summed), within noise.
  for (int m = 1; m <= 5; ++m) {
    RegionStats a = region_stats(img[m - 1], 0, 0, p.width, p.height), b = region_stats(img[m], 0, 0, p.width, p.height);
    EXPECT_GT(b.mean, a.mean - 3 * (a.stderr_ + b.stderr_)) << "depth " << m;
  }
}

}  // namespace

// Our Cornell box (scenes/README.md): the back wall at z = -1, the glass sphere (r 0.3) resting on
// the floor in front of the light, its caustic just in front of where it touches the floor.
TEST(DepthSequence, CornellShowsTheCourseEffects) {
  check_depth_sequence(load_collada(test::own_scene("cornell.dae")), Vec3(0, 0.4f, -1), Vec3(-0.04f, -0.299f, 0.12f));
}

// The course's CBspheres, where ../shared has it: the caustic pushed away from the light.
TEST(DepthSequence, CBspheresShowsTheCourseEffects) {
  PT_REQUIRE_SHARED_SCENE(path, "CBspheres.dae");
  SceneDesc desc = load_collada(path);
  float r = 0;
  for (const SphereDesc& s : desc.spheres)
    if (desc.materials[s.material].type == MaterialType::glass) r = s.radius;
  check_depth_sequence(desc, Vec3(0, 0.9f, -1), Vec3(0.1f, -r + 0.001f, 0.1f));
}

// Our Cornell box, with mirror, glass and caustic light paths (no ../shared needed).
TEST(Determinism, SameSeedSameImageWithOneOrTwoThreads) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  RenderParams p;
  p.width = 80;
  p.height = 60;
  p.spp = 40;  // > batch 32: adaptive stopping is exercised too
  p.max_depth = 4;
  p.threads = 1;
  ImageRGB a = render(desc, p);
  p.threads = 2;
  p.tile_size = 7;  // a different tile layout and order
  ImageRGB b = render(desc, p);
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(Vec3)), 0);
  p.seed = 1;
  ImageRGB c = render(desc, p);
  EXPECT_NE(std::memcmp(a.pixels.data(), c.pixels.data(), a.pixels.size() * sizeof(Vec3)), 0);
}

// SessionStats::cpu_seconds sums the render threads' own CPU time: positive, and never more than
// the threads could have run in the pass's wall time (a clock other than the threads' would break it).
TEST(Stats, CpuSecondsCountEveryRenderThreadWithinTheWallTime) {
  SceneDesc desc = parse_collada(sphere_scene(0.5f, 0, true), "furnace.dae");
  RenderParams p;
  p.file_camera = true;
  p.width = p.height = 32;
  p.adaptive = false;
  p.max_depth = 8;
  p.spp = 64;
  for (int threads : {1, 2}) {
    p.threads = threads;
    p.tile_size = 8;  // 16 tiles: both threads get work
    auto scene = make_render_scene(desc, p);
    RenderSession s(*scene, p);
    s.render_pass(16);
    const SessionStats one = s.stats();
    EXPECT_GT(one.cpu_seconds, 0) << threads;
    EXPECT_LE(one.cpu_seconds, threads * one.seconds * 1.02 + 0.002) << threads;
    s.render_pass(64);
    const SessionStats two = s.stats();
    EXPECT_GT(two.cpu_seconds, one.cpu_seconds) << "passes add up, threads " << threads;
    EXPECT_LE(two.cpu_seconds, threads * two.seconds * 1.02 + 0.004) << threads;
  }
}

// Threads take the costliest tiles first: before any pass, the tiles with the most pixels that see
// the scene (in raster order among equals), so background-only tiles come last; every pass renders
// every tile exactly once, whatever the order and thread count.
TEST(Schedule, TilesThatSeeTheSceneComeFirst) {
  SceneDesc d = test::two_small_spheres();
  RenderParams p;
  p.width = 96;
  p.height = 72;
  p.keep_fov = true;
  p.tile_size = 8;
  p.spp = 4;
  for (int threads : {1, 3}) {
    p.threads = threads;
    auto scene = make_render_scene(d, p);
    RenderSession s(*scene, p);
    auto scene_pixels = [&](const Tile& t) {
      int n = 0;
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x) n += !s.sees_only_background(x, p.height - 1 - y);
      return n;
    };
    for (int pass = 1; pass <= 2; ++pass) {
      std::mutex m;
      std::vector<Tile> order;
      s.render_pass(2 * pass, nullptr, [&](const Tile& t) {
        std::lock_guard<std::mutex> lock(m);
        order.push_back(t);
      });
      ASSERT_EQ(order.size(), s.tiles().size()) << "pass " << pass;
      std::set<std::pair<int, int>> seen;
      for (const Tile& t : order) EXPECT_TRUE(seen.insert({t.x0, t.y0}).second) << "tile twice: " << t.x0 << " " << t.y0;
      if (pass > 1 || threads > 1) continue;  // later passes follow measured times; threads interleave
      EXPECT_GT(scene_pixels(order.front()), 0);
      EXPECT_EQ(scene_pixels(order.back()), 0) << "the spheres leave background-only tiles";
      for (size_t k = 1; k < order.size(); ++k)
        EXPECT_GE(scene_pixels(order[k - 1]), scene_pixels(order[k])) << "tile " << k;
    }
  }
}

TEST(Determinism, CellRenderEqualsThatWindowOfTheFullFrame) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  RenderParams p;
  p.width = 80;
  p.height = 60;
  p.spp = 8;
  p.max_depth = 3;
  ImageRGB full = render(desc, p);
  p.cell_x = 50;  // bottom-left origin, as in the course
  p.cell_y = 10;
  p.cell_w = 20;
  p.cell_h = 15;
  ImageRGB cell = render(desc, p);
  ASSERT_EQ(cell.width, 20);
  ASSERT_EQ(cell.height, 15);
  int top = p.height - (p.cell_y + p.cell_h);
  for (int y = 0; y < cell.height; ++y)
    for (int x = 0; x < cell.width; ++x) ASSERT_EQ(cell.at(x, y), full.at(p.cell_x + x, top + y)) << x << "," << y;
}

TEST(Adaptive, ConvergedPixelsStopEarlyAndAreNotBiased) {
  SceneDesc desc = parse_collada(sphere_scene(0.5f, 0, true), "furnace.dae");
  RenderParams p;
  p.file_camera = true;
  p.width = p.height = 8;
  p.max_depth = 1;  // noise-free: every pixel converges at the first check
  p.spp = 256;
  p.adaptive_batch = 32;
  auto scene = make_render_scene(desc, p);
  RenderSession s(*scene, p);
  s.render_all();
  // The first check is after sample index 32 (33 samples), as in the course.
  EXPECT_EQ(s.stats().samples, uint64_t(33 * 64));
  expect_image_mean(s.image(), 0.5 / kPi, 0, "adaptive mean");  // no n/(n-1) brightening
  RegionStats rate = region_stats(s.rate_image(), 0, 0, 8, 8, 2);
  EXPECT_GT(rate.mean, 0.6);  // blue-ish: few samples used
}

// Progress counts a pixel's whole budget once an adaptive stop ends it, and each sample added
// otherwise: a pass to t of spp samples is t / spp of the way, and an adaptive render that
// stopped every pixel early is all the way. Batched tiles credit it per tile, scalar ones per row.
TEST(Adaptive, ProgressCountsStoppedPixelsAsDone) {
  SceneDesc desc = parse_collada(sphere_scene(0.5f, 0, true), "furnace.dae");
  for (bool packets : {true, false}) {
    RenderParams p;
    p.file_camera = true;
    p.width = p.height = 8;
    p.max_depth = 1;
    p.spp = 256;
    p.adaptive_batch = 32;
    p.adaptive = false;
    auto scene = make_render_scene(desc, p);
    forms::Scoped forms;
    forms->packets = packets;
    RenderSession fixed(*scene, p);
    for (int target : {1, 16, 64}) {
      fixed.render_pass(target);
      EXPECT_DOUBLE_EQ(fixed.progress(), target / 256.0) << "packets " << packets;
    }
    p.adaptive = true;  // every pixel stops at its first check, after 33 samples
    RenderSession adaptive(*scene, p);
    adaptive.render_pass(16);
    EXPECT_DOUBLE_EQ(adaptive.progress(), 16 / 256.0) << "packets " << packets;
    adaptive.render_pass(64);
    ASSERT_EQ(adaptive.stats().samples, uint64_t(33 * 64));
    EXPECT_DOUBLE_EQ(adaptive.progress(), 1.0) << "packets " << packets;
  }
}

// Importance sampling of a high-dynamic-range environment (a bright "sun" 60x the dim sky)
// must be unbiased: it agrees with uniform hemisphere sampling within noise.
TEST(Estimators, EnvironmentImportanceSamplingIsUnbiased) {
  ImageRGB env;
  env.width = 64;
  env.height = 32;
  env.pixels.assign(size_t(env.width) * env.height, Vec3(0.05f, 0.08f, 0.1f));
  for (int y = 4; y < 10; ++y)
    for (int x = 16; x < 28; ++x) env.at(x, y) = Vec3(6, 5, 4);
  std::string env_path = test::temp_dir() + "/sun_env.exr";
  write_image(env, env_path);
  SceneDesc desc = parse_collada(sphere_scene(0.7f, 20, false), "env_sun.dae");
  RenderParams p;
  p.file_camera = true;
  p.env_map = env_path;
  p.width = p.height = 64;
  p.adaptive = false;
  p.threads = 2;
  p.max_depth = 1;
  p.cell_x = p.cell_y = 28;  // the central 8x8 pixels, all on the sphere
  p.cell_w = p.cell_h = 8;
  p.spp = 256;
  ImageRGB is = render(desc, p);
  p.hemisphere = true;
  p.spp = 8192;
  ImageRGB hemi = render(desc, p);
  RegionStats a = region_stats(is, 0, 0, 8, 8);
  RegionStats d = difference(is, hemi, 0, 0, 8, 8);
  double tol = 4.5 * d.stderr_;
  EXPECT_NEAR(d.mean, 0, tol) << "importance " << a.mean << " vs hemisphere " << a.mean - d.mean;
  EXPECT_GT(a.mean, 0.1);
  EXPECT_LT(tol, 0.05 * a.mean);  // the comparison is sharp enough to catch a wrong pdf
}
