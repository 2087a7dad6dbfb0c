// glTF textures read per hit on every material kind, normal maps, TEXCOORD_1 and
// KHR_texture_transform, as images: a textured quad renders, quarter by quarter, what a constant
// material of each texel's value renders (the difference within its noise), and a normal map
// tilts the shading normal as glTF's tangent frame says (the Lambertian cosine under a sun).
#include <gtest/gtest.h>

#include <cmath>

#include "gltf_docs.h"
#include "image.h"
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

ImageRGB render(const std::string& text, int spp, int depth, uint64_t seed = 0) {
  return test::render_gltf(text, spp, depth, seed);
}

// The quad (test::quad_doc) with uvs running as an image's (u along +x, v down +y: (0, 0) at the
// top-left corner) and a camera 3 units in front of it, which it fills.
GltfDoc textured_quad() {
  GltfDoc g = test::quad_doc();
  g.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = g.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2);
  g.doc["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.01}}}}});
  g.root(json{{"camera", 0}, {"translation", {0, 0, 3}}});
  return g;
}

// A 2 x 2 texture (texels top-left, top-right, bottom-left, bottom-right), nearest filtering.
void add_texture(GltfDoc& g, const std::vector<uint8_t>& texels, int wrap = 33071) {
  g.doc["images"] = json::array({json{{"uri", "data:image/png;base64," + test::base64(encode_png8(texels, 2, 2))}}});
  g.doc["samplers"] = json::array({json{{"magFilter", 9728}, {"wrapS", wrap}, {"wrapT", wrap}}});
  g.doc["textures"] = json::array({json{{"source", 0}, {"sampler", 0}}});
}

// The mean of each quarter's inner square (10 pixels off the centre, which the quad covers).
constexpr int kHalf = 24, kR = 4;
RegionStats quarter(const ImageRGB& img, int q, int c) {
  const int cx = kHalf + (q % 2 ? 10 : -10) - kR, cy = kHalf + (q / 2 ? 10 : -10) - kR;
  return region_stats(img, cx, cy, cx + 2 * kR, cy + 2 * kR, c);
}

// Each quarter of `textured` against a render of `constant(q)`: equal within 4.5 standard errors.
template <class Constant>
void expect_quarters_match(const ImageRGB& textured, Constant&& constant, int spp, int depth, const char* what) {
  for (int q = 0; q < 4; ++q) {
    const ImageRGB ref = render(constant(q), spp, depth, 7);
    for (int c = 0; c < 3; ++c) {
      const RegionStats a = quarter(textured, q, c), b = quarter(ref, q, c);
      EXPECT_NEAR(a.mean, b.mean, 4.5 * std::hypot(a.stderr_, b.stderr_) + 1e-4) << what << ": quarter " << q << " channel " << c;
    }
  }
}

}  // namespace

// Base colour on a rough metal, metal / roughness (linear: G roughness, B metalness) on a
// coloured material, emission: each read per hit, each quarter its texel's constant material.
TEST(GltfTextures, EveryTextureIsReadPerHit) {
  const std::vector<uint8_t> colours = {230, 40, 40, 40, 230, 40, 40, 40, 230, 200, 200, 200};
  {
    GltfDoc g = textured_quad();
    add_texture(g, colours);
    json& pbr = g.doc["materials"][0]["pbrMetallicRoughness"];
    pbr = {{"metallicFactor", 1}, {"roughnessFactor", 0.5}, {"baseColorTexture", {{"index", 0}}}};
    const ImageRGB img = render(g.text(), 64, 2);
    expect_quarters_match(img, [&](int q) {
      GltfDoc c = textured_quad();
      json base = json::array();
      for (int k = 0; k < 3; ++k) base.push_back(srgb8_to_linear(colours[size_t(3 * q + k)]));
      base.push_back(1);
      c.doc["materials"][0]["pbrMetallicRoughness"] = {{"metallicFactor", 1}, {"roughnessFactor", 0.5}, {"baseColorFactor", base}};
      return c.text();
    }, 64, 2, "base colour on a metal");
    // A metal's colour is its texture's, not the mean grey of the old mapping.
    EXPECT_GT(quarter(img, 0, 0).mean, 3 * quarter(img, 0, 1).mean);
  }
  {
    const std::vector<uint8_t> mr = {0, 255, 255, 0, 40, 0, 0, 128, 255, 0, 200, 128};
    GltfDoc g = textured_quad();
    add_texture(g, mr);
    g.doc["materials"][0]["pbrMetallicRoughness"] = {
        {"baseColorFactor", {0.9, 0.5, 0.2, 1}}, {"metallicRoughnessTexture", {{"index", 0}}}};
    const ImageRGB img = render(g.text(), 64, 2);
    expect_quarters_match(img, [&](int q) {
      GltfDoc c = textured_quad();
      c.doc["materials"][0]["pbrMetallicRoughness"] = {{"baseColorFactor", {0.9, 0.5, 0.2, 1}},
                                                       {"roughnessFactor", mr[size_t(3 * q + 1)] / 255.0},
                                                       {"metallicFactor", mr[size_t(3 * q + 2)] / 255.0}};
      return c.text();
    }, 64, 2, "metallic-roughness");
  }
  {
    GltfDoc g = textured_quad();
    add_texture(g, colours);
    g.doc["materials"][0] = {{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}},
                             {"emissiveFactor", {1, 1, 1}}, {"emissiveTexture", {{"index", 0}}}};
    const ImageRGB img = render(g.text(), 16, 1);
    for (int q = 0; q < 4; ++q)
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(quarter(img, q, c).mean, srgb8_to_linear(colours[size_t(3 * q + c)]), 0.02)
            << "emission, quarter " << q << " channel " << c;
  }
}

// The texture named through TEXCOORD_1 (TEXCOORD_0 would read one texel everywhere), then shifted
// half a texture to the right by KHR_texture_transform's offset with REPEAT wrapping.
TEST(GltfTextures, SecondUvSetAndTextureTransform) {
  const std::vector<uint8_t> colours = {230, 40, 40, 40, 230, 40, 40, 40, 230, 200, 200, 200};
  for (bool shifted : {false, true}) {
    GltfDoc g = textured_quad();
    add_texture(g, colours, 10497);
    json& prim = g.doc["meshes"][0]["primitives"][0];
    prim["attributes"]["TEXCOORD_1"] = prim["attributes"]["TEXCOORD_0"];
    prim["attributes"]["TEXCOORD_0"] = g.floats({0, 0, 0, 0, 0, 0, 0, 0}, "VEC2", 2);
    json info = {{"index", 0}, {"texCoord", 1}};
    if (shifted) info["extensions"]["KHR_texture_transform"] = {{"offset", {0.5, 0}}};
    g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = info;
    g.doc["materials"][0]["extensions"]["KHR_materials_specular"] = {{"specularFactor", 0}};
    const ImageRGB img = render(g.text(), 32, 1);
    for (int q = 0; q < 4; ++q) {
      const int texel = shifted ? (q ^ 1) : q;  // half a texture along u: left and right swap
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(quarter(img, q, c).mean, srgb8_to_linear(colours[size_t(3 * texel + c)]) * kDefaultLightOnTheQuad, 0.03)
            << (shifted ? "shifted" : "TEXCOORD_1") << ": quarter " << q << " channel " << c;
    }
  }
}

// Under a sun tilted 40 degrees from the quad's normal, a Lambertian quad shows cos / pi. A normal
// map tilting the normal 30 degrees towards the sun (red: +u, along +x; green: up the image, +y)
// makes that cos 10 degrees; its scale 0 leaves the normal as it was.
TEST(GltfTextures, NormalMapsTiltTheShadingNormalInTheTangentFrame) {
  const double tilt = 30 * M_PI / 180, sun = 40 * M_PI / 180;
  const uint8_t up = uint8_t(std::lround((std::sin(tilt) + 1) / 2 * 255)), flat = 128;
  const uint8_t z = uint8_t(std::lround((std::cos(tilt) + 1) / 2 * 255));
  struct Case {
    const char* name;
    bool along_x;  // tilt and sun towards +x, else towards +y
    double scale;
  };
  for (const Case& k : {Case{"red tilts towards +x", true, 1}, Case{"green tilts towards +y", false, 1},
                        Case{"scale 0", true, 0}}) {
    GltfDoc g = textured_quad();
    const std::vector<uint8_t> t = k.along_x ? std::vector<uint8_t>{up, flat, z} : std::vector<uint8_t>{flat, up, z};
    std::vector<uint8_t> texels;
    for (int i = 0; i < 4; ++i) texels.insert(texels.end(), t.begin(), t.end());
    add_texture(g, texels);
    g.doc["materials"][0]["normalTexture"] = {{"index", 0}, {"scale", k.scale}};
    g.doc["materials"][0]["extensions"]["KHR_materials_specular"] = {{"specularFactor", 0}};
    // The sun travels along the node's -Z: rotated towards -x (about y) or -y (about x).
    const double h = sun / 2;
    const json rot = k.along_x ? json{0, std::sin(h), 0, std::cos(h)} : json{-std::sin(h), 0, 0, std::cos(h)};
    g.light(json{{"type", "directional"}, {"intensity", 683}}, json{{"rotation", rot}});  // 1 W/m^2
    const ImageRGB img = render(g.text(), 16, 1);
    // The decoded map: n = normalize(x, y, z) in (tangent, bitangent, normal).
    auto decode = [](uint8_t c) { return c / 255.0 * 2 - 1; };
    double nx = decode(t[0]) * k.scale, ny = decode(t[1]) * k.scale, nz = decode(t[2]);
    const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
    const double along = (k.along_x ? nx : ny) / len;
    const double cos_theta = along * std::sin(sun) + nz / len * std::cos(sun);
    for (int q = 0; q < 4; ++q) {
      const RegionStats s = quarter(img, q, 1);
      EXPECT_NEAR(s.mean, cos_theta / M_PI, 0.01 * cos_theta / M_PI + 4.5 * s.stderr_) << k.name << ", quarter " << q;
    }
  }
}

// The extensions' textures are read per hit as the core ones are: the clear coat's strength (red),
// the sheen's colour and the specular colour, quarter by quarter against constant factors.
TEST(GltfTextures, ExtensionTexturesAreReadPerHit) {
  const std::vector<uint8_t> texels = {255, 0, 0, 128, 0, 0, 40, 0, 0, 0, 0, 0};  // red: 1, 0.5, 0.16, 0 (linear)
  const std::vector<uint8_t> colours = {230, 40, 40, 40, 230, 40, 40, 40, 230, 200, 200, 200};
  struct Case {
    const char* name;
    const char* extension;
    json textured, constant;  // the extension's object; `constant` takes the texel's value for "@"
    bool colour;
  };
  const Case cases[] = {
      {"clearcoat", "KHR_materials_clearcoat", {{"clearcoatFactor", 1}, {"clearcoatTexture", {{"index", 0}}}},
       {{"clearcoatFactor", "@"}}, false},
      {"sheen colour", "KHR_materials_sheen", {{"sheenColorFactor", {1, 1, 1}}, {"sheenRoughnessFactor", 0.4}, {"sheenColorTexture", {{"index", 0}}}},
       {{"sheenColorFactor", "@"}, {"sheenRoughnessFactor", 0.4}}, true},
      {"specular colour", "KHR_materials_specular", {{"specularColorFactor", {1, 1, 1}}, {"specularColorTexture", {{"index", 0}}}},
       {{"specularColorFactor", "@"}}, true},
  };
  for (const Case& k : cases) {
    const std::vector<uint8_t>& t = k.colour ? colours : texels;
    auto doc = [&](const json& ext) {
      GltfDoc g = textured_quad();
      g.doc["materials"][0]["pbrMetallicRoughness"] = {{"baseColorFactor", {0.02, 0.02, 0.02, 1}}, {"metallicFactor", 0},
                                                       {"roughnessFactor", 0.5}};
      g.doc["materials"][0]["extensions"][k.extension] = ext;
      return g;
    };
    GltfDoc g = doc(k.textured);
    add_texture(g, t);
    const ImageRGB img = render(g.text(), 64, 2);
    expect_quarters_match(img, [&](int q) {
      json ext = k.constant;
      for (auto& [key, value] : ext.items())
        if (value == "@") {
          if (k.colour) value = {srgb8_to_linear(t[size_t(3 * q)]), srgb8_to_linear(t[size_t(3 * q + 1)]), srgb8_to_linear(t[size_t(3 * q + 2)])};
          else value = t[size_t(3 * q)] / 255.0;
        }
      return doc(ext).text();
    }, 64, 2, k.name);
  }
}

// The clear coat has its own normal (KHR_materials_clearcoat): its clearcoatNormalTexture's, else
// the unbent normal, whatever normalTexture does to the base. On a black base under a sun 40
// degrees off the quad's normal, a rough coat seen head on shines only where its normal tilts 20
// degrees towards the sun (the half vector): with its own map tilting it, with both maps alike,
// not with the base's map alone.
TEST(GltfTextures, TheClearCoatHasItsOwnNormal) {
  const double tilt = 20 * M_PI / 180, sun = 40 * M_PI / 180;
  const uint8_t up = uint8_t(std::lround((std::sin(tilt) + 1) / 2 * 255)), flat = 128;
  const uint8_t z = uint8_t(std::lround((std::cos(tilt) + 1) / 2 * 255));
  auto coat = [&](bool base_map, bool coat_map) {
    GltfDoc g = textured_quad();
    std::vector<uint8_t> texels;
    for (int i = 0; i < 4; ++i) texels.insert(texels.end(), {up, flat, z});
    add_texture(g, texels);
    json& m = g.doc["materials"][0];
    m["pbrMetallicRoughness"] = {{"baseColorFactor", {0, 0, 0, 1}}, {"metallicFactor", 0}};
    m["extensions"]["KHR_materials_specular"] = {{"specularFactor", 0}};
    m["extensions"]["KHR_materials_clearcoat"] = {{"clearcoatFactor", 1}, {"clearcoatRoughnessFactor", 0.5}};
    if (base_map) m["normalTexture"] = {{"index", 0}};
    if (coat_map) m["extensions"]["KHR_materials_clearcoat"]["clearcoatNormalTexture"] = {{"index", 0}};
    const double h = sun / 2;  // the sun travels along the node's -Z, turned towards -x
    g.light(json{{"type", "directional"}, {"intensity", 683}}, json{{"rotation", {0, std::sin(h), 0, std::cos(h)}}});
    return render(g.text(), 64, 1);
  };
  const ImageRGB none = coat(false, false), base = coat(true, false), own = coat(false, true), both = coat(true, true);
  for (int q = 0; q < 4; ++q) {
    const RegionStats n = quarter(none, q, 1), b = quarter(base, q, 1), o = quarter(own, q, 1), t = quarter(both, q, 1);
    EXPECT_GT(o.mean, 3 * n.mean + 0.01) << "the coat's own map tilts it towards the highlight, quarter " << q;
    EXPECT_NEAR(b.mean, n.mean, 4.5 * std::hypot(b.stderr_, n.stderr_) + 1e-4) << "the base's map moved the coat, quarter " << q;
    EXPECT_NEAR(t.mean, o.mean, 4.5 * std::hypot(t.stderr_, o.stderr_) + 1e-4) << "quarter " << q;
  }
}
