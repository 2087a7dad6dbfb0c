// Leave out what a scene does not need: the derived feature set of every scene is what the file
// contains, and the specialised path loop renders exactly what the generic one does.
#include <gtest/gtest.h>

#include <cstring>
#include <set>

#include "collada.h"
#include "render.h"
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
  if (e.shared) return test::shared_scene(e.file);
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
  p.generic = true;
  EXPECT_EQ(make_render_scene(desc, p)->features.bits, uint32_t(kFeatAll));
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
    std::string p = test::shared_scene(f);
    if (!p.empty()) cases.push_back({p, ""});
  }
  ImageRGB env;
  env.width = 16;
  env.height = 8;
  env.pixels.assign(128, Vec3(0.3f, 0.4f, 0.6f));
  std::string env_path = test::temp_dir() + "/features_sky.exr";
  write_image(env, env_path);
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
    p.generic = true;
    auto generic = make_render_scene(desc, p);
    ASSERT_NE(special->features.bits, uint32_t(kFeatAll)) << "this case does not exercise a specialisation";
    RenderSession a(*special, p), b(*generic, p);
    a.render_all();
    b.render_all();
    ImageRGB ia = a.image(), ib = b.image();
    EXPECT_EQ(std::memcmp(ia.pixels.data(), ib.pixels.data(), ia.pixels.size() * sizeof(Vec3)), 0);
    EXPECT_GT(a.stats().samples, 0u);
  }
}
