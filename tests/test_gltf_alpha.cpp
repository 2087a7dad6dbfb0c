// glTF alpha (alphaMode MASK with alphaCutoff, BLEND as stochastic pass-through) for camera,
// bounce and shadow rays: a black quad in front of an emitter shows the emitter where it is cut
// out, (1 - alpha) of it where it blends; a cut-out occluder lets the sun through to a floor.
#include <gtest/gtest.h>

#include <cmath>

#include "gltf_docs.h"
#include "image.h"
#include "png_rgba.h"
#include "session.h"
#include "test_util.h"

using namespace pt;
using test::GltfDoc;
using test::json;
using test::region_stats;
using test::RegionStats;

namespace {

ImageRGB render(const std::string& text, int spp, int depth) { return test::render_gltf(text, spp, depth); }

// The mean of each quarter's inner square (10 pixels off the centre).
constexpr int kHalf = 24, kR = 4;
RegionStats quarter(const ImageRGB& img, int q, int c) {
  const int cx = kHalf + (q % 2 ? 10 : -10) - kR, cy = kHalf + (q / 2 ? 10 : -10) - kR;
  return region_stats(img, cx, cy, cx + 2 * kR, cy + 2 * kR, c);
}

// Texel alphas (top-left, top-right, bottom-left, bottom-right) of the 2 x 2 RGBA texture.
const uint8_t kAlpha[4] = {0, 100, 200, 255};
const Vec3 kGlow{1.0f, 0.5f, 0.25f};

// A black quad (no specular layer) at z = 0, its base colour texture's alpha kAlpha, filling the
// view of a camera 3 units in front; behind it, at z = -1, a larger emitter of radiance kGlow.
GltfDoc cutout_scene(const json& alpha) {
  GltfDoc g = test::quad_doc();
  json& prim = g.doc["meshes"][0]["primitives"][0];
  prim["attributes"]["TEXCOORD_0"] = g.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2);
  std::vector<uint8_t> rgba;
  for (uint8_t a : kAlpha) rgba.insert(rgba.end(), {255, 255, 255, a});
  g.doc["images"] = json::array({json{{"uri", "data:image/png;base64," + test::base64(test::encode_png_rgba(rgba, 2, 2))}}});
  g.doc["samplers"] = json::array({json{{"magFilter", 9728}, {"wrapS", 33071}, {"wrapT", 33071}}});
  g.doc["textures"] = json::array({json{{"source", 0}, {"sampler", 0}}});
  json m = {{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}, {"metallicFactor", 0}, {"baseColorTexture", {{"index", 0}}}}},
            {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0}}}}}};
  m.update(alpha);
  g.doc["materials"][0] = m;
  const int glow = g.material(json{{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}},
                                   {"emissiveFactor", {kGlow.x, kGlow.y, kGlow.z}}});
  g.mesh(json{{"POSITION", prim["attributes"]["POSITION"]}}, prim["indices"], glow,
         json{{"translation", {0, 0, -1}}, {"scale", {3, 3, 1}}});
  g.doc["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.01}}}}});
  g.root(json{{"camera", 0}, {"translation", {0, 0, 3}}});
  return g;
}

void expect_quarters(const ImageRGB& img, const double visible[4], const char* what) {
  for (int q = 0; q < 4; ++q)
    for (int c = 0; c < 3; ++c) {
      const RegionStats s = quarter(img, q, c);
      const double want = visible[q] * kGlow[c];
      EXPECT_NEAR(s.mean, want, 4.5 * s.stderr_ + 0.01 * want + 1e-4) << what << ": quarter " << q << " channel " << c;
    }
}

}  // namespace

// MASK: texels below the cutoff are cut out (the emitter shows through), the others are opaque;
// the cutoff moves the edge between them.
TEST(GltfAlpha, MaskCutsOutBelowTheCutoff) {
  for (double cutoff : {0.5, 0.3}) {
    const ImageRGB img = render(cutout_scene(json{{"alphaMode", "MASK"}, {"alphaCutoff", cutoff}}).text(), 16, 2);
    double visible[4];
    for (int q = 0; q < 4; ++q) visible[q] = kAlpha[q] / 255.0 >= cutoff ? 0 : 1;
    expect_quarters(img, visible, cutoff == 0.5 ? "cutoff 0.5" : "cutoff 0.3");
  }
}

// BLEND: a ray passes a surface of alpha a with probability 1 - a, so the emitter shows at
// (1 - a) of its radiance; the factor's alpha multiplies the texture's. OPAQUE ignores alpha.
TEST(GltfAlpha, BlendPassesOneMinusAlpha) {
  {
    const ImageRGB img = render(cutout_scene(json{{"alphaMode", "BLEND"}}).text(), 64, 2);
    double visible[4];
    for (int q = 0; q < 4; ++q) visible[q] = 1 - kAlpha[q] / 255.0;
    expect_quarters(img, visible, "BLEND");
  }
  {
    GltfDoc g = cutout_scene(json{{"alphaMode", "BLEND"}});
    g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {0, 0, 0, 0.5};
    const ImageRGB img = render(g.text(), 64, 2);
    double visible[4];
    for (int q = 0; q < 4; ++q) visible[q] = 1 - 0.5 * kAlpha[q] / 255.0;
    expect_quarters(img, visible, "BLEND x factor 0.5");
  }
  {
    const ImageRGB img = render(cutout_scene(json::object()).text(), 16, 2);
    const double visible[4] = {0, 0, 0, 0};
    expect_quarters(img, visible, "OPAQUE");
  }
}

// COLOR_0's alpha multiplies the base colour's (glTF 2.0, 3.9.2).
TEST(GltfAlpha, VertexColourAlphaBlends) {
  GltfDoc g = cutout_scene(json{{"alphaMode", "BLEND"}});
  g.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] =
      g.floats({1, 1, 1, 0.25f, 1, 1, 1, 0.25f, 1, 1, 1, 0.25f, 1, 1, 1, 0.25f}, "VEC4", 4);
  const ImageRGB img = render(g.text(), 64, 2);
  double visible[4];
  for (int q = 0; q < 4; ++q) visible[q] = 1 - 0.25 * kAlpha[q] / 255.0;
  expect_quarters(img, visible, "COLOR_0 alpha 0.25");
}

// Shadow rays see alpha too. A white floor at z = 0 under a sun straight down (1 W/m^2) and, half
// a unit above it, a black occluder: cut out (MASK) the camera sees the lit floor, 1/pi; blended
// at alpha 1/2 the camera sees the floor half the time and the sun reaches it half the time,
// 1/(4 pi). An occluder opaque to shadow rays would leave the floor black in both.
TEST(GltfAlpha, ShadowRaysPassWhereAlphaLetsThem) {
  for (const char* mode : {"MASK", "BLEND"}) {
    GltfDoc g = test::quad_doc();
    g.doc["nodes"][0]["scale"] = {3, 3, 1};
    g.doc["materials"][0]["extensions"]["KHR_materials_specular"] = {{"specularFactor", 0}};
    const json& prim = g.doc["meshes"][0]["primitives"][0];
    const bool mask = std::string(mode) == "MASK";
    const int occluder = g.material(json{{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, mask ? 0.2 : 0.5}}}},
                                         {"alphaMode", mode},
                                         {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0}}}}}});
    g.mesh(json{{"POSITION", prim["attributes"]["POSITION"]}}, prim["indices"], occluder,
           json{{"translation", {0, 0, 0.5}}, {"scale", {3, 3, 1}}});
    g.doc["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.01}}}}});
    g.root(json{{"camera", 0}, {"translation", {0, 0, 3}}});
    g.light(json{{"type", "directional"}, {"intensity", 683}}, json::object());  // travels along -z
    const ImageRGB img = render(g.text(), 64, 2);
    const double want = mask ? 1 / M_PI : 0.25 / M_PI;
    for (int q = 0; q < 4; ++q) {
      const RegionStats s = quarter(img, q, 1);
      EXPECT_NEAR(s.mean, want, 4.5 * s.stderr_ + 0.01 * want) << mode << ", quarter " << q;
    }
  }
}

// Out-of-range and unknown values: warned, naming the JSON path; a negative cutoff is an error.
TEST(GltfAlpha, BadValuesAreNamed) {
  for (const auto& [alpha, what] : {std::pair<json, const char*>{{{"alphaMode", "MASK"}, {"alphaCutoff", 1.5}}, "/materials/0/alphaCutoff"},
                                    {{{"alphaMode", "CUTOUT"}}, "/materials/0/alphaMode"}}) {
    const SceneDesc d = parse_gltf(cutout_scene(alpha).text(), "t.gltf", false);
    bool named = false;
    for (const std::string& w : d.warnings) named |= w.find(what) != std::string::npos;
    EXPECT_TRUE(named) << what;
  }
  EXPECT_TRUE(test::fails_at(cutout_scene(json{{"alphaMode", "MASK"}, {"alphaCutoff", -0.5}}).text(), "/materials/0/alphaCutoff"));
}

// A texel's colour is the file's, not premultiplied by its alpha (glTF 2.0, 3.9.2): an unlit card
// shows the texture's white where MASK keeps a texel of alpha 100/255, not 100/255 of it.
TEST(GltfAlpha, TexelColoursAreNotPremultiplied) {
  GltfDoc g = cutout_scene(json{{"alphaMode", "MASK"}, {"alphaCutoff", 0.3}});
  g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {1, 1, 1, 1};
  g.doc["materials"][0]["extensions"] = {{"KHR_materials_unlit", json::object()}};
  const ImageRGB img = render(g.text(), 4, 2);
  for (int q = 1; q < 4; ++q)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(quarter(img, q, c).mean, 1.0, 1e-3) << "quarter " << q << " channel " << c;
}
