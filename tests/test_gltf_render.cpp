// Image tests of glTF scenes: our glTF Cornell box renders to the COLLADA one's image within the
// noise (the same scene with an emissive quad for the area light and tessellated spheres), and
// textures and vertex colours show the colours they hold under the default light.
#include <gtest/gtest.h>

#include "gltf_docs.h"
#include "image.h"
#include "scene_file.h"
#include "session.h"
#include "test_util.h"
#include "texture.h"

using namespace pt;
using test::GltfDoc;
using test::json;
using test::kDefaultLightOnTheQuad;
using test::region_stats;
using test::RegionStats;

namespace {

ImageRGB render(const SceneDesc& desc, const RenderParams& p) {
  auto scene = make_render_scene(desc, p);
  RenderSession s(*scene, p);
  s.render_all();
  EXPECT_EQ(s.stats().nonfinite, 0u);
  return s.image();
}

// Per-pixel difference of two renders with the same expectation: zero mean within its own
// standard error (pixels are independent), whatever the scene's spatial variation.
RegionStats difference(const ImageRGB& a, const ImageRGB& b, int x0, int y0, int x1, int y1) {
  ImageRGB d = a;
  for (size_t i = 0; i < d.pixels.size(); ++i) d.pixels[i] = a.pixels[i] - b.pixels[i];
  return region_stats(d, x0, y0, x1, y1);
}

}  // namespace

TEST(GltfRender, CornellMatchesTheColladaCornellWithinNoise) {
  RenderParams p;
  p.width = 96;
  p.height = 72;
  p.spp = 64;
  p.max_depth = 5;
  p.adaptive = false;
  p.threads = 2;
  p.file_camera = true;  // the .dae's authored camera, which the .glb's is
  ImageRGB dae = render(load_scene(test::own_scene("cornell.dae")), p);
  p.seed = 1;  // independent noise
  ImageRGB glb = render(load_scene(test::own_scene("cornell_gltf.glb")), p);
  RegionStats all = region_stats(dae, 0, 0, p.width, p.height);
  RegionStats d = difference(glb, dae, 0, 0, p.width, p.height);
  EXPECT_NEAR(d.mean, 0, 4.5 * d.stderr_) << "glTF - COLLADA over the image, mean " << all.mean;
  EXPECT_LT(4.5 * d.stderr_, 0.03 * all.mean) << "too noisy to tell";
  // And in each of 4 x 3 blocks (walls, light, spheres, blocks), per channel: 36 tests at 4.5 sigma.
  for (int by = 0; by < 3; ++by)
    for (int bx = 0; bx < 4; ++bx)
      for (int c = 0; c < 3; ++c) {
        const int x0 = bx * 24, y0 = by * 24;
        ImageRGB diff = glb;
        for (size_t i = 0; i < diff.pixels.size(); ++i) diff.pixels[i] = glb.pixels[i] - dae.pixels[i];
        RegionStats b = region_stats(diff, x0, y0, x0 + 24, y0 + 24, c);
        EXPECT_NEAR(b.mean, 0, 4.5 * b.stderr_ + 1e-6) << "block " << bx << "," << by << " channel " << c;
      }
}

// A quad facing the camera, alone under the default light: a diffuse surface of albedo a reflects
// a x kDefaultLightOnTheQuad, so each quarter shows its texel's linear colour (scaled); uv (0, 0)
// is the image's top-left corner. KHR_materials_specular's factor 0 removes the specular layer:
// the base alone.
TEST(GltfRender, TexturesAndVertexColoursShowTheirColours) {
  GltfDoc g = test::quad_doc();
  const std::vector<uint8_t> texels = {255, 0, 0, 0, 255, 0, 0, 0, 255, 128, 128, 128};  // TL TR BL BR
  g.doc["images"] = json::array({json{{"uri", "data:image/png;base64," + test::base64(encode_png8(texels, 2, 2))}}});
  g.doc["samplers"] = json::array({json{{"magFilter", 9728}}});  // NEAREST
  g.doc["textures"] = json::array({json{{"source", 0}, {"sampler", 0}}});
  g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  g.doc["materials"][0]["extensions"]["KHR_materials_specular"] = {{"specularFactor", 0}};
  // Quad corners (-1,-1) (1,-1) (1,1) (-1,1): the top-left corner (-1, 1) gets uv (0, 0).
  g.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = g.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2);
  g.doc["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.01}}}}});
  g.root(json{{"camera", 0}, {"translation", {0, 0, 3}}});  // the quad fills the middle of the view
  RenderParams p;
  p.width = p.height = 64;
  p.spp = 256;
  p.max_depth = 1;
  p.adaptive = false;
  p.threads = 2;
  ImageRGB img = render(parse_gltf(g.text(), "textured.gltf", false), p);
  // The 2 x 2 quad at distance 3 is larger than the view (3 tan 0.25 = 0.77 each side of the
  // centre): a square 10 pixels off the centre lies inside each quarter of the texture.
  const int half = p.width / 2, r = 5;
  auto expect_quarter = [&](int qx, int qy, int texel) {
    const int cx = half + (qx ? 10 : -10) - r, cy = half + (qy ? 10 : -10) - r;
    for (int c = 0; c < 3; ++c) {
      RegionStats s = region_stats(img, cx, cy, cx + 2 * r, cy + 2 * r, c);
      double want = srgb8_to_linear(texels[size_t(3 * texel + c)]) * kDefaultLightOnTheQuad;
      EXPECT_NEAR(s.mean, want, 4.5 * s.stderr_ + 1e-3) << "quarter " << qx << "," << qy << " channel " << c;
    }
  };
  expect_quarter(0, 0, 0);  // top left: red
  expect_quarter(1, 0, 1);  // top right: green
  expect_quarter(0, 1, 2);  // bottom left: blue
  expect_quarter(1, 1, 3);  // bottom right: grey
  // Vertex colours multiply the base colour the same way.
  GltfDoc v = test::quad_doc();
  v.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] =
      v.floats({0.5f, 0.25f, 1, 0.5f, 0.25f, 1, 0.5f, 0.25f, 1, 0.5f, 0.25f, 1}, "VEC3", 3);
  v.doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {0.8, 0.8, 0.8, 1};
  v.doc["materials"][0]["extensions"]["KHR_materials_specular"] = {{"specularFactor", 0}};
  v.doc["cameras"] = g.doc["cameras"];
  v.root(json{{"camera", 0}, {"translation", {0, 0, 3}}});
  ImageRGB vc = render(parse_gltf(v.text(), "coloured.gltf", false), p);
  // 0.8 x (0.5, 0.25, 1), interpolated in floating point.
  const float colour[3] = {0.5f, 0.25f, 1.0f};
  for (int c = 0; c < 3; ++c) {
    RegionStats s = region_stats(vc, half - 8, half - 8, half + 8, half + 8, c);
    EXPECT_NEAR(s.mean, 0.8 * colour[c] * kDefaultLightOnTheQuad, 4.5 * s.stderr_ + 1e-4) << "channel " << c;
  }
}
