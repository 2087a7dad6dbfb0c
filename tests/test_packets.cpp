// Paths in packets (render_tile_batched, trace_paths_t): many camera paths advance together and
// their rays go to Embree in packets (16 rays, 8 without AVX-512). They must trace the paths the
// one-at-a-time loop traces: the same random numbers, the same shadow-ray sums in the same order,
// the same per-pixel statistics and adaptive stops. Embree's packet kernel may round a rare hit
// differently from its single-ray kernel (about 5 in 100,000 rays in the last bit), which sends
// that one path another way: a few pixels may differ, nothing else.
#include <gtest/gtest.h>

#include "collada.h"
#include "diffuse_lanes.h"
#include "loop_forms.h"
#include "session.h"
#include "test_util.h"

using namespace pt;

namespace {

struct Case {
  std::string name, path;
  RenderParams params;
};

std::vector<Case> cases() {
  std::vector<Case> out;
  RenderParams p;
  p.width = 64;
  p.height = 48;
  p.spp = 16;
  p.max_depth = 5;
  p.adaptive = false;
  p.threads = 2;
  p.keep_fov = true;
  out.push_back({"cornell: glass, mirror, spheres, light-traced caustics", test::own_scene("cornell.dae"), p});
  RenderParams lens = p;
  lens.lens_radius = 0.08f;
  lens.focal_distance = 4.42f;
  lens.light_samples = 3;
  out.push_back({"cornell through a thin lens, 3 light samples", test::own_scene("cornell.dae"), lens});
  RenderParams adaptive = p;
  adaptive.spp = 80;  // stop tests after samples 33 and 65, then the pass ends at 80
  adaptive.adaptive = true;
  adaptive.adaptive_tolerance = 0.2f;
  adaptive.tile_size = 7;
  out.push_back({"dof with adaptive stops", test::own_scene("dof.dae"), adaptive});
  RenderParams cell = p;
  cell.cell_x = 10, cell.cell_y = 5, cell.cell_w = 30, cell.cell_h = 20;
  out.push_back({"cornell, a -p cell", test::own_scene("cornell.dae"), cell});
  for (const char* f : {"CBbunny.dae", "CBdragon.dae", "CBspheres_microfacet_al_ag.dae"}) {
    std::string path = test::optional_shared_scene(f);
    if (!path.empty()) out.push_back({f, path, p});
  }
  return out;
}

// How many pixels differ at all.
size_t differing_pixels(const ImageRGB& a, const ImageRGB& b) {
  size_t n = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) n += !(a.pixels[i] == b.pixels[i]);
  return n;
}

}  // namespace

TEST(Packets, BatchedPathsRenderWhatThePathByPathLoopRenders) {
  std::string env_path = test::uniform_sky("packets_sky.exr", Vec3(0.3f, 0.4f, 0.6f));
  std::vector<Case> all = cases();
  RenderParams sky = all[0].params;
  sky.env_map = env_path;  // escaping rays look the environment up (the infinite-light loop)
  all.push_back({"dof under an environment", test::own_scene("dof.dae"), sky});

  for (const Case& c : all) {
    SCOPED_TRACE(c.name);
    SceneDesc desc = load_collada(c.path);
    RenderParams p = c.params;
    auto scene = make_render_scene(desc, p);
    ASSERT_NE(path_batch_tracer_for(scene->features.bits, PathSettings(p)), nullptr);
    RenderSession batched(*scene, p);
    batched.render_all();
    RenderSession single(*scene, p);
    {
      forms::Scoped one_by_one;
      one_by_one->packets = false;
      single.render_all();
    }
    ImageRGB a = batched.image(), b = single.image();
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    EXPECT_LE(differing_pixels(a, b), a.pixels.size() / 200) << "more than 0.5% of the pixels differ";
    EXPECT_EQ(batched.stats().samples, single.stats().samples);
    EXPECT_EQ(batched.film().done_mask(), single.film().done_mask()) << "adaptive stops differ";
    EXPECT_GT(batched.stats().samples, 0u);
    double ra = double(batched.stats().rays), rb = double(single.stats().rays);
    EXPECT_NEAR(ra, rb, 0.002 * rb) << "the batched loop counts its rays as the scalar one does";
  }
}

// The SSE2 and AVX2 lanes (diffuse_lanes.h) repeat path_step's generic vertex operation for
// operation (the path-by-path loop runs only the generic one): with them and without, the batched
// loop must render the same bits, count the same rays and stop the same pixels. Depth 8 makes
// paths reach Russian roulette (from the sixth vertex).
TEST(Packets, DiffuseLanesRenderTheBitsOfOneVertexAtATime) {
  std::vector<Case> all = cases();
  for (Case& c : all) c.params.max_depth = 8;
  all.push_back({"dof, depth 8", test::own_scene("dof.dae"), all[0].params});
  all.push_back({"cornell with a mesh light, depth 8", "", all[0].params});
  int laned = 0;
  for (const Case& c : all) {
    SCOPED_TRACE(c.name);
    SceneDesc desc = load_collada(c.path.empty() ? test::own_scene("cornell.dae") : c.path);
    if (c.path.empty()) test::area_lights_as_meshes(desc);  // sampled by triangle before the lanes
    RenderParams p = c.params;
    auto scene = make_render_scene(desc, p);
    laned += diffuse_lanes_apply(*scene, PathSettings(p));
    RenderSession without(*scene, p);
    {
      forms::Scoped scalar;
      scalar->lanes = false;
      EXPECT_FALSE(diffuse_lanes_apply(*scene, PathSettings(p)));
      without.render_all();
    }
    for (bool avx2 : {true, false}) {  // eight lanes where the CPU has AVX2, and four (SSE2)
      forms::Scoped width;
      width->avx2 = avx2;
      SCOPED_TRACE(testing::Message() << lanes::lane_width() << " lanes");
      RenderSession with(*scene, p);
      with.render_all();
      ImageRGB a = with.image(), b = without.image();
      ASSERT_EQ(a.pixels.size(), b.pixels.size());
      EXPECT_EQ(differing_pixels(a, b), 0u);
      EXPECT_EQ(with.stats().rays, without.stats().rays);
      EXPECT_EQ(with.film().done_mask(), without.film().done_mask());
      EXPECT_EQ(with.stats().nonfinite, 0u);
    }
  }
  EXPECT_GE(laned, 6) << "the own scenes' lights take the lanes: rectangles (1 or 3 samples), a mesh";
}

TEST(Packets, DiffuseLanesTakeOnlyAreaLights) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  RenderParams p;
  auto scene = make_render_scene(desc, p);
  EXPECT_TRUE(diffuse_lanes_apply(*scene, PathSettings(p)));
  p.light_samples = 4;
  EXPECT_TRUE(diffuse_lanes_apply(*scene, PathSettings(p)));
  p.hemisphere = true;
  EXPECT_FALSE(diffuse_lanes_apply(*scene, PathSettings(p)));
  p.hemisphere = false;
  SceneDesc meshed = desc;
  test::area_lights_as_meshes(meshed);
  auto mesh_lit = make_render_scene(meshed, p);
  ASSERT_EQ(mesh_lit->lights.size(), 1u);
  EXPECT_EQ(mesh_lit->lights[0].kind, LightKind::mesh);
  EXPECT_TRUE(diffuse_lanes_apply(*mesh_lit, PathSettings(p)));
  RenderScene other = *scene;
  Light point;
  point.kind = LightKind::point;
  point.color = Vec3(1.0f);
  other.lights.push_back(point);
  EXPECT_FALSE(diffuse_lanes_apply(other, PathSettings(p)));
}

TEST(Packets, HemisphereSamplingTracesPathByPath) {
  SceneDesc desc = load_collada(test::own_scene("dof.dae"));
  RenderParams p;
  p.hemisphere = true;  // its direct-light rays look emitters up one at a time
  auto scene = make_render_scene(desc, p);
  EXPECT_EQ(path_batch_tracer_for(scene->features.bits, PathSettings(p)), nullptr);
  p.hemisphere = false;
  EXPECT_NE(path_batch_tracer_for(scene->features.bits, PathSettings(p)), nullptr);
}
