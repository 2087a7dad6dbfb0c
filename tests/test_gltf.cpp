// The glTF reader on our scenes and on small documents: counts, the material mapping
// (docs/gltf.md), lights in photometric units against a hand computation, cameras, textures, the
// default light, quantized attributes, transforms; the format dispatch and --describe.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "gltf_docs.h"
#include "materials.h"
#include "render_scene.h"
#include "scene_file.h"
#include "test_util.h"
#include "texture.h"

using namespace pt;
using test::GltfDoc;
using test::json;

namespace {

SceneDesc parse(const GltfDoc& g) { return parse_gltf(g.text(), "t.gltf", false); }

const Material* find_material(const SceneDesc& d, const std::string& name) {
  for (const Material& m : d.materials)
    if (m.name == name) return &m;
  return nullptr;
}

}  // namespace

TEST(Gltf, OurCornellHasTheColladaScenesContents) {
  SceneDesc d = load_scene(test::own_scene("cornell_gltf.glb"));
  SceneDesc c = load_scene(test::own_scene("cornell.dae"));
  // The walls and blocks triangle for triangle, two 64 x 32 UV spheres, the light's quad.
  EXPECT_EQ(d.meshes.size(), c.meshes.size() + 2 + 1);
  EXPECT_EQ(d.triangle_count(), c.triangle_count() + 2 * (64 * 32 * 2 - 2 * 64) + 2);
  EXPECT_TRUE(d.spheres.empty());
  EXPECT_TRUE(d.lights.empty());  // the area light is an emissive mesh
  ASSERT_NE(find_material(d, "ceiling_light"), nullptr);
  EXPECT_EQ(find_material(d, "ceiling_light")->type, MaterialType::pbr);
  EXPECT_NEAR(find_material(d, "ceiling_light")->pbr.emissive.y, 11.0f, 1e-4f);
  ASSERT_NE(find_material(d, "glass"), nullptr);
  EXPECT_EQ(find_material(d, "glass")->type, MaterialType::glass);
  EXPECT_FLOAT_EQ(find_material(d, "glass")->ior, 1.5f);
  EXPECT_EQ(find_material(d, "mirror")->type, MaterialType::mirror);  // smooth metal: exact, with Schlick's Fresnel
  EXPECT_NEAR(find_material(d, "mirror")->albedo.x, 0.95f, 1e-6f);
  EXPECT_TRUE(find_material(d, "mirror")->schlick);
  EXPECT_NEAR(find_material(d, "red")->pbr.base.x, 0.63f, 1e-6f);
  EXPECT_TRUE(d.camera.present && d.camera.as_authored);
  EXPECT_NEAR(d.camera.world.point(Vec3(0, 0, 0)).z, 4.8f, 1e-5f);
  Bounds3 a = d.geometry_bounds(), b = c.geometry_bounds();
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a.lo[k], b.lo[k], 1e-3f) << k;
  EXPECT_TRUE(d.default_light);
}

TEST(Gltf, OurShowcaseMapsEachMaterialLightAndTheCamera) {
  SceneDesc d = load_scene(test::own_scene("showcase.gltf"));
  ASSERT_EQ(d.textures.size(), 1u);
  EXPECT_EQ(d.textures[0].width, 64);
  EXPECT_EQ(d.textures[0].wrap_s, TextureWrap::repeat);
  EXPECT_EQ(d.textures[0].wrap_t, TextureWrap::mirror);
  const Material* floor = find_material(d, "checker floor");
  ASSERT_NE(floor, nullptr);
  EXPECT_EQ(floor->type, MaterialType::pbr);
  EXPECT_EQ(floor->pbr.base_tex.texture, 0);
  EXPECT_TRUE(d.textures[0].srgb);
  EXPECT_TRUE(find_material(d, "vertex-coloured wall")->pbr.vertex_color);
  const Material* gold = find_material(d, "rough gold");
  EXPECT_EQ(gold->type, MaterialType::pbr);
  EXPECT_NEAR(gold->pbr.roughness, 0.35f, 1e-6f);
  EXPECT_NEAR(gold->pbr.base.y, 0.766f, 1e-4f);
  EXPECT_EQ(find_material(d, "glass")->type, MaterialType::glass);
  EXPECT_NEAR(find_material(d, "glass")->transmittance.x, 0.95f, 1e-6f);
  EXPECT_NEAR(find_material(d, "emissive panel")->pbr.emissive.y, 5.4f, 1e-5f);
  for (const MeshDesc& m : d.meshes)  // the panel's front (emitting) face looks down on the scene
    if (m.name == "panel") {
      const uint32_t* i = m.indices.data();
      EXPECT_LT(cross(m.positions[i[1]] - m.positions[i[0]], m.positions[i[2]] - m.positions[i[0]]).y, 0.0f);
    }
  ASSERT_EQ(d.lights.size(), 1u);
  const LightDesc& spot = d.lights[0];
  EXPECT_EQ(spot.type, LightType::spot);
  EXPECT_NEAR(spot.spot_angle_deg, 2 * 0.5 * 180 / M_PI, 1e-3);
  EXPECT_NEAR(spot.spot_inner_deg, 2 * 0.35 * 180 / M_PI, 1e-3);
  EXPECT_NEAR(spot.color.x, 15000.0 / 683.0, 1e-3);
  EXPECT_NEAR(dot(spot.direction, normalize(Vec3(-2.5f, -3.5f, -2.5f))), 1.0f, 1e-5f);
  EXPECT_TRUE(d.camera.present);
  EXPECT_NEAR(d.camera.yfov_deg, 0.75 * 180 / M_PI, 1e-4);
}

// KHR_lights_punctual: candela / 683 lm/W is W/sr; at distance d a point light gives I / d^2
// (W/m^2). Hand computation: 100 cd of colour (1, 0.5, 0.25) at 2 m: 100 / 683 / 4 =
// 0.0366032 W/m^2 in red. 10 lux of directional light: 10 / 683 = 0.0146413 W/m^2.
TEST(Gltf, PunctualLightsConvertFromPhotometricUnitsByHand) {
  EXPECT_NEAR(radiometric_from_photometric(Vec3(1.0f), 683.0).x, 1.0f, 1e-7f);
  GltfDoc g = test::quad_doc();
  g.light(json{{"type", "point"}, {"color", {1, 0.5, 0.25}}, {"intensity", 100}}, json{{"translation", {0, 0, 2}}});
  g.light(json{{"type", "directional"}, {"intensity", 10}}, json{{"rotation", {-0.7071068, 0, 0, 0.7071068}}});
  SceneDesc d = parse(g);
  ASSERT_EQ(d.lights.size(), 2u);
  RenderParams p;
  auto scene = make_render_scene(d, p);
  ASSERT_EQ(scene->lights.size(), 2u);
  LightSample s;
  ASSERT_TRUE(sample_light(scene->lights[0], Vec3(0, 0, 0), Vec2{0.5f, 0.5f}, s));
  EXPECT_NEAR(s.radiance.x, 0.0366032f, 1e-6f);
  EXPECT_NEAR(s.radiance.y, 0.0183016f, 1e-6f);
  EXPECT_NEAR(s.radiance.z, 0.0091508f, 1e-6f);
  EXPECT_NEAR(s.wi.z, 1.0f, 1e-6f);
  // Rotated -90 degrees about x, the directional light's -z points down: light travels along -y.
  ASSERT_TRUE(sample_light(scene->lights[1], Vec3(0, 0, 0), Vec2{0.5f, 0.5f}, s));
  EXPECT_NEAR(s.radiance.x, 0.0146413f, 1e-6f);
  EXPECT_NEAR(s.wi.y, 1.0f, 1e-5f);
}

// The spot's edge as Blender imports it and Cycles renders it (measured in Cycles, docs/gltf.md):
// zero outside the outer cone, then a smoothstep over a band of width (1 - cos outer) (1 - inner /
// outer) in the cosine, full intensity beyond it.
TEST(Gltf, SpotLightsFallOffBetweenTheCones) {
  GltfDoc g = test::quad_doc();
  g.light(json{{"type", "spot"}, {"intensity", 683}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.4}}}},
          json{{"translation", {0, 0, 1}}});
  auto scene = make_render_scene(parse(g), RenderParams());
  const Light& l = scene->lights[0];
  auto at_angle = [&](double a) {
    LightSample s;
    Vec3 p(float(std::tan(a)), 0, 0);  // on the plane z = 0, one unit below the light
    return sample_light(l, p, Vec2{0.5f, 0.5f}, s) ? double(s.radiance.x) * double(length_squared(p - l.position)) : 0.0;
  };
  EXPECT_NEAR(at_angle(0.1), 1.0, 1e-5);
  EXPECT_NEAR(at_angle(0.45), 0.0, 1e-9);
  const double band = (1 - std::cos(0.4)) * (1 - 0.2 / 0.4);
  for (double a : {0.3, 0.35, 0.38}) {
    const double x = std::min(1.0, (std::cos(a) - std::cos(0.4)) / band);
    EXPECT_NEAR(at_angle(a), x * x * (3 - 2 * x), 1e-4) << a;
  }
}

TEST(Gltf, MetallicRoughnessIsReadAsTheGltfMaterial) {
  GltfDoc g = test::quad_doc();
  auto add = [&](const json& pbr, const json& extra = json::object()) {
    json m = extra;
    m["pbrMetallicRoughness"] = pbr;
    int mat = g.material(m);
    g.mesh(json{{"POSITION", 0}}, 1, mat);
  };
  add(json{{"baseColorFactor", {0.8, 0.6, 0.4, 1}}, {"metallicFactor", 0.25}});  // 1: blended, not a threshold
  add(json{{"metallicFactor", 0}, {"roughnessFactor", 0.3}},
      json{{"extensions", {{"KHR_materials_specular", {{"specularFactor", 0.5}, {"specularColorFactor", {1, 0.5, 0.25}}}},
                           {"KHR_materials_ior", {{"ior", 1.7}}}}}});  // 2
  add(json{{"metallicFactor", 0}}, json{{"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1}}},
                                                        {"KHR_materials_ior", {{"ior", 1.33}}}}}});  // 3: rough glass
  add(json{{"metallicFactor", 0}, {"roughnessFactor", 0}},
      json{{"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1}}}}}});  // 4: smooth glass
  SceneDesc d = parse(g);
  ASSERT_EQ(d.materials.size(), 5u);
  const PbrParams& a = d.materials[1].pbr;
  EXPECT_EQ(d.materials[1].type, MaterialType::pbr);
  EXPECT_NEAR(a.base.x, 0.8f, 1e-6f);
  EXPECT_NEAR(a.metallic, 0.25f, 1e-6f);
  EXPECT_NEAR(a.roughness, 1.0f, 1e-6f);  // glTF's default
  const PbrParams& b = d.materials[2].pbr;
  EXPECT_NEAR(b.specular, 0.5f, 1e-6f);
  EXPECT_NEAR(b.specular_color.z, 0.25f, 1e-6f);
  EXPECT_NEAR(b.ior, 1.7f, 1e-6f);
  EXPECT_EQ(d.materials[3].type, MaterialType::pbr);
  EXPECT_NEAR(d.materials[3].pbr.transmission, 1.0f, 1e-6f);
  EXPECT_NEAR(d.materials[3].pbr.ior, 1.33f, 1e-6f);
  EXPECT_TRUE(is_transmissive(d.materials[3]));
  EXPECT_EQ(d.materials[4].type, MaterialType::glass);  // exact: the light tracer sees it
  // No material: glTF's default (white, metallic 1, roughness 1).
  GltfDoc h = test::quad_doc();
  h.doc["meshes"][0]["primitives"][0].erase("material");
  SceneDesc e = parse(h);
  const Material& def = e.materials[e.meshes[0].tri_material[0]];
  EXPECT_EQ(def.type, MaterialType::pbr);
  EXPECT_EQ(def.pbr.metallic, 1.0f);
  EXPECT_EQ(def.pbr.roughness, 1.0f);
}

TEST(Gltf, CameraKeepsItsVerticalFieldOfViewAtAnyImageAspect) {
  GltfDoc g = test::quad_doc();
  g.doc["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}});
  g.root(json{{"camera", 0}, {"translation", {0, 0, 5}}});
  SceneDesc d = parse(g);
  for (auto [w, h] : {std::pair{800, 600}, std::pair{300, 600}}) {
    CameraParams cp;
    cp.width = w, cp.height = h;
    Camera c = make_camera(d, cp);  // without --file-camera: glTF cameras are used as authored
    EXPECT_NEAR(c.tan_half_h, std::tan(0.25), 1e-5) << w;
    EXPECT_NEAR(c.tan_half_w, std::tan(0.25) * w / h, 1e-5) << w;
    EXPECT_NEAR(c.position.z, 5.0f, 1e-6f);
    EXPECT_NEAR(c.back.z, 1.0f, 1e-6f);
  }
  // Orthographic: a warning, and the bounds framed as for a scene without a camera.
  g.doc["cameras"][0] = json{{"type", "orthographic"}, {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 10}}}};
  EXPECT_FALSE(parse(g).camera.present);
}

// Without a camera: a three-quarter view from above and to the side of the bounds (every face of a
// box shows), looking at their centre, the whole bounding box inside the image at any -r size:
// the course's framing and crop are COLLADA's.
TEST(Gltf, AScenesWithoutACameraGetsAThreeQuarterView) {
  GltfDoc g = test::quad_doc();
  g.doc["nodes"][0]["translation"] = {3, 1, -2};
  g.doc["nodes"][0]["scale"] = {1, 1, 2};  // bounds (2, 0, -2) to (4, 2, -2)
  SceneDesc d = parse(g);
  ASSERT_FALSE(d.camera.present);
  EXPECT_TRUE(d.camera.overview);
  const Bounds3 b = d.geometry_bounds();
  for (auto [w, h] : {std::pair{320, 240}, std::pair{64, 48}, std::pair{200, 400}}) {
    CameraParams cp;
    cp.width = w, cp.height = h;
    const Camera c = make_camera(d, cp);
    const Vec3 from = c.position - b.center();
    EXPECT_GT(from.x, 0) << w;
    EXPECT_GT(from.y, 0.3f * length(from)) << w << ": looks down on the scene";
    EXPECT_GT(from.z, 0) << w;
    EXPECT_NEAR(dot(normalize(from), c.back), 1.0f, 1e-5f) << w << ": looks at the centre";
    for (int k = 0; k < 8; ++k) {
      const Vec3 corner((k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y, (k & 4) ? b.hi.z : b.lo.z);
      const Vec3 v = corner - c.position;
      const float depth = -dot(v, c.back);
      ASSERT_GT(depth, 0);
      EXPECT_LE(std::fabs(dot(v, c.right) / depth), c.tan_half_w) << w << " corner " << k;
      EXPECT_LE(std::fabs(dot(v, c.up) / depth), c.tan_half_h) << w << " corner " << k;
    }
  }
}

TEST(Gltf, UnlitScenesGetTheDefaultLightUnlessTurnedOff) {
  SceneDesc d = parse(test::quad_doc());
  RenderParams p;
  auto lit = make_render_scene(d, p);
  ASSERT_EQ(lit->lights.size(), 2u);  // a white environment and a sun, so that shapes shade
  EXPECT_EQ(lit->lights[0].kind, LightKind::ambient);
  EXPECT_TRUE(lit->lights[0].sphere);
  EXPECT_EQ(infinite_light_radiance(lit->lights[0], Vec3(0, -1, 0)).x, kDefaultEnvironment);  // from below too
  EXPECT_EQ(lit->lights[1].kind, LightKind::directional);
  EXPECT_GT(-lit->lights[1].direction.y, 0.5f) << "the sun shines from above";
  EXPECT_NE(lit->features.bits & kFeatInfinite, 0u);
  p.default_light = false;
  EXPECT_TRUE(make_render_scene(d, p)->lights.empty());
  // A COLLADA scene never gets it (the course renders an unlit scene black).
  d.default_light = false;
  EXPECT_TRUE(make_render_scene(d, RenderParams())->lights.empty());
}

TEST(Gltf, TexturesWrapAndDecodeSrgb) {
  TextureDesc t;
  t.width = 2, t.height = 1;
  t.texels = {255, 0, 0, 0, 0, 255};  // red, blue
  t.nearest = true;
  EXPECT_EQ(eval_texture(t, Vec2{0.25f, 0.5f}).x, 1.0f);
  EXPECT_EQ(eval_texture(t, Vec2{1.25f, 0.5f}).x, 1.0f);  // repeat
  t.wrap_s = TextureWrap::clamp;
  EXPECT_EQ(eval_texture(t, Vec2{1.25f, 0.5f}).z, 1.0f);
  t.wrap_s = TextureWrap::mirror;
  EXPECT_EQ(eval_texture(t, Vec2{1.25f, 0.5f}).z, 1.0f);  // [1, 2) runs backwards
  EXPECT_EQ(eval_texture(t, Vec2{1.75f, 0.5f}).x, 1.0f);
  t.nearest = false;
  t.wrap_s = TextureWrap::clamp;
  EXPECT_NEAR(eval_texture(t, Vec2{0.5f, 0.5f}).x, 0.5f, 1e-6f);  // halfway between the centres
  EXPECT_NEAR(srgb8_to_linear(128), 0.2158605f, 1e-6f);             // IEC 61966-2-1
  EXPECT_NEAR(texture_mean(t).z, 0.5f, 1e-6f);
}

// KHR_mesh_quantization: normalized bytes and shorts, read through the accessor as glTF 3.11 says.
TEST(Gltf, QuantizedAttributesAreNormalized) {
  GltfDoc g;
  // Strided as the extension requires: each 6-byte position and 2-byte uv padded to 4 bytes.
  std::vector<int16_t> pos = {-32767, 0, 0, 0, 32767, 0, 0, 0, 0, 32767, 0, 0};
  int p = g.accessor(g.view(test::bytes_of(pos), 8), 5122, 3, "VEC3", true);
  std::vector<uint8_t> uv = {0, 0, 0, 0, 255, 0, 0, 0, 0, 255, 0, 0};
  int t = g.accessor(g.view(test::bytes_of(uv), 4), 5121, 3, "VEC2", true);
  int mat = g.material(json{{"pbrMetallicRoughness", {{"metallicFactor", 0}}}});
  g.mesh(json{{"POSITION", p}, {"TEXCOORD_0", t}}, -1, mat, json{{"scale", {2, 2, 2}}});
  SceneDesc d = parse(g);
  ASSERT_EQ(d.meshes.size(), 1u);
  EXPECT_FLOAT_EQ(d.meshes[0].positions[0].x, -2.0f);
  EXPECT_FLOAT_EQ(d.meshes[0].positions[2].y, 2.0f);
  EXPECT_TRUE(d.meshes[0].uvs.empty());  // no texture reads them
}

TEST(Gltf, NodeTransformsComposeAndMirroringKeepsTheFrontFace) {
  GltfDoc g = test::quad_doc();
  // Parent: translate (0, 0, -4); child: rotate 90 degrees about y, then scale x by -1 (mirror).
  g.doc["nodes"][0] = json{{"translation", {0, 0, -4}}, {"children", {1}}};
  g.doc["nodes"].push_back(json{{"mesh", 0}, {"rotation", {0, 0.7071068, 0, 0.7071068}}, {"scale", {-1, 1, 1}}});
  SceneDesc d = parse(g);
  ASSERT_EQ(d.meshes.size(), 1u);
  const MeshDesc& m = d.meshes[0];
  Vec3 v = m.positions[1];  // (1, -1, 0) -> mirrored (-1, -1, 0) -> rotated (0, -1, 1) -> (0, -1, -3)
  EXPECT_NEAR(v.x, 0.0f, 1e-6f);
  EXPECT_NEAR(v.z, -3.0f, 1e-6f);
  // The quad faced +z: the mirror keeps that normal, the turn makes it +x; the winding agrees.
  const uint32_t* i = m.indices.data();
  Vec3 n = normalize(cross(m.positions[i[1]] - m.positions[i[0]], m.positions[i[2]] - m.positions[i[0]]));
  EXPECT_NEAR(n.x, 1.0f, 1e-5f);
  // The same as one matrix (column-major).
  GltfDoc h = test::quad_doc();
  h.doc["nodes"][0]["matrix"] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, -4, 1};
  EXPECT_NEAR(parse(h).meshes[0].positions[1].z, -3.0f, 1e-6f);
}

TEST(Gltf, UnsupportedModesAreSkippedWithOneWarning) {
  GltfDoc g = test::quad_doc();
  g.doc["meshes"][0]["primitives"].push_back(json{{"attributes", {{"POSITION", 0}}}, {"mode", 1}});
  g.doc["meshes"][0]["primitives"].push_back(json{{"attributes", {{"POSITION", 0}}}, {"mode", 1}});
  testing::internal::CaptureStderr();
  SceneDesc d = parse(g);
  std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(d.meshes.size(), 1u);
  EXPECT_NE(err.find("t.gltf: /meshes/0/primitives/1/mode: primitive mode 1 (LINES)"), std::string::npos) << err;
  EXPECT_EQ(err.find("primitives/2"), std::string::npos) << "one line per mode: " << err;
  // An unsupported extension that is only used: one warning naming it.
  g.doc["extensionsUsed"] = {"EXT_meshopt_compression", "EXT_meshopt_compression"};
  testing::internal::CaptureStderr();
  parse(g);
  err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("/extensionsUsed/0: extension 'EXT_meshopt_compression' is not supported"), std::string::npos) << err;
  EXPECT_EQ(err.find("/extensionsUsed/1"), std::string::npos) << err;
}

TEST(Gltf, FormatIsPickedByMagicExtensionOrContent) {
  EXPECT_EQ(detect_scene_format("glTF....", "scene.dae"), SceneFormat::glb);
  EXPECT_EQ(detect_scene_format("{}", "scene.dae"), SceneFormat::collada);
  EXPECT_EQ(detect_scene_format("<x/>", "scene.gltf"), SceneFormat::gltf);
  EXPECT_EQ(detect_scene_format(" \n{\"asset\":{}}", "scene"), SceneFormat::gltf);
  EXPECT_EQ(detect_scene_format("<?xml?>", "scene"), SceneFormat::collada);
  EXPECT_EQ(scene_file_name("cornell", "glTF"), "cornell.glb");
  // The same quad as .gltf and as .glb.
  GltfDoc g = test::quad_doc();
  SceneDesc a = parse_scene(g.text(), "q.gltf"), b = parse_scene(g.glb(), "q.glb");
  ASSERT_EQ(a.meshes.size(), 1u);
  ASSERT_EQ(b.meshes.size(), 1u);
  EXPECT_EQ(a.meshes[0].positions[2].y, b.meshes[0].positions[2].y);
}

TEST(Gltf, DescribeListsAGltfScenesFeatures) {
  std::string out = test::temp_dir() + "/describe.txt";
  std::string cmd = std::string(PT_PATHTRACER) + " --describe " + test::own_scene("showcase.gltf") + " > " + out + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(out);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  for (const char* want : {"glass, pbr", "mesh, spot", "textures:         1",
                           "path loop:        generic"})
    EXPECT_NE(text.find(want), std::string::npos) << want << "\n" << text;
}

// glTF's doubleSided: a single-sided emitter's back face sends nothing (the face is culled), a
// double-sided one emits from both faces, for rays that hit it and for light sampling alike.
TEST(Gltf, DoubleSidedEmittersEmitFromBothFaces) {
  for (bool two : {false, true}) {
    GltfDoc g = test::quad_doc();  // facing +z
    g.doc["materials"][0] = {{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}},
                             {"emissiveFactor", {1, 0.5, 0.25}}, {"doubleSided", two}};
    RenderParams p;
    auto scene = make_render_scene(parse(g), p);
    ASSERT_EQ(scene->lights.size(), 1u);
    const Light& l = scene->lights[0];
    EXPECT_EQ(l.kind, LightKind::mesh);
    EXPECT_EQ(l.two_sided, two);
    LightSample front, back;
    EXPECT_TRUE(sample_light(l, Vec3(0.1f, 0.2f, 2), Vec2{0.3f, 0.6f}, front));
    const bool lit_behind = sample_light(l, Vec3(0.1f, 0.2f, -2), Vec2{0.3f, 0.6f}, back);
    EXPECT_EQ(lit_behind, two);
    if (lit_behind) {
      EXPECT_NEAR(back.pdf, front.pdf, 1e-4f * front.pdf) << "the same point, mirrored";
      EXPECT_EQ(back.radiance.x, 1.0f);
    }
    // A ray from behind sees the back face's emission only when it is double-sided.
    SurfaceHit hit;
    Ray r;
    r.o = Vec3(0.2f, 0.1f, -3);
    r.d = Vec3(0, 0, 1);
    ASSERT_TRUE(scene->accel->intersect(r, hit));
    const Vec3 seen = emitted_radiance(scene->materials[size_t(hit.material)], Vec3(0, 0, dot(-r.d, hit.ng)));
    EXPECT_EQ(seen.y, two ? 0.5f : 0.0f);
  }
}
