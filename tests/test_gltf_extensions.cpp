// KHR_materials_unlit and KHR_materials_volume in renders: an unlit surface shows its base colour
// to the camera whatever the light, lights nothing and, as Blender renders it, casts no shadow; light crossing a volume's mesh is attenuated
// by Beer-Lambert's law, attenuationColor after attenuationDistance.
#include <gtest/gtest.h>

#include <cmath>

#include "gltf_docs.h"
#include "image.h"
#include "session.h"
#include "test_util.h"

using namespace pt;
using test::GltfDoc;
using test::json;
using test::region_stats;
using test::RegionStats;

namespace {

ImageRGB render(const std::string& text, int spp, int depth) { return test::render_gltf(text, spp, depth); }

RegionStats centre(const ImageRGB& img, int c) { return region_stats(img, 16, 16, 32, 32, c); }

void add_camera(GltfDoc& g, double z) {
  g.doc["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.01}}}}});
  g.root(json{{"camera", 0}, {"translation", {0, 0, z}}});
}

// A closed box from -1 to 1 in x and y, -0.5 to 0.5 in z (thickness 1), faces wound outwards.
void add_box(GltfDoc& g, int material) {
  const std::vector<float> p = {-1, -1, -0.5f, 1, -1, -0.5f, 1, 1, -0.5f, -1, 1, -0.5f,
                                -1, -1, 0.5f,  1, -1, 0.5f,  1, 1, 0.5f,  -1, 1, 0.5f};
  const int pos = g.floats(p, "VEC3", 3);
  g.doc["accessors"][size_t(pos)]["min"] = {-1, -1, -0.5};
  g.doc["accessors"][size_t(pos)]["max"] = {1, 1, 0.5};
  const int idx = g.indices({0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                             1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7});
  g.mesh(json{{"POSITION", pos}}, idx, material, json{{"scale", {3, 3, 1}}});
}

}  // namespace

// The camera sees an unlit quad's base colour exactly, under a sun or in the dark; a white floor
// facing it (the quad its only emitter) stays black: unlit emits to camera rays only.
TEST(GltfExtensions, UnlitShowsItsBaseColourAndLightsNothing) {
  const Vec3 colour(0.2f, 0.5f, 0.8f);
  for (bool sun : {false, true}) {
    GltfDoc g = test::quad_doc();
    g.doc["materials"][0] = {{"pbrMetallicRoughness", {{"baseColorFactor", {colour.x, colour.y, colour.z, 1}}}},
                             {"extensions", {{"KHR_materials_unlit", json::object()}}}};
    g.doc["nodes"][0]["scale"] = {3, 3, 1};
    add_camera(g, 3);
    if (sun) g.light(json{{"type", "directional"}, {"intensity", 6830}}, json::object());
    const ImageRGB img = render(g.text(), 16, 3);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(centre(img, c).mean, colour[c], 1e-3) << (sun ? "sun" : "dark") << " channel " << c;
  }
  // Seen from a white floor: a mirror-free diffuse floor at right angles to the unlit quad.
  GltfDoc g = test::quad_doc();
  g.doc["materials"][0]["extensions"]["KHR_materials_specular"] = {{"specularFactor", 0}};
  g.doc["nodes"][0]["scale"] = {3, 3, 1};
  const int unlit = g.material(json{{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}}},
                                    {"extensions", {{"KHR_materials_unlit", json::object()}}}, {"doubleSided", true}});
  const json& prim = g.doc["meshes"][0]["primitives"][0];
  g.mesh(json{{"POSITION", prim["attributes"]["POSITION"]}}, prim["indices"], unlit,
         json{{"translation", {0, 3, 1}}, {"rotation", {std::sqrt(0.5), 0, 0, std::sqrt(0.5)}}, {"scale", {3, 3, 1}}});
  add_camera(g, 3);
  const ImageRGB img = render(g.text(), 16, 3);
  EXPECT_LT(centre(img, 1).mean, 1e-6) << "an unlit surface lit the floor";
}

// Blender's importer makes an unlit material transparent to every ray but camera rays: a card
// between the sun and the floor casts no shadow there. The same card opaque does (the test sees a
// shadow when there is one).
TEST(GltfExtensions, UnlitCastsNoShadow) {
  auto floor_centre = [](const char* card) {
    GltfDoc g = test::quad_doc();
    g.doc["materials"][0]["extensions"]["KHR_materials_specular"] = {{"specularFactor", 0}};
    g.doc["nodes"][0]["scale"] = {3, 3, 1};
    add_camera(g, 3);
    // The sun along (-1, 0, -1) / sqrt 2: a card at (2, 0, 2) facing it, outside the camera's view,
    // shadows the floor's centre.
    const double q = std::sin(M_PI / 8), w = std::cos(M_PI / 8);
    g.light(json{{"type", "directional"}, {"intensity", 6830}}, json{{"rotation", {0, q, 0, w}}});
    if (card) {
      json m = {{"pbrMetallicRoughness", {{"baseColorFactor", {1, 0.5, 0.2, 1}}}}, {"doubleSided", true}};
      if (std::string(card) == "unlit") m["extensions"] = {{"KHR_materials_unlit", json::object()}};
      const json& prim = g.doc["meshes"][0]["primitives"][0];
      g.mesh(json{{"POSITION", prim["attributes"]["POSITION"]}}, prim["indices"], g.material(m),
             json{{"translation", {2, 0, 2}}, {"rotation", {0, q, 0, w}}, {"scale", {0.8, 0.8, 1}}});
    }
    return centre(render(g.text(), 64, 2), 1).mean;
  };
  const double open = floor_centre(nullptr), unlit = floor_centre("unlit"), opaque = floor_centre("opaque");
  ASSERT_GT(open, 0.05);
  EXPECT_LT(opaque, 0.5 * open) << "the opaque card casts no shadow: the test's geometry is off";
  EXPECT_NEAR(unlit / open, 1.0, 0.02) << "an unlit card shadows the floor";
}

// A glass box (transmission 1, ior 1.01: almost no reflection, no bending) 1 unit thick before an
// emitter, seen head on: with KHR_materials_volume's attenuationColor c at attenuationDistance 1,
// each channel is c times what it is without the volume; thickness 0 (a thin wall) absorbs nothing.
TEST(GltfExtensions, VolumesAttenuateByBeerLambert) {
  const double c[3] = {0.5, 0.8, 1.0};
  auto scene = [&](const json* volume) {
    GltfDoc g;
    json glass = {{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 0}}},
                  {"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1}}}, {"KHR_materials_ior", {{"ior", 1.01}}}}}};
    if (volume) glass["extensions"]["KHR_materials_volume"] = *volume;
    add_box(g, g.material(glass));
    const int pos = g.floats({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, "VEC3", 3);  // the emitter behind
    g.doc["accessors"][size_t(pos)]["min"] = {-1, -1, 0};
    g.doc["accessors"][size_t(pos)]["max"] = {1, 1, 0};
    const int glow = g.material(json{{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}}, {"emissiveFactor", {1, 1, 1}}});
    g.mesh(json{{"POSITION", pos}}, g.indices({0, 1, 2, 0, 2, 3}), glow, json{{"translation", {0, 0, -2}}, {"scale", {5, 5, 1}}});
    add_camera(g, 4);
    return render(g.text(), 32, 6);
  };
  const ImageRGB clear = scene(nullptr);
  const json volume = {{"thicknessFactor", 1}, {"attenuationDistance", 1}, {"attenuationColor", {c[0], c[1], c[2]}}};
  const ImageRGB tinted = scene(&volume);
  const json thin = {{"thicknessFactor", 0}, {"attenuationDistance", 1}, {"attenuationColor", {c[0], c[1], c[2]}}};
  const ImageRGB thin_wall = scene(&thin);
  for (int k = 0; k < 3; ++k) {
    const RegionStats a = centre(clear, k), b = centre(tinted, k), t = centre(thin_wall, k);
    EXPECT_GT(a.mean, 0.9) << "the emitter shows through the glass";
    EXPECT_NEAR(b.mean / a.mean, c[k], 0.01) << "channel " << k;
    EXPECT_NEAR(t.mean / a.mean, 1.0, 0.01) << "thin wall, channel " << k;
  }
}
