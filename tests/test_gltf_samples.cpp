// Khronos' simple glTF sample models, rebuilt here from their published structure (the sample
// repository cannot be fetched on the build hosts): each loads without error, renders without
// NaN, and shows what the sample is there to show (its texture, its vertex colours, the second uv
// set, the sparse substitution, the interleaved buffer, the cameras, the sampler's wrap modes).
// Features the renderer leaves out (animation, skins, morph targets, orthographic cameras) are one
// warning each, never an error.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "gltf_docs.h"
#include "image.h"
#include "session.h"
#include "test_util.h"

using namespace pt;
using test::GltfDoc;
using test::json;

namespace {

ImageRGB render(const SceneDesc& d) {
  RenderParams p;
  p.width = p.height = 48;
  p.spp = 4;
  p.max_depth = 2;
  p.adaptive = false;
  p.threads = 2;
  auto scene = make_render_scene(d, p);
  RenderSession s(*scene, p);
  s.render_all();
  EXPECT_EQ(s.stats().nonfinite, 0u);
  return s.image();
}

SceneDesc load(const GltfDoc& g) { return parse_gltf(g.text(), "sample.gltf", false); }

// Distinct hues in an image: each lit pixel's colour over its largest channel, quantised to 1/4
// (shading changes brightness, not hue: a flat grey or a single colour counts once).
size_t colours(const ImageRGB& img) {
  std::set<int> seen;
  for (const Vec3& c : img.pixels) {
    const float m = max_component(c);
    if (!(m > 0.02f)) continue;
    auto q = [&](float v) { return std::min(3, std::max(0, int(v / m * 4))); };
    seen.insert(q(c.x) * 16 + q(c.y) * 4 + q(c.z));
  }
  return seen.size();
}

double mean(const ImageRGB& img, int c) {
  double s = 0;
  for (const Vec3& p : img.pixels) s += p[c];
  return s / double(img.pixels.size());
}

bool warned(const SceneDesc& d, const std::string& what) {
  for (const std::string& w : d.warnings)
    if (w.find(what) != std::string::npos) return true;
  return false;
}

// The Box sample's cube: 24 vertices (4 a face, their own normals), 36 indices, uvs per face.
struct Cube {
  std::vector<float> pos, nrm, uv;
  std::vector<uint16_t> idx;
};
Cube cube() {
  Cube c;
  const int axes[6][3] = {{0, 1, 2}, {0, 1, 2}, {1, 2, 0}, {1, 2, 0}, {2, 0, 1}, {2, 0, 1}};
  for (int f = 0; f < 6; ++f) {
    const float s = f % 2 ? -0.5f : 0.5f;
    const int* a = axes[f];
    const float corners[4][2] = {{-0.5f, -0.5f}, {0.5f, -0.5f}, {0.5f, 0.5f}, {-0.5f, 0.5f}};
    const uint16_t base = uint16_t(c.pos.size() / 3);
    for (const auto& k : corners) {
      float p[3], n[3] = {0, 0, 0};
      p[a[2]] = s, p[a[0]] = k[0] * (s > 0 ? 1 : -1), p[a[1]] = k[1];
      n[a[2]] = s > 0 ? 1.0f : -1.0f;
      c.pos.insert(c.pos.end(), p, p + 3);
      c.nrm.insert(c.nrm.end(), n, n + 3);
      c.uv.insert(c.uv.end(), {k[0] + 0.5f, 0.5f - k[1]});
    }
    c.idx.insert(c.idx.end(), {base, uint16_t(base + 1), uint16_t(base + 2), base, uint16_t(base + 2), uint16_t(base + 3)});
  }
  return c;
}

// Box: the cube under a node hierarchy (the sample's Z-up to Y-up matrix on the root), red.
GltfDoc box(const json& material, bool with_uvs = false) {
  GltfDoc g;
  const Cube c = cube();
  json attrs{{"POSITION", g.floats(c.pos, "VEC3", 3)}, {"NORMAL", g.floats(c.nrm, "VEC3", 3)}};
  g.doc["accessors"][size_t(attrs["POSITION"].get<int>())]["min"] = {-0.5, -0.5, -0.5};
  g.doc["accessors"][size_t(attrs["POSITION"].get<int>())]["max"] = {0.5, 0.5, 0.5};
  if (with_uvs) attrs["TEXCOORD_0"] = g.floats(c.uv, "VEC2", 2);
  const int idx = g.indices(c.idx);
  const int mat = g.material(material);
  json prim{{"attributes", attrs}, {"indices", idx}, {"material", mat}};
  g.doc["meshes"].push_back(json{{"primitives", json::array({prim})}});
  g.doc["nodes"] = json::array({json{{"children", {1}}, {"matrix", {1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1}}},
                                json{{"mesh", 0}}});
  g.doc["scenes"][0]["nodes"] = {0};
  return g;
}

// A 2 x 2 texture of four distinct colours.
void add_texture(GltfDoc& g, int sampler_wrap = 10497, bool nearest = true) {
  const std::vector<uint8_t> texels = {230, 30, 30, 30, 230, 30, 30, 30, 230, 230, 230, 30};
  g.doc["images"] = json::array({json{{"uri", "data:image/png;base64," + test::base64(encode_png8(texels, 2, 2))}}});
  json sampler{{"wrapS", sampler_wrap}, {"wrapT", sampler_wrap}};
  if (nearest) sampler["magFilter"] = 9728;
  g.doc["samplers"] = json::array({sampler});
  g.doc["textures"] = json::array({json{{"source", 0}, {"sampler", 0}}});
}

GltfDoc triangle(bool indexed) {
  GltfDoc g;
  const int pos = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
  g.doc["accessors"][size_t(pos)]["min"] = {0, 0, 0};
  g.doc["accessors"][size_t(pos)]["max"] = {1, 1, 0};
  g.mesh(json{{"POSITION", pos}}, indexed ? g.indices({0, 1, 2}) : -1, -1);
  return g;
}

}  // namespace

// Triangle, TriangleWithoutIndices, SimpleMeshes (one mesh, two nodes): glTF's default material
// under the default light, seen from the three-quarter view.
TEST(GltfSamples, TrianglesAndSharedMeshes) {
  for (bool indexed : {true, false}) {
    const SceneDesc d = load(triangle(indexed));
    EXPECT_EQ(d.triangle_count(), 1u);
    EXPECT_GT(mean(render(d), 1), 0.005) << (indexed ? "Triangle" : "TriangleWithoutIndices");
  }
  GltfDoc g = triangle(true);
  g.root(json{{"mesh", 0}, {"translation", {1, 0, 0}}});  // SimpleMeshes: the same mesh again
  const SceneDesc d = load(g);
  EXPECT_EQ(d.triangle_count(), 2u);
  EXPECT_GT(mean(render(d), 1), 0.005);
}

// Box, BoxInterleaved (positions and normals in one strided view): the same red cube.
TEST(GltfSamples, BoxAndBoxInterleaved) {
  const json red = {{"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0, 0, 1}}, {"metallicFactor", 0}}}};
  const ImageRGB a = render(load(box(red)));
  EXPECT_GT(mean(a, 0), 3 * mean(a, 1)) << "the box is red";
  GltfDoc g = box(red);
  const Cube c = cube();
  std::vector<float> inter;
  for (size_t v = 0; v < c.pos.size() / 3; ++v) {
    inter.insert(inter.end(), c.pos.begin() + long(3 * v), c.pos.begin() + long(3 * v + 3));
    inter.insert(inter.end(), c.nrm.begin() + long(3 * v), c.nrm.begin() + long(3 * v + 3));
  }
  const int view = g.view(test::bytes_of(inter), 24);
  const int pos = g.accessor(view, 5126, inter.size() / 6, "VEC3");
  g.doc["accessors"][size_t(pos)]["min"] = {-0.5, -0.5, -0.5};
  g.doc["accessors"][size_t(pos)]["max"] = {0.5, 0.5, 0.5};
  const int nrm = g.accessor(view, 5126, inter.size() / 6, "VEC3");
  g.doc["accessors"][size_t(nrm)]["byteOffset"] = 12;
  g.doc["meshes"][0]["primitives"][0]["attributes"] = {{"POSITION", pos}, {"NORMAL", nrm}};
  const ImageRGB b = render(load(g));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(mean(b, k), mean(a, k), 1e-6) << "interleaved, channel " << k;
}

// BoxTextured (on glTF's default metallic 1 too, where the old mapping averaged the texture),
// BoxVertexColors: the colours show, not one flat grey.
TEST(GltfSamples, BoxTexturedAndBoxVertexColors) {
  for (double metallic : {0.0, 1.0}) {
    GltfDoc g = box({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", metallic}}}}, true);
    add_texture(g);
    EXPECT_GE(colours(render(load(g))), 3u) << "BoxTextured, metallic " << metallic;
  }
  GltfDoc g = box({{"pbrMetallicRoughness", {{"metallicFactor", 0}}}});
  std::vector<float> rgba;
  for (size_t v = 0; v < cube().pos.size() / 3; ++v) rgba.insert(rgba.end(), {float(v % 3 == 0), float(v % 3 == 1), float(v % 3 == 2), 1});
  g.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = g.floats(rgba, "VEC4", 4);
  EXPECT_GE(colours(render(load(g))), 3u) << "BoxVertexColors";
}

// SimpleSparseAccessor: a sparse accessor over a base buffer moves some vertices.
TEST(GltfSamples, SimpleSparseAccessor) {
  GltfDoc g = triangle(true);
  json& pos = g.doc["accessors"][0];
  pos["sparse"] = {{"count", 1},
                   {"indices", {{"bufferView", g.view(test::bytes_of(std::vector<uint16_t>{2, 0}))}, {"componentType", 5123}}},
                   {"values", {{"bufferView", g.view(test::bytes_of(std::vector<float>{0, 3, 0}))}}}};
  pos["max"] = {1, 3, 0};
  const SceneDesc d = load(g);
  ASSERT_EQ(d.meshes.size(), 1u);
  EXPECT_NEAR(d.geometry_bounds().hi.y - d.geometry_bounds().lo.y, 3.0f, 1e-5f) << "the sparse value replaced vertex 2";
}

// TextureCoordinateTest and MultiUVTest: uv (0, 0) is the image's top-left; a texture may name
// TEXCOORD_1. TextureSettingsTest: REPEAT, MIRRORED_REPEAT and CLAMP_TO_EDGE over uvs 0..3 differ.
TEST(GltfSamples, TextureCoordinatesSetsAndWrapModes) {
  auto quad = [](int wrap, int set) {
    GltfDoc g = test::quad_doc();
    json& prim = g.doc["meshes"][0]["primitives"][0];
    const int uv = g.floats({0, 3, 3, 3, 3, 0, 0, 0}, "VEC2", 2);
    prim["attributes"]["TEXCOORD_0"] = set == 0 ? uv : g.floats({0, 0, 0, 0, 0, 0, 0, 0}, "VEC2", 2);
    if (set == 1) prim["attributes"]["TEXCOORD_1"] = uv;
    g.doc["materials"][0] = {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}, {"texCoord", set}}}, {"metallicFactor", 0}}}};
    add_texture(g, wrap);
    g.doc["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.01}}}}});
    g.root(json{{"camera", 0}, {"translation", {0, 0, 3}}});
    return render(load(g));
  };
  const ImageRGB repeat = quad(10497, 0), mirror = quad(33648, 0), clamp = quad(33071, 0), second = quad(10497, 1);
  EXPECT_GE(colours(repeat), 4u);
  double d_mirror = 0, d_clamp = 0, d_second = 0;
  for (size_t i = 0; i < repeat.pixels.size(); ++i) {
    d_mirror += length(repeat.pixels[i] - mirror.pixels[i]);
    d_clamp += length(repeat.pixels[i] - clamp.pixels[i]);
    d_second += length(repeat.pixels[i] - second.pixels[i]);
  }
  EXPECT_GT(d_mirror, 10) << "MIRRORED_REPEAT renders as REPEAT";
  EXPECT_GT(d_clamp, 10) << "CLAMP_TO_EDGE renders as REPEAT";
  EXPECT_LT(d_second / double(repeat.pixels.size()), 0.02) << "TEXCOORD_1 is not read as TEXCOORD_0 would be";
}

// Cameras (a perspective and an orthographic camera), AnimatedTriangle, SimpleSkin, SimpleMorph:
// they load, render, and say once what is left out.
TEST(GltfSamples, CamerasAnimationSkinsAndMorphsLoadWithAWarning) {
  GltfDoc g = triangle(true);
  g.doc["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"aspectRatio", 1.0}, {"znear", 0.01}}}},
                                  json{{"type", "orthographic"}, {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.01}, {"zfar", 100}}}}});
  g.root(json{{"camera", 0}, {"translation", {0.5, 0.5, 3}}});
  g.root(json{{"camera", 1}, {"translation", {0.5, 0.5, 3}}});
  g.doc["animations"] = json::array({json{{"channels", json::array({json{{"sampler", 0}, {"target", {{"node", 0}, {"path", "rotation"}}}}})},
                                          {"samplers", json::array({json{{"input", g.floats({0, 1}, "SCALAR", 1)},
                                                                         {"output", g.floats({0, 0, 0, 1, 0, 0, 0, 1}, "VEC4", 4)}}})}}});
  g.doc["meshes"][0]["primitives"][0]["targets"] = json::array({json{{"POSITION", g.floats({0, 0, 0, 0, 0, 0, 0, 0.5f, 0}, "VEC3", 3)}}});
  const SceneDesc d = load(g);
  EXPECT_TRUE(d.camera.present);
  EXPECT_TRUE(warned(d, "animations"));
  EXPECT_TRUE(warned(d, "morph targets"));
  EXPECT_GT(mean(render(d), 1), 0.005);
}
