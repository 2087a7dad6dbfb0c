// Tests for the CS184 COLLADA reader (renderer/collada.cpp): every element it supports (up axis
// and transforms, cameras, lights, geometry, materials). Malformed input: test_collada_errors.cpp;
// the course scenes: test_collada_course.cpp.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "collada.h"
#include "test_util.h"
#include "collada_docs.h"

namespace pt {
namespace {

using namespace collada_docs;

// ============================================================================================
// Up axis and transforms

TEST(ColladaTransform, BaseDocumentLoads) {
  SceneDesc s = parse_collada(base_doc(), "base.dae");
  EXPECT_EQ(s.source, "base.dae");
  EXPECT_EQ(s.triangle_count(), 2u);
  EXPECT_EQ(s.spheres.size(), 3u);
  EXPECT_EQ(s.lights.size(), 1u);
  EXPECT_TRUE(s.camera.present);
}

TEST(ColladaTransform, UpAxisYIsIdentity) {
  EXPECT_TRUE(affine_near(probe("", "Y_UP"), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}));
  // Without <up_axis>, or without <asset>, the world is taken as Y up.
  EXPECT_TRUE(affine_near(probe("", ""), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}));
  EXPECT_TRUE(affine_near(probe("", "-"), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}));
  // Surrounding white space in the value is tolerated.
  EXPECT_TRUE(affine_near(probe("", " Y_UP\n"), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}));
}

TEST(ColladaTransform, UpAxisZMapsXYZToMinusXZY) {
  Affine a = probe("<translate>1 2 3</translate>\n", "Z_UP");
  EXPECT_TRUE(vec_near(a.o, {-1, 3, 2}));
  EXPECT_TRUE(vec_near(a.x, {-1, 0, 0}));
  EXPECT_TRUE(vec_near(a.y, {0, 0, 1}));
  EXPECT_TRUE(vec_near(a.z, {0, 1, 0}));
}

TEST(ColladaTransform, UpAxisXMapsXYZToYXMinusZ) {
  Affine a = probe("<translate>1 2 3</translate>\n", "X_UP");
  EXPECT_TRUE(vec_near(a.o, {2, 1, -3}));
  EXPECT_TRUE(vec_near(a.x, {0, 1, 0}));
  EXPECT_TRUE(vec_near(a.y, {1, 0, 0}));
  EXPECT_TRUE(vec_near(a.z, {0, 0, -1}));
}

TEST(ColladaTransform, MatrixIsRowMajor) {
  // Rows: x' = x + 2y + 3z + 10, y' = 4x + 5y + 6z + 20, z' = 7x + 8y + 9z + 30.
  Affine a = probe("<matrix>1 2 3 10  4 5 6 20  7 8 9 30  0 0 0 1</matrix>\n");
  EXPECT_TRUE(affine_near(a, {{10, 20, 30}, {1, 4, 7}, {2, 5, 8}, {3, 6, 9}}));
  // A short list (CBgems' camera has 15 numbers) loads with a warning, the missing values read as 0.
  ::testing::internal::CaptureStderr();
  Affine b = probe("<matrix>1 0 0 5  0 1 0 6  0 0 1 7  0 0 0</matrix>\n");
  std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_TRUE(affine_near(b, {{5, 6, 7}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}));
  EXPECT_NE(err.find("probe.dae:29: <matrix>: only 15 numbers"), std::string::npos) << err;
}

TEST(ColladaTransform, Translate) {
  EXPECT_TRUE(affine_near(probe("<translate>1.5 -2 3</translate>\n"), {{1.5f, -2, 3}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}));
}

TEST(ColladaTransform, RotateTakesAxisAndDegrees) {
  // 90 degrees about +Z: x -> y, y -> -x (right-handed).
  EXPECT_TRUE(affine_near(probe("<rotate>0 0 1 90</rotate>\n"), {{0, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, 0, 1}}));
  // 90 degrees about +X: y -> z, z -> -y.
  EXPECT_TRUE(affine_near(probe("<rotate>1 0 0 90</rotate>\n"), {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, -1, 0}}));
  // 120 degrees about the unnormalised (2,2,2) axis cycles x -> y -> z -> x.
  EXPECT_TRUE(affine_near(probe("<rotate>2 2 2 120</rotate>\n"), {{0, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 0}}));
  // A negative angle turns the other way.
  EXPECT_TRUE(affine_near(probe("<rotate>0 1 0 -90</rotate>\n"), {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, {-1, 0, 0}}));
}

TEST(ColladaTransform, ScaleIsPerAxis) {
  EXPECT_TRUE(affine_near(probe("<scale>2 3 4</scale>\n"), {{0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0, 4}}));
}

TEST(ColladaTransform, LookatPlacesEyeAndLooksAlongMinusZ) {
  // Eye at (2,0,0) looking at the origin with +Y up: local -Z points at the target, +Y stays up.
  Affine a = probe("<lookat>2 0 0  0 0 0  0 1 0</lookat>\n");
  EXPECT_TRUE(vec_near(a.o, {2, 0, 0}));
  EXPECT_TRUE(vec_near(a.z * -1.0f, {-1, 0, 0}));  // viewing direction
  EXPECT_TRUE(vec_near(a.y, {0, 1, 0}));
  EXPECT_TRUE(vec_near(a.x, {0, 0, -1}));  // right = up x back
  // A tilted up hint is orthogonalised.
  Affine b = probe("<lookat>0 0 5  0 0 0  0 1 1</lookat>\n");
  EXPECT_TRUE(vec_near(b.o, {0, 0, 5}));
  EXPECT_TRUE(vec_near(b.z, {0, 0, 1}));
  EXPECT_TRUE(vec_near(b.y, {0, 1, 0}));
}

TEST(ColladaTransform, ElementsComposeInDocumentOrder) {
  // translate then scale: p -> T(S(p)) = 2p + (10,0,0).
  EXPECT_TRUE(affine_near(probe("<translate>10 0 0</translate>\n<scale>2 2 2</scale>\n"),
                          {{10, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}}));
  // scale then translate: p -> S(T(p)) = 2(p + (10,0,0)).
  EXPECT_TRUE(affine_near(probe("<scale>2 2 2</scale>\n<translate>10 0 0</translate>\n"),
                          {{20, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}}));
  // rotate (90 about Z) then translate: the translation is rotated, (1,0,0) -> (0,1,0).
  EXPECT_TRUE(affine_near(probe("<rotate>0 0 1 90</rotate>\n<translate>1 0 0</translate>\n"),
                          {{0, 1, 0}, {0, 1, 0}, {-1, 0, 0}, {0, 0, 1}}));
  // matrix, then translate, then rotate, then scale: all four multiply in order.
  Affine a = probe("<matrix>1 0 0 1  0 1 0 0  0 0 1 0  0 0 0 1</matrix>\n<translate>0 1 0</translate>\n"
                   "<rotate>0 0 1 90</rotate>\n<scale>3 1 1</scale>\n");
  EXPECT_TRUE(affine_near(a, {{1, 1, 0}, {0, 3, 0}, {-1, 0, 0}, {0, 0, 1}}));
  // <skew> (with a warning) and unknown elements are ignored, not fatal.
  ::testing::internal::CaptureStderr();
  Affine b = probe("<skew>45 1 0 0 0 1 0</skew>\n<frobnicate>1 2</frobnicate>\n<translate>1 0 0</translate>\n");
  std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_TRUE(affine_near(b, {{1, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}));
  EXPECT_NE(err.find("<skew>"), std::string::npos) << err;
}

TEST(ColladaTransform, NestedNodesComposeParentTimesChild) {
  std::string nodes =
      "<node>\n<scale>2 2 2</scale>\n"
      "<node>\n<translate>1 0 0</translate>\n"
      "<node>\n<rotate>0 0 1 90</rotate>\n<instance_geometry url=\"#probe\"/>\n</node>\n"
      "</node>\n</node>\n";
  SceneDesc s = parse_collada(dae(nodes, kProbeLib, "Z_UP"), "nested.dae");
  ASSERT_EQ(s.meshes.size(), 1u);
  // Local chain: S(2) * T(1,0,0) * Rz(90): origin -> (2,0,0), x -> (0,2,0), y -> (-2,0,0), z -> (0,0,2);
  // then Z_UP maps (x,y,z) -> (-x,z,y).
  EXPECT_TRUE(affine_near(affine_of(s.meshes[0]), {{-2, 0, 0}, {0, 0, 2}, {2, 0, 0}, {0, 2, 0}}));
}

TEST(ColladaTransform, InstanceNodeAppliesTheInstancingNodesTransform) {
  std::string libs = kProbeLib +
                     "<library_nodes>\n<node id=\"lib\">\n<translate>1 0 0</translate>\n"
                     "<instance_geometry url=\"#probe\"/>\n</node>\n</library_nodes>\n";
  std::string nodes =
      "<node>\n<translate>0 5 0</translate>\n<instance_node url=\"#lib\"/>\n</node>\n"
      "<node>\n<scale>2 2 2</scale>\n<instance_node url=\"#lib\"/>\n</node>\n";
  SceneDesc s = parse_collada(dae(nodes, libs), "inst.dae");
  ASSERT_EQ(s.meshes.size(), 2u);  // the library node itself is not part of the scene
  EXPECT_TRUE(affine_near(affine_of(s.meshes[0]), {{1, 5, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}));
  EXPECT_TRUE(affine_near(affine_of(s.meshes[1]), {{2, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}}));
}

TEST(ColladaTransform, NestingUpToTheDepthLimitLoads) {
  LoadLimits limits;
  limits.max_node_depth = 40;
  std::string nodes;
  for (int i = 0; i <= 40; ++i) nodes += "<node>\n<translate>0.5 0 0</translate>\n";
  nodes += "<instance_geometry url=\"#probe\"/>\n";
  for (int i = 0; i <= 40; ++i) nodes += "</node>\n";
  SceneDesc s = parse_collada(dae(nodes, kProbeLib), "deep.dae", limits);
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_TRUE(vec_near(s.meshes[0].positions[0], {20.5f, 0, 0}));
}

// ============================================================================================
// Cameras

TEST(ColladaCamera, ReadsPerspectiveFields) {
  std::string libs = kFillerLight +
                     camera_lib("cam", "<xfov>60</xfov>\n<aspect_ratio>1.5</aspect_ratio>\n<znear>0.5</znear>\n<zfar>50</zfar>\n");
  SceneDesc s = parse_collada(dae(kFillerNode + camera_node("#cam", "<translate>0 -3 1</translate>\n"), libs, "Z_UP"), "cam.dae");
  ASSERT_TRUE(s.camera.present);
  EXPECT_FLOAT_EQ(s.camera.xfov_deg, 60);
  EXPECT_FLOAT_EQ(s.camera.yfov_deg, 0);  // derived later from xfov and aspect
  EXPECT_FLOAT_EQ(s.camera.aspect, 1.5f);
  EXPECT_FLOAT_EQ(s.camera.znear, 0.5f);
  EXPECT_FLOAT_EQ(s.camera.zfar, 50);
  // The camera's world matrix includes the node transform and the up-axis conversion.
  EXPECT_TRUE(vec_near(s.camera.world.point({0, 0, 0}), {0, 1, -3}));
  EXPECT_TRUE(vec_near(s.camera.world.vector({0, 0, -1}), {0, -1, 0}));
}

TEST(ColladaCamera, FovCombinationsAndDefaults) {
  auto cam = [](const std::string& persp) {
    return parse_collada(dae(kFillerNode + camera_node("#cam"), kFillerLight + camera_lib("cam", persp)), "cam.dae").camera;
  };
  CameraDesc c = cam("<yfov>30</yfov>\n<aspect_ratio>2</aspect_ratio>\n");
  EXPECT_FLOAT_EQ(c.yfov_deg, 30);
  EXPECT_FLOAT_EQ(c.aspect, 2);
  c = cam("<xfov>70</xfov>\n<yfov>40</yfov>\n");
  EXPECT_FLOAT_EQ(c.xfov_deg, 70);
  EXPECT_FLOAT_EQ(c.yfov_deg, 40);
  // aspect_ratio alone: xfov defaults to 50 degrees (course).
  c = cam("<aspect_ratio>1.25</aspect_ratio>\n");
  EXPECT_FLOAT_EQ(c.xfov_deg, 50);
  EXPECT_FLOAT_EQ(c.aspect, 1.25f);
  // yfov alone is a valid COLLADA camera (the course gives only "yfov and aspect both absent" as fatal).
  c = cam("<yfov>35</yfov>\n");
  EXPECT_TRUE(c.present);
  EXPECT_FLOAT_EQ(c.yfov_deg, 35);
  // znear / zfar defaults.
  c = cam("<xfov>45</xfov>\n<aspect_ratio>1</aspect_ratio>\n");
  EXPECT_FLOAT_EQ(c.znear, 0.001f);
  EXPECT_FLOAT_EQ(c.zfar, 1000);
}

TEST(ColladaCamera, LastCameraWins) {
  std::string libs = kFillerLight + camera_lib("a", "<xfov>30</xfov>\n<aspect_ratio>1</aspect_ratio>\n") +
                     camera_lib("b", "<xfov>70</xfov>\n<aspect_ratio>2</aspect_ratio>\n");
  std::string nodes = camera_node("#a", "<translate>1 0 0</translate>\n") + kFillerNode +
                      camera_node("#b", "<translate>0 0 7</translate>\n");
  SceneDesc s = parse_collada(dae(nodes, libs), "cams.dae");
  EXPECT_FLOAT_EQ(s.camera.xfov_deg, 70);
  EXPECT_FLOAT_EQ(s.camera.aspect, 2);
  EXPECT_TRUE(vec_near(s.camera.world.point({0, 0, 0}), {0, 0, 7}));
}

TEST(ColladaCamera, LookatCameraNode) {
  std::string libs = kFillerLight + camera_lib("cam", "<xfov>45</xfov>\n<aspect_ratio>1</aspect_ratio>\n");
  SceneDesc s = parse_collada(dae(kFillerNode + camera_node("#cam", "<lookat>0 2 6  0 2 0  0 1 0</lookat>\n"), libs), "la.dae");
  EXPECT_TRUE(vec_near(s.camera.world.point({0, 0, 0}), {0, 2, 6}));
  EXPECT_TRUE(vec_near(s.camera.world.point({0, 0, -6}), {0, 2, 0}));  // 6 units ahead is the target
}

TEST(ColladaCamera, NoCameraMeansNotPresent) {
  SceneDesc s = parse_collada(dae(kFillerNode, kFillerLight), "nocam.dae");
  EXPECT_FALSE(s.camera.present);
}

// ============================================================================================
// Lights

TEST(ColladaLight, CglAreaRectangleFromNodeMatrix) {
  // The Cornell-box light: Z_UP, matrix scale (0.6, 0.8, 1) and translation (0, 0, 1.49).
  std::string libs = light_lib("l", "<point>\n<color>1 1 1</color>\n</point>\n", "<area>\n<color>10 9 8</color>\n</area>\n");
  SceneDesc s = parse_collada(dae(light_node("#l", "<matrix>0.6 0 0 0  0 0.8 0 0  0 0 1 1.49  0 0 0 1</matrix>\n"), libs, "Z_UP"),
                              "area.dae");
  ASSERT_EQ(s.lights.size(), 1u);
  const LightDesc& l = s.lights[0];
  EXPECT_EQ(l.type, LightType::area);  // the CGL technique wins over technique_common
  EXPECT_EQ(l.name, "l");
  EXPECT_TRUE(vec_near(l.color, {10, 9, 8}));
  EXPECT_TRUE(vec_near(l.position, {0, 1.49f, 0}));
  EXPECT_TRUE(vec_near(l.direction, {0, -1, 0}));  // facing down
  EXPECT_TRUE(vec_near(l.dim_x, {0.6f, 0, 0}));    // M * (-1,0,0), then Z_UP
  EXPECT_TRUE(vec_near(l.dim_y, {0, 0, 0.8f}));    // M * (0,1,0), then Z_UP
  EXPECT_NEAR(length(l.dim_x) * length(l.dim_y), 0.48, 1e-6);

  // Y_UP, translate then rotate 90 about X then scale: facing turns to +Y; edges follow the rotation.
  SceneDesc t = parse_collada(
      dae(light_node("#l", "<translate>1 2 3</translate>\n<rotate>1 0 0 90</rotate>\n<scale>0.6 0.8 1</scale>\n"), libs),
      "area2.dae");
  ASSERT_EQ(t.lights.size(), 1u);
  EXPECT_TRUE(vec_near(t.lights[0].position, {1, 2, 3}));
  EXPECT_TRUE(vec_near(t.lights[0].direction, {0, 1, 0}));
  EXPECT_TRUE(vec_near(t.lights[0].dim_x, {-0.6f, 0, 0}));
  EXPECT_TRUE(vec_near(t.lights[0].dim_y, {0, 0, 0.8f}));
}

TEST(ColladaLight, CglTechniquePreferredOverCommon) {
  // technique_common says ambient, CGL says area: area wins; with no CGL the common technique is used.
  std::string libs = light_lib("both", "<ambient>\n<color>1 1 1</color>\n</ambient>\n", "<area>\n<color>3 3 3</color>\n</area>\n") +
                     light_lib("common", "<ambient>\n<color>0.5 0.5 0.5</color>\n</ambient>\n");
  SceneDesc s = parse_collada(dae(light_node("#both") + light_node("#common"), libs), "pref.dae");
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].type, LightType::area);
  EXPECT_TRUE(vec_near(s.lights[0].color, {3, 3, 3}));
  EXPECT_EQ(s.lights[1].type, LightType::ambient);
  EXPECT_TRUE(vec_near(s.lights[1].color, {0.5f, 0.5f, 0.5f}));
  // profile_COMMON/technique[@sid='common'] is also read, before technique_common.
  std::string pc = "<library_lights>\n<light id=\"pc\">\n<profile_COMMON>\n<technique sid=\"common\">\n<point>\n"
                   "<color>2 2 2</color>\n</point>\n</technique>\n</profile_COMMON>\n<technique_common>\n<ambient>\n"
                   "<color>1 1 1</color>\n</ambient>\n</technique_common>\n</light>\n</library_lights>\n";
  SceneDesc p = parse_collada(dae(light_node("#pc"), pc), "pc.dae");
  ASSERT_EQ(p.lights.size(), 1u);
  EXPECT_EQ(p.lights[0].type, LightType::point);
}

TEST(ColladaLight, PointLight) {
  std::string libs = light_lib("p", "<point>\n<color>5 5 5</color>\n<constant_attenuation>1</constant_attenuation>\n"
                                    "<linear_attenuation>0</linear_attenuation>\n"
                                    "<quadratic_attenuation>0.0016</quadratic_attenuation>\n</point>\n");
  SceneDesc s = parse_collada(dae(light_node("#p", "<translate>1 2 3</translate>\n"), libs, "Z_UP"), "point.dae");
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].type, LightType::point);
  EXPECT_TRUE(vec_near(s.lights[0].color, {5, 5, 5}));
  EXPECT_TRUE(vec_near(s.lights[0].position, {-1, 3, 2}));
}

TEST(ColladaLight, SpotLightWithFalloff) {
  std::string libs = light_lib("s", "<spot>\n<color>4 4 4</color>\n<falloff_angle>40</falloff_angle>\n"
                                    "<falloff_exponent>3</falloff_exponent>\n</spot>\n") +
                     light_lib("d", "<spot>\n<color>1 1 1</color>\n</spot>\n");
  // Rotating -90 about X points the local -Z axis down.
  std::string nodes = light_node("#s", "<translate>0 5 0</translate>\n<rotate>1 0 0 -90</rotate>\n") + light_node("#d");
  SceneDesc s = parse_collada(dae(nodes, libs), "spot.dae");
  ASSERT_EQ(s.lights.size(), 2u);
  const LightDesc& l = s.lights[0];
  EXPECT_EQ(l.type, LightType::spot);
  EXPECT_TRUE(vec_near(l.color, {4, 4, 4}));
  EXPECT_TRUE(vec_near(l.position, {0, 5, 0}));
  EXPECT_TRUE(vec_near(l.direction, {0, -1, 0}));
  EXPECT_FLOAT_EQ(l.spot_angle_deg, 40);
  EXPECT_FLOAT_EQ(l.spot_exponent, 3);
  // Defaults: COLLADA's 180-degree cone, no exponent; untransformed axis is -Z.
  EXPECT_FLOAT_EQ(s.lights[1].spot_angle_deg, 180);
  EXPECT_FLOAT_EQ(s.lights[1].spot_exponent, 0);
  EXPECT_TRUE(vec_near(s.lights[1].direction, {0, 0, -1}));
}

TEST(ColladaLight, DirectionalLightDirection) {
  // The course takes normalize(M * (0,0,-1)) as the direction towards the light (cs184-spec (c):
  // cow.dae's light comes from above); light travels the opposite way. The translation, which the
  // course folds in by mistake, must not change the direction.
  std::string libs = light_lib("d", "<directional>\n<color>0.7 0.8 0.9</color>\n</directional>\n");
  SceneDesc s = parse_collada(
      dae(light_node("#d", "<translate>7 8 9</translate>\n<rotate>1 0 0 45</rotate>\n"), libs), "dir.dae");
  ASSERT_EQ(s.lights.size(), 1u);
  const LightDesc& l = s.lights[0];
  EXPECT_EQ(l.type, LightType::directional);
  EXPECT_TRUE(vec_near(l.color, {0.7f, 0.8f, 0.9f}));
  // Rx(45) * (0,0,-1) = (0, 0.7071, -0.7071) points towards the light.
  const float h = std::sqrt(0.5f);
  EXPECT_TRUE(vec_near(l.direction, {0, -h, h}));
  EXPECT_NEAR(length(l.direction), 1.0f, 1e-6f);
  SceneDesc z = parse_collada(dae(light_node("#d", "<rotate>1 0 0 180</rotate>\n"), libs, "Z_UP"), "dirz.dae");
  // Rx(180) * (0,0,-1) = (0,0,1), Z_UP -> (0,1,0): the light is above, so it travels down.
  EXPECT_TRUE(vec_near(z.lights[0].direction, {0, -1, 0}));
}

TEST(ColladaLight, AmbientLight) {
  std::string libs = light_lib("a", "<ambient>\n<color>0.2 0.3 0.4</color>\n</ambient>\n");
  SceneDesc s = parse_collada(dae(light_node("#a", "<translate>9 9 9</translate>\n"), libs), "amb.dae");
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].type, LightType::ambient);
  EXPECT_TRUE(vec_near(s.lights[0].color, {0.2f, 0.3f, 0.4f}));
}

TEST(ColladaLight, ColourWithAlphaAndComments) {
  // A fourth (alpha) value is ignored; comments before the type element are skipped.
  std::string libs = "<library_lights>\n<light id=\"c\">\n<technique_common>\n<!-- a comment -->\n<point>\n"
                     "<color>1 2 3 1</color>\n</point>\n</technique_common>\n</light>\n</library_lights>\n";
  SceneDesc s = parse_collada(dae(light_node("#c"), libs), "alpha.dae");
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].type, LightType::point);
  EXPECT_TRUE(vec_near(s.lights[0].color, {1, 2, 3}));
}

// ============================================================================================
// Geometry

TEST(ColladaGeometry, PolylistFanTriangulatesQuadsAndNgons) {
  // A triangle, a unit square, a convex pentagon and a regular hexagon, all in the z = 0 plane,
  // wound counter-clockwise (+Z facing).
  std::vector<std::pair<double, double>> pts = {{0, 0}, {1, 0}, {0, 1},                          // triangle
                                                {2, 0}, {3, 0}, {3, 1}, {2, 1},                  // square
                                                {5, 0}, {6, 0}, {6.5, 1}, {5.5, 1.8}, {4.5, 1}};  // pentagon
  for (int i = 0; i < 6; ++i) pts.push_back({10 + std::cos(i * M_PI / 3), std::sin(i * M_PI / 3)});
  std::vector<int> sizes = {3, 4, 5, 6};
  std::string positions, p, vcount;
  for (auto& [x, y] : pts) positions += std::to_string(x) + " " + std::to_string(y) + " 0 ";
  for (size_t i = 0; i < pts.size(); ++i) p += std::to_string(i) + " ";
  for (int n : sizes) vcount += std::to_string(n) + " ";
  double expected_area = 0;
  size_t at = 0;
  for (int n : sizes) {  // shoelace
    for (int i = 0; i < n; ++i) {
      auto [x0, y0] = pts[at + i];
      auto [x1, y1] = pts[at + (i + 1) % n];
      expected_area += 0.5 * (x0 * y1 - x1 * y0);
    }
    at += n;
  }
  std::string libs = kFillerLight + "<library_geometries>\n" + mesh_geometry("poly", positions, polylist(vcount, p)) +
                     "</library_geometries>\n";
  SceneDesc s = parse_collada(dae(kFillerNode + geom_node("#poly"), libs), "poly.dae");
  ASSERT_EQ(s.meshes.size(), 1u);
  const MeshDesc& m = s.meshes[0];
  EXPECT_EQ(m.indices.size() / 3, size_t(1 + 2 + 3 + 4));
  EXPECT_EQ(m.tri_material.size(), m.indices.size() / 3);
  EXPECT_NEAR(mesh_area(m), expected_area, 1e-5);
  // Every triangle keeps the polygon's winding (+Z).
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    Vec3 n = cross(m.positions[m.indices[t + 1]] - m.positions[m.indices[t]], m.positions[m.indices[t + 2]] - m.positions[m.indices[t]]);
    EXPECT_GT(n.z, 0) << "triangle " << t / 3;
  }
  EXPECT_TRUE(m.normals.empty());  // planar: flat shading
}

TEST(ColladaGeometry, TrianglesElement) {
  std::string libs = kFillerLight + "<library_geometries>\n" +
                     mesh_geometry("tri", "0 0 0  1 0 0  1 1 0  0 1 0", triangles("0 1 2  0 2 3")) + "</library_geometries>\n";
  SceneDesc s = parse_collada(dae(kFillerNode + geom_node("#tri"), libs), "tri.dae");
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_NEAR(mesh_area(s.meshes[0]), 1.0, 1e-6);
}

TEST(ColladaGeometry, PolygonsElementWithHoles) {
  // One square <p> and one <ph> whose outer ring (a 2x2 square) is kept; the hole is ignored.
  std::string prims =
      "<polygons count=\"2\">\n<input semantic=\"VERTEX\" source=\"#V\" offset=\"0\"/>\n"
      "<p>0 1 2 3</p>\n<ph>\n<p>4 5 6 7</p>\n<h>8 9 10</h>\n</ph>\n</polygons>\n";
  std::string positions = "0 0 0  1 0 0  1 1 0  0 1 0   5 0 0  7 0 0  7 2 0  5 2 0   5.5 0.5 0  6 0.5 0  6 1 0";
  std::string libs = kFillerLight + "<library_geometries>\n" + mesh_geometry("pg", positions, prims) + "</library_geometries>\n";
  SceneDesc s = parse_collada(dae(kFillerNode + geom_node("#pg"), libs), "pg.dae");
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].indices.size() / 3, 4u);
  EXPECT_NEAR(mesh_area(s.meshes[0]), 1.0 + 4.0, 1e-5);
}

TEST(ColladaGeometry, InterleavedInputsUseTheVertexOffset) {
  // VERTEX at offset 1 of three interleaved inputs; the other indices are junk for positions.
  std::string prims =
      "<polylist count=\"1\">\n<input semantic=\"NORMAL\" source=\"#nrm\" offset=\"0\"/>\n"
      "<input semantic=\"VERTEX\" source=\"#V\" offset=\"1\"/>\n<input semantic=\"TEXCOORD\" source=\"#uv\" offset=\"2\" set=\"0\"/>\n"
      "<vcount>4</vcount>\n<p>9 3 8  9 2 8  9 1 8  9 0 8</p>\n</polylist>\n";
  std::string libs = kFillerLight + "<library_geometries>\n" +
                     mesh_geometry("il", "0 0 0  1 0 0  1 1 0  0 1 0", prims) + "</library_geometries>\n";
  SceneDesc s = parse_collada(dae(kFillerNode + geom_node("#il"), libs), "il.dae");
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].indices, (std::vector<uint32_t>{3, 2, 1, 3, 1, 0}));
}

TEST(ColladaGeometry, SeveralPrimitivesBindMaterialsBySymbol) {
  std::string libs = material("matA", phong("phong", "1 0 0 1")) + material("matB", phong("phong", "0 0 1 1")) +
                     kFillerLight + "<library_geometries>\n" +
                     mesh_geometry("two", "0 0 0  1 0 0  1 1 0  0 1 0  2 0 0  2 1 0",
                                   polylist("3", "0 1 2", "symB") + triangles("0 2 3  1 4 5", "symA")) +
                     "</library_geometries>\n";
  // Bound in the opposite order to the primitives: the binding must go by symbol, not position.
  std::string nodes = kFillerNode + geom_node("#two", "", {{"symA", "#matA"}, {"symB", "#matB"}});
  SceneDesc s = parse_collada(dae(nodes, libs), "mats.dae");
  ASSERT_EQ(s.meshes.size(), 1u);
  const MeshDesc& m = s.meshes[0];
  ASSERT_EQ(m.tri_material.size(), 3u);
  EXPECT_TRUE(vec_near(s.materials.at(m.tri_material[0]).albedo, {0, 0, 1}));
  EXPECT_TRUE(vec_near(s.materials.at(m.tri_material[1]).albedo, {1, 0, 0}));
  EXPECT_TRUE(vec_near(s.materials.at(m.tri_material[2]).albedo, {1, 0, 0}));
  EXPECT_EQ(s.materials.at(m.tri_material[0]).name, "matB");
  EXPECT_EQ(s.materials.at(m.tri_material[1]).name, "matA");
}

TEST(ColladaGeometry, CglSphereCentreAndRadiusFromMatrix) {
  std::string libs = kFillerLight + "<library_geometries>\n" + sphere_geometry("ball", "0.5") + "</library_geometries>\n";
  // Rotate 90 about Z then scale 2: the x column is (0,2,0), length 2.
  std::string nodes = geom_node("#ball", "<translate>1 2 3</translate>\n<rotate>0 0 1 90</rotate>\n<scale>2 2 2</scale>\n") +
                      // Non-uniform scale: the radius follows the x column only (course).
                      geom_node("#ball", "<scale>3 1 1</scale>\n") + kFillerNode;
  SceneDesc s = parse_collada(dae(nodes, libs, "Z_UP"), "sph.dae");
  ASSERT_EQ(s.spheres.size(), 2u);
  EXPECT_TRUE(vec_near(s.spheres[0].center, {-1, 3, 2}));
  EXPECT_NEAR(s.spheres[0].radius, 1.0f, 1e-6f);
  EXPECT_EQ(s.spheres[0].name, "ball");
  EXPECT_TRUE(vec_near(s.spheres[1].center, {0, 0, 0}));
  EXPECT_NEAR(s.spheres[1].radius, 1.5f, 1e-6f);
  EXPECT_EQ(s.triangle_count(), 0u);
}

TEST(ColladaGeometry, FlatMeshHasNoNormalsCurvedMeshHasUnitNormals) {
  // Octahedron, outward winding.
  std::string oct_pos = "1 0 0  -1 0 0  0 1 0  0 -1 0  0 0 1  0 0 -1";
  std::string oct_p = "0 2 4  2 1 4  1 3 4  3 0 4  2 0 5  1 2 5  3 1 5  0 3 5";
  std::string libs = kFillerLight + "<library_geometries>\n" +
                     mesh_geometry("flat", "0 0 0  1 0 0  1 1 0  0 1 0", polylist("4", "0 1 2 3")) +
                     mesh_geometry("oct", oct_pos, triangles(oct_p)) + "</library_geometries>\n";
  std::string nodes = kFillerNode + geom_node("#flat") + geom_node("#oct", "<translate>5 0 0</translate>\n") +
                      geom_node("#oct", "<translate>-5 0 0</translate>\n<scale>-1 2 1</scale>\n");  // mirrored
  SceneDesc s = parse_collada(dae(nodes, libs), "normals.dae");
  ASSERT_EQ(s.meshes.size(), 3u);
  EXPECT_TRUE(s.meshes[0].normals.empty());
  for (int k : {1, 2}) {
    const MeshDesc& m = s.meshes[k];
    Vec3 centre = k == 1 ? Vec3(5, 0, 0) : Vec3(-5, 0, 0);
    ASSERT_EQ(m.normals.size(), m.positions.size()) << "mesh " << k;
    for (size_t i = 0; i < m.normals.size(); ++i) {
      EXPECT_NEAR(length(m.normals[i]), 1.0f, 1e-5f) << "mesh " << k << " vertex " << i;
      EXPECT_GT(dot(m.normals[i], m.positions[i] - centre), 0) << "mesh " << k << " vertex " << i << " normal points inwards";
    }
    // Outward winding survives the mirroring transform.
    for (size_t t = 0; t < m.indices.size(); t += 3) {
      Vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]], c = m.positions[m.indices[t + 2]];
      EXPECT_GT(dot(cross(b - a, c - a), (a + b + c) / 3.0f - centre), 0) << "mesh " << k << " triangle " << t / 3;
    }
  }
}

TEST(ColladaGeometry, UnsupportedPrimitivesAreSkippedNotFatal) {
  std::string prims = "<lines count=\"1\">\n<input semantic=\"VERTEX\" source=\"#V\" offset=\"0\"/>\n<p>0 1</p>\n</lines>\n" +
                      triangles("0 1 2");
  std::string libs = kFillerLight + "<library_geometries>\n" + mesh_geometry("ln", "0 0 0  1 0 0  0 1 0", prims) +
                     "</library_geometries>\n";
  ::testing::internal::CaptureStderr();
  SceneDesc s = parse_collada(dae(kFillerNode + geom_node("#ln"), libs), "lines.dae");
  std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(s.triangle_count(), 1u);
  EXPECT_NE(err.find("<lines>"), std::string::npos) << err;
}

// ============================================================================================
// Materials

TEST(ColladaMaterial, EveryMaterialKind) {
  std::string libs =
      material("ph", phong("phong", "0.1 0.2 0.3 1")) + material("la", phong("lambert", "0.4 0.5 0.6 1")) +
      material("bl", phong("blinn", "0.7 0.6 0.5 1")) +
      material("mi", phong("phong", "0.9 0.9 0.9 1") + cgl("<mirror>\n<reflectance>0.9 0.8 0.7</reflectance>\n</mirror>\n")) +
      material("gl", cgl("<glass>\n<reflectance>0.7 0.6 0.5</reflectance>\n<transmittance>1 0.9 0.8</transmittance>\n"
                         "<roughness>0</roughness>\n<ior>1.33</ior>\n</glass>\n")) +
      material("rf", cgl("<refraction>\n<transmittance>0.9 1 0.9</transmittance>\n<roughness>0</roughness>\n<ior>1.6</ior>\n</refraction>\n")) +
      material("mf", cgl("<microfacet>\n<alpha>0.3</alpha>\n<eta>0.2 0.9 1.1</eta>\n<k>3.9 2.4 2.2</k>\n"
                         "<reflectance>1 1 1</reflectance>\n</microfacet>\n")) +
      material("em", cgl("<emission>\n<radiance>4 5 6</radiance>\n</emission>\n")) +
      // The last recognised CGL child wins; an unrecognised CGL child falls back to the common profile.
      material("last", cgl("<mirror>\n<reflectance>1 1 1</reflectance>\n</mirror>\n<glass>\n<reflectance>1 1 1</reflectance>\n"
                           "<transmittance>1 1 1</transmittance>\n<roughness>0</roughness>\n<ior>2.4</ior>\n</glass>\n")) +
      material("cdiff", phong("phong", "0.3 0.3 0.3 1") + cgl("<diffuse>\n<reflectance>1 0 0</reflectance>\n</diffuse>\n")) +
      // A textured diffuse colour is not read: 0.5 grey.
      material("tex", "<profile_COMMON>\n<technique sid=\"common\">\n<phong>\n<diffuse>\n<texture texture=\"img\" texcoord=\"uv\"/>\n"
                      "</diffuse>\n</phong>\n</technique>\n</profile_COMMON>\n") +
      kFillerLight + "<library_geometries>\n" + sphere_geometry("ball", "1") + "</library_geometries>\n";
  std::vector<std::string> ids = {"ph", "la", "bl", "mi", "gl", "rf", "mf", "em", "last", "cdiff", "tex", "ph"};
  std::string nodes = kFillerNode;
  for (const std::string& id : ids) nodes += geom_node("#ball", "", {{id, "#" + id}});
  SceneDesc s = parse_collada(dae(nodes, libs), "mats.dae");
  ASSERT_EQ(s.spheres.size(), ids.size());
  auto mat = [&](size_t i) -> const Material& { return s.materials.at(s.spheres.at(i).material); };

  EXPECT_EQ(mat(0).type, MaterialType::diffuse);
  EXPECT_EQ(mat(0).name, "ph");
  EXPECT_TRUE(vec_near(mat(0).albedo, {0.1f, 0.2f, 0.3f}));
  EXPECT_EQ(mat(1).type, MaterialType::diffuse);
  EXPECT_TRUE(vec_near(mat(1).albedo, {0.4f, 0.5f, 0.6f}));
  EXPECT_EQ(mat(2).type, MaterialType::diffuse);
  EXPECT_TRUE(vec_near(mat(2).albedo, {0.7f, 0.6f, 0.5f}));

  EXPECT_EQ(mat(3).type, MaterialType::mirror);  // CGL over phong
  EXPECT_TRUE(vec_near(mat(3).albedo, {0.9f, 0.8f, 0.7f}));

  EXPECT_EQ(mat(4).type, MaterialType::glass);
  EXPECT_TRUE(vec_near(mat(4).albedo, {0.7f, 0.6f, 0.5f}));
  EXPECT_TRUE(vec_near(mat(4).transmittance, {1, 0.9f, 0.8f}));
  EXPECT_FLOAT_EQ(mat(4).ior, 1.33f);

  EXPECT_EQ(mat(5).type, MaterialType::refraction);
  EXPECT_TRUE(vec_near(mat(5).transmittance, {0.9f, 1, 0.9f}));
  EXPECT_FLOAT_EQ(mat(5).ior, 1.6f);

  EXPECT_EQ(mat(6).type, MaterialType::microfacet);
  EXPECT_FLOAT_EQ(mat(6).alpha, 0.3f);
  EXPECT_TRUE(vec_near(mat(6).eta, {0.2f, 0.9f, 1.1f}));
  EXPECT_TRUE(vec_near(mat(6).k, {3.9f, 2.4f, 2.2f}));

  EXPECT_EQ(mat(7).type, MaterialType::emission);
  EXPECT_TRUE(vec_near(mat(7).radiance, {4, 5, 6}));

  EXPECT_EQ(mat(8).type, MaterialType::glass);
  EXPECT_FLOAT_EQ(mat(8).ior, 2.4f);

  EXPECT_EQ(mat(9).type, MaterialType::diffuse);
  EXPECT_TRUE(vec_near(mat(9).albedo, {0.3f, 0.3f, 0.3f}));

  EXPECT_EQ(mat(10).type, MaterialType::diffuse);
  EXPECT_TRUE(vec_near(mat(10).albedo, {0.5f, 0.5f, 0.5f}));

  // A material bound twice is read once.
  EXPECT_EQ(s.spheres[0].material, s.spheres[11].material);
  EXPECT_EQ(s.materials.size(), ids.size() - 1);
}

TEST(ColladaMaterial, NoBindingGivesSharedHalfGreyDiffuse) {
  std::string libs = kFillerLight + "<library_geometries>\n" + sphere_geometry("ball", "1") +
                     mesh_geometry("tri", "0 0 0  1 0 0  0 1 0", polylist("3", "0 1 2")) + "</library_geometries>\n";
  SceneDesc s = parse_collada(dae(kFillerNode + geom_node("#ball") + geom_node("#tri"), libs), "grey.dae");
  ASSERT_EQ(s.spheres.size(), 1u);
  ASSERT_EQ(s.meshes.size(), 1u);
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.spheres[0].material, 0);
  EXPECT_EQ(s.meshes[0].tri_material, (std::vector<int>{0}));
  EXPECT_EQ(s.materials[0].type, MaterialType::diffuse);
  EXPECT_TRUE(vec_near(s.materials[0].albedo, {0.5f, 0.5f, 0.5f}));
}

}  // namespace
}  // namespace pt
