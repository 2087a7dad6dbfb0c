// Leave out what a scene does not need: the derived feature set of every scene is what the file
// contains, the specialised path loop renders exactly what the generic one does, and views of one
// shared scene base render exactly what make_render_scene's scenes do.
#include <gtest/gtest.h>

#include <cstring>
#include <set>
#include <thread>

#include "collada.h"
#include "session.h"
#include "test_util.h"

using namespace pt;

namespace {

struct Expected {
  const char* file;
  bool shared;  // in ../shared/scenes-cs184 (else scenes/ or the build's generated scenes)
  std::set<std::string> materials, lights;
  bool spheres;
  uint32_t bits;
};

std::string path_of(const Expected& e) {
  if (e.shared) return test::optional_shared_scene(e.file);
  std::string own = test::own_scene(e.file);
  if (test::file_exists(own)) return own;
  std::string built = std::string(PT_BINARY_DIR) + "/scenes/" + e.file;
  return test::file_exists(built) ? built : "";
}

const Expected kScenes[] = {
    {"CBempty.dae", true, {"diffuse"}, {"point"}, false, 0},
    {"CBspheres_lambertian.dae", true, {"diffuse", "emission"}, {"area"}, true, 0},
    {"CBspheres.dae", true, {"diffuse", "emission", "glass", "mirror"}, {"area"}, true, kFeatDelta},
    {"CBspheres_microfacet_al_ag.dae", true, {"diffuse", "emission", "microfacet"}, {"area"}, true, kFeatMicrofacet},
    {"CBbunny.dae", true, {"diffuse", "emission"}, {"area"}, false, 0},
    {"CBdragon.dae", true, {"diffuse", "emission", "mirror"}, {"area", "mesh"}, false, kFeatDelta},
    {"cornell.dae", false, {"diffuse", "emission", "glass", "mirror"}, {"area"}, true, kFeatDelta},
    {"dof.dae", false, {"diffuse", "emission"}, {"area"}, true, 0},
    {"heavy.dae", false, {"diffuse", "emission", "microfacet"}, {"area"}, false, kFeatMicrofacet},
};

}  // namespace

TEST(Features, EveryScenesFeatureSetIsWhatTheFileContains) {
  int checked = 0;
  for (const Expected& e : kScenes) {
    std::string path = path_of(e);
    if (path.empty()) continue;
    SCOPED_TRACE(e.file);
    SceneDesc desc = load_collada(path);
    RenderParams p;
    auto scene = make_render_scene(desc, p);
    const SceneFeatures& f = scene->features;
    EXPECT_EQ(std::set<std::string>(f.materials.begin(), f.materials.end()), e.materials);
    EXPECT_EQ(std::set<std::string>(f.lights.begin(), f.lights.end()), e.lights);
    EXPECT_EQ(f.spheres, e.spheres);
    EXPECT_EQ(f.bits, e.bits);
    EXPECT_FALSE(f.environment);
    EXPECT_FALSE(f.thin_lens);
    ++checked;
  }
  EXPECT_GE(checked, 2);  // our own scenes are always there
}

TEST(Features, ParametersAddTheirFeatures) {
  SceneDesc desc = load_collada(test::own_scene("dof.dae"));
  ImageRGB env;
  env.width = 8;
  env.height = 4;
  env.pixels.assign(32, Vec3(0.5f));
  std::string env_path = test::temp_dir() + "/features_env.exr";
  write_image(env, env_path);
  RenderParams p;
  p.env_map = env_path;
  p.lens_radius = 0.1f;
  p.spp = 64;
  auto scene = make_render_scene(desc, p);
  EXPECT_TRUE(scene->features.environment);
  EXPECT_TRUE(scene->features.thin_lens);
  EXPECT_TRUE(scene->features.adaptive);
  EXPECT_EQ(scene->features.bits, uint32_t(kFeatInfinite));
}

TEST(Features, ZeroAreaAndBlackLightsAreLeftOut) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  LightDesc black = desc.lights[0];
  black.color = Vec3(0.0f);
  LightDesc flat = desc.lights[0];
  flat.dim_y = Vec3(0.0f);
  desc.lights.push_back(black);
  desc.lights.push_back(flat);
  auto scene = make_render_scene(desc, RenderParams());
  EXPECT_EQ(scene->lights.size(), 1u);
}

// Same seed, specialised vs generic loop: bit-identical images on every kind of scene.
TEST(Features, SpecialisedAndGenericLoopsRenderTheSameImage) {
  struct Case {
    std::string path;
    std::string env;
  };
  std::vector<Case> cases = {{test::own_scene("cornell.dae"), ""}, {test::own_scene("dof.dae"), ""}};
  for (const char* f : {"CBspheres_lambertian.dae", "CBspheres_microfacet_al_ag.dae", "CBempty.dae"}) {
    std::string p = test::optional_shared_scene(f);
    if (!p.empty()) cases.push_back({p, ""});
  }
  std::string env_path = test::uniform_sky("features_sky.exr", Vec3(0.3f, 0.4f, 0.6f));
  cases.push_back({test::own_scene("dof.dae"), env_path});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.path + " " + c.env);
    SceneDesc desc = load_collada(c.path);
    RenderParams p;
    p.width = 48;
    p.height = 36;
    p.spp = 8;
    p.max_depth = 5;
    p.light_samples = 2;
    p.file_camera = desc.camera.present;
    p.env_map = c.env;
    p.threads = 2;
    auto special = make_render_scene(desc, p);
    auto generic = make_render_scene(desc, p);
    generic->features.bits = kFeatAll;  // the loop with every feature
    ASSERT_NE(special->features.bits, uint32_t(kFeatAll)) << "this case does not exercise a specialisation";
    RenderSession a(*special, p), b(*generic, p);
    a.render_all();
    b.render_all();
    ImageRGB ia = a.image(), ib = b.image();
    EXPECT_EQ(std::memcmp(ia.pixels.data(), ib.pixels.data(), ia.pixels.size() * sizeof(Vec3)), 0);
    EXPECT_GT(a.stats().samples, 0u);
  }
}

// The server's sharing: one SceneBase (BVH, lights, materials) per scene file, a cheap view per
// job. Each view renders bit-identically to make_render_scene with the same options and seed.
TEST(Features, ViewsOfASharedBaseRenderWhatMakeRenderSceneRenders) {
  SceneDesc desc = load_collada(test::own_scene("cornell.dae"));
  std::string env_path = test::uniform_sky("features_shared_sky.exr", Vec3(0.2f, 0.3f, 0.5f));
  auto base = std::make_shared<const SceneBase>(make_scene_base(desc));
  ASSERT_TRUE(base->accel);
  EXPECT_GE(base->memory_bytes(), base->accel->memory_bytes());
  EXPECT_GT(base->accel->memory_bytes(), 0u);
  EXPECT_EQ(base->triangle_count, desc.triangle_count());

  std::vector<RenderParams> views(4);
  for (RenderParams& p : views) {
    p.width = 40;
    p.height = 30;
    p.spp = 8;
    p.max_depth = 4;
    p.light_samples = 2;
    p.seed = 5;
    p.threads = 1;
  }
  views[1].width = 24;  // another size and a thin lens
  views[1].lens_radius = 0.05f;
  views[1].focal_distance = 4;
  views[2].env_map = env_path;  // an environment map and the file's camera
  views[2].file_camera = desc.camera.present;
  views[3].spp = 64;  // adaptive
  std::vector<std::unique_ptr<RenderScene>> made;
  for (const RenderParams& p : views) made.push_back(make_view(*base, p));
  base.reset();  // the views keep what they share alive
  // Render all views at once: the shared BVH is read from several threads.
  std::vector<ImageRGB> images(views.size());
  std::vector<std::thread> threads;
  for (size_t i = 0; i < views.size(); ++i)
    threads.emplace_back([&, i] {
      RenderSession s(*made[i], views[i]);
      s.render_all();
      images[i] = s.image();
    });
  for (std::thread& t : threads) t.join();

  for (size_t i = 0; i < views.size(); ++i) {
    SCOPED_TRACE("view " + std::to_string(i));
    EXPECT_EQ(made[i]->accel, made[0]->accel) << "each view must share the base's BVH, not build its own";
    auto direct = make_render_scene(desc, views[i]);
    const SceneFeatures &a = made[i]->features, &b = direct->features;
    EXPECT_EQ(a.materials, b.materials);
    EXPECT_EQ(a.lights, b.lights);
    EXPECT_EQ(a.bits, b.bits);
    EXPECT_EQ(a.environment, b.environment);
    EXPECT_EQ(a.thin_lens, b.thin_lens);
    EXPECT_EQ(a.adaptive, b.adaptive);
    EXPECT_EQ(made[i]->lights.size(), direct->lights.size());
    EXPECT_EQ(made[i]->infinite_lights, direct->infinite_lights);
    RenderSession s(*direct, views[i]);
    s.render_all();
    ImageRGB want = s.image();
    ASSERT_EQ(images[i].pixels.size(), want.pixels.size());
    EXPECT_EQ(std::memcmp(images[i].pixels.data(), want.pixels.data(), want.pixels.size() * sizeof(Vec3)), 0);
  }
  EXPECT_TRUE(made[1]->features.thin_lens);
  EXPECT_TRUE(made[2]->features.environment);
}

// The base is what the file contains, whatever options a view adds later.
TEST(Features, SceneBaseHoldsNoOptions) {
  SceneDesc desc = load_collada(test::own_scene("dof.dae"));
  SceneBase base = make_scene_base(desc);
  EXPECT_FALSE(base.features.environment);
  EXPECT_FALSE(base.features.thin_lens);
  EXPECT_FALSE(base.features.adaptive);
  EXPECT_EQ(base.features.bits, 0u);
  EXPECT_EQ(base.camera.present, desc.camera.present);
  Bounds3 b = desc.geometry_bounds();
  EXPECT_EQ(base.bounds.lo, b.lo);
  EXPECT_EQ(base.bounds.hi, b.hi);
  // The camera made from the base equals the one made from the file.
  RenderParams p;
  p.file_camera = false;
  Camera from_base = make_view(base, p)->camera, from_file = make_camera(desc, camera_params(p));
  EXPECT_EQ(from_base.position, from_file.position);
  EXPECT_EQ(from_base.back, from_file.back);
  EXPECT_EQ(from_base.screen_distance, from_file.screen_distance);
}
