// Tests for the CS184 COLLADA reader (renderer/collada.cpp): every element it supports, malformed
// input (each a SceneError naming file, element and line; never a crash or a hang), and the course
// scenes in ../shared/scenes-cs184 (skipped cleanly when absent).
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

namespace pt {
namespace {

// ---- small documents ----

// A whole COLLADA document. `libs` are library sections, `nodes` the visual scene's children.
// `up` is the <up_axis> text; "" writes an <asset> without <up_axis>, "-" writes no <asset>.
std::string dae(const std::string& nodes, const std::string& libs, const std::string& up = "Y_UP") {
  std::string s =
      "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
      "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n";
  if (up != "-") {
    s += "<asset>\n";
    if (!up.empty()) s += "<up_axis>" + up + "</up_axis>\n";
    s += "</asset>\n";
  }
  s += libs;
  s += "<library_visual_scenes>\n<visual_scene id=\"Scene\">\n" + nodes + "</visual_scene>\n</library_visual_scenes>\n";
  s += "<scene>\n<instance_visual_scene url=\"#Scene\"/>\n</scene>\n</COLLADA>\n";
  return s;
}

size_t count_tokens(const std::string& s) {
  std::istringstream in(s);
  std::string t;
  size_t n = 0;
  while (in >> t) ++n;
  return n;
}

// A <geometry id=id> mesh over `positions` (x y z ...); in `prims` "#V" names the mesh's <vertices>.
std::string mesh_geometry(const std::string& id, const std::string& positions, std::string prims) {
  for (size_t at; (at = prims.find("\"#V\"")) != std::string::npos;) prims.replace(at, 4, "\"#" + id + "-v\"");
  return "<geometry id=\"" + id + "\">\n<mesh>\n<source id=\"" + id + "-pos\">\n<float_array id=\"" + id +
         "-arr\" count=\"" + std::to_string(count_tokens(positions)) + "\">" + positions + "</float_array>\n" +
         "<technique_common>\n<accessor source=\"#" + id + "-arr\" count=\"" +
         std::to_string(count_tokens(positions) / 3) + "\" stride=\"3\"/>\n</technique_common>\n</source>\n" +
         "<vertices id=\"" + id + "-v\">\n<input semantic=\"POSITION\" source=\"#" + id + "-pos\"/>\n</vertices>\n" +
         prims + "</mesh>\n</geometry>\n";
}

std::string polylist(const std::string& vcount, const std::string& p, const std::string& material = "") {
  std::string m = material.empty() ? "" : " material=\"" + material + "\"";
  return "<polylist" + m + " count=\"" + std::to_string(count_tokens(vcount)) +
         "\">\n<input semantic=\"VERTEX\" source=\"#V\" offset=\"0\"/>\n<vcount>" + vcount + "</vcount>\n<p>" + p +
         "</p>\n</polylist>\n";
}

std::string triangles(const std::string& p, const std::string& material = "") {
  std::string m = material.empty() ? "" : " material=\"" + material + "\"";
  return "<triangles" + m + " count=\"" + std::to_string(count_tokens(p) / 3) +
         "\">\n<input semantic=\"VERTEX\" source=\"#V\" offset=\"0\"/>\n<p>" + p + "</p>\n</triangles>\n";
}

std::string sphere_geometry(const std::string& id, const std::string& radius) {
  return "<geometry id=\"" + id + "\">\n<extra>\n<technique profile=\"CGL\">\n<sphere>\n<radius>" + radius +
         "</radius>\n</sphere>\n</technique>\n</extra>\n</geometry>\n";
}

// A material `id` whose effect holds `effect_body`.
std::string material(const std::string& id, const std::string& effect_body) {
  return "<library_effects>\n<effect id=\"" + id + "-fx\">\n" + effect_body +
         "</effect>\n</library_effects>\n<library_materials>\n<material id=\"" + id + "\">\n<instance_effect url=\"#" +
         id + "-fx\"/>\n</material>\n</library_materials>\n";
}
std::string phong(const std::string& shader, const std::string& diffuse) {
  return "<profile_COMMON>\n<technique sid=\"common\">\n<" + shader + ">\n<diffuse>\n<color sid=\"diffuse\">" + diffuse +
         "</color>\n</diffuse>\n</" + shader + ">\n</technique>\n</profile_COMMON>\n";
}
std::string cgl(const std::string& body) { return "<extra>\n<technique profile=\"CGL\">\n" + body + "</technique>\n</extra>\n"; }

// A node instancing geometry `url`, with `transforms` and {symbol, target} material bindings.
std::string geom_node(const std::string& url, const std::string& transforms = "",
                      const std::vector<std::pair<std::string, std::string>>& binds = {}) {
  std::string s = "<node>\n" + transforms + "<instance_geometry url=\"" + url + "\">\n";
  if (!binds.empty()) {
    s += "<bind_material>\n<technique_common>\n";
    for (auto& [sym, target] : binds)
      s += "<instance_material symbol=\"" + sym + "\" target=\"" + target + "\"/>\n";
    s += "</technique_common>\n</bind_material>\n";
  }
  return s + "</instance_geometry>\n</node>\n";
}

std::string light_lib(const std::string& id, const std::string& common, const std::string& cgl_body = "") {
  std::string s = "<library_lights>\n<light id=\"" + id + "\">\n";
  if (!common.empty()) s += "<technique_common>\n" + common + "</technique_common>\n";
  if (!cgl_body.empty()) s += cgl(cgl_body);
  return s + "</light>\n</library_lights>\n";
}
std::string light_node(const std::string& url, const std::string& transforms = "") {
  return "<node>\n" + transforms + "<instance_light url=\"" + url + "\"/>\n</node>\n";
}

std::string camera_lib(const std::string& id, const std::string& perspective) {
  return "<library_cameras>\n<camera id=\"" + id + "\">\n<optics>\n<technique_common>\n<perspective>\n" + perspective +
         "</perspective>\n</technique_common>\n</optics>\n</camera>\n</library_cameras>\n";
}
std::string camera_node(const std::string& url, const std::string& transforms = "") {
  return "<node>\n" + transforms + "<instance_camera url=\"" + url + "\"/>\n</node>\n";
}

// A scene needs geometry or a light to load; this point light is far out of the way.
const std::string kFillerLight = light_lib("filler", "<point>\n<color>1 1 1</color>\n</point>\n");
const std::string kFillerNode = light_node("#filler");

// ---- the probe: recovering a node's world transform ----

// Images of the origin and of the three unit axes (as vectors) under a world transform.
struct Affine {
  Vec3 o, x, y, z;
  Vec3 apply(Vec3 p) const { return o + x * p.x + y * p.y + z * p.z; }
};
// A triangle mesh whose vertices are the origin and the unit axes (vertex 3 is unreferenced).
const std::string kProbeLib = "<library_geometries>\n" +
                              mesh_geometry("probe", "0 0 0  1 0 0  0 1 0  0 0 1", polylist("3", "0 1 2")) +
                              "</library_geometries>\n";
Affine affine_of(const MeshDesc& m) {
  EXPECT_EQ(m.positions.size(), 4u);
  if (m.positions.size() != 4) return {};
  Vec3 o = m.positions[0];
  return {o, m.positions[1] - o, m.positions[2] - o, m.positions[3] - o};
}
// The world transform that a node with `transforms` gives under up axis `up`.
Affine probe(const std::string& transforms, const std::string& up = "Y_UP") {
  SceneDesc s = parse_collada(dae(geom_node("#probe", transforms), kProbeLib, up), "probe.dae");
  EXPECT_EQ(s.meshes.size(), 1u);
  return s.meshes.empty() ? Affine{} : affine_of(s.meshes[0]);
}

::testing::AssertionResult vec_near(Vec3 a, Vec3 b, float tol = 1e-5f) {
  if (std::fabs(a.x - b.x) <= tol && std::fabs(a.y - b.y) <= tol && std::fabs(a.z - b.z) <= tol)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "(" << a.x << ", " << a.y << ", " << a.z << ") vs expected (" << b.x << ", "
                                       << b.y << ", " << b.z << "), tolerance " << tol;
}

::testing::AssertionResult affine_near(const Affine& a, const Affine& b, float tol = 1e-5f) {
  const char* names[] = {"origin", "x axis", "y axis", "z axis"};
  const Vec3 va[] = {a.o, a.x, a.y, a.z}, vb[] = {b.o, b.x, b.y, b.z};
  for (int i = 0; i < 4; ++i)
    if (auto r = vec_near(va[i], vb[i], tol); !r) return ::testing::AssertionFailure() << names[i] << ": " << r.message();
  return ::testing::AssertionSuccess();
}

double mesh_area(const MeshDesc& m) {
  double a = 0;
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    Vec3 p0 = m.positions[m.indices[t]], p1 = m.positions[m.indices[t + 1]], p2 = m.positions[m.indices[t + 2]];
    a += 0.5 * length(cross(p1 - p0, p2 - p0));
  }
  return a;
}

// ---- errors ----

// ":<line>:" for the line on which `marker` first occurs in `text`.
std::string line_tag(const std::string& text, const std::string& marker) {
  size_t at = text.find(marker);
  if (at == std::string::npos) return "<marker '" + marker + "' not in the document>";
  return ":" + std::to_string(1 + std::count(text.begin(), text.begin() + at, '\n')) + ":";
}

// Parses `text` as "bad.dae" and succeeds when a SceneError is thrown whose message starts with the
// file name and holds every one of `parts`.
::testing::AssertionResult scene_error(const std::string& text, const std::vector<std::string>& parts,
                                       const LoadLimits& limits = {}) {
  std::string msg;
  try {
    parse_collada(text, "bad.dae", limits);
    return ::testing::AssertionFailure() << "no error was raised";
  } catch (const SceneError& e) {
    msg = e.what();
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << "not a SceneError: " << e.what();
  }
  if (msg.rfind("bad.dae", 0) != 0) return ::testing::AssertionFailure() << "message does not start with the file name: " << msg;
  for (const std::string& p : parts)
    if (msg.find(p) == std::string::npos)
      return ::testing::AssertionFailure() << "message lacks '" << p << "': " << msg;
  return ::testing::AssertionSuccess() << msg;
}

// `text` with the first `from` replaced by `to` (the test fails when `from` is absent).
std::string with(std::string text, const std::string& from, const std::string& to) {
  size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' is not in the document";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// A valid document using most of the dialect, for the malformed-input tests to break one piece at a time.
std::string base_doc() {
  std::string libs =
      camera_lib("cam", "<xfov>45</xfov>\n<aspect_ratio>1.5</aspect_ratio>\n<znear>0.1</znear>\n<zfar>100</zfar>\n") +
      light_lib("lamp", "<point>\n<color>1 1 1</color>\n</point>\n", "<area>\n<color>10 10 10</color>\n</area>\n") +
      material("red", phong("phong", "0.8 0.1 0.1 1")) +
      material("glassy", cgl("<glass>\n<reflectance>1 1 1</reflectance>\n<transmittance>1 1 1</transmittance>\n"
                             "<roughness>0</roughness>\n<ior>1.5</ior>\n</glass>\n")) +
      material("metal", cgl("<microfacet>\n<alpha>0.2</alpha>\n<eta>0.2 0.9 1.1</eta>\n<k>3.9 2.4 2.2</k>\n</microfacet>\n")) +
      "<library_geometries>\n" +
      mesh_geometry("quad", "-1 0 -1  1 0 -1  1 0 1  -1 0 1", polylist("3 3", "0 2 1  0 3 2")) +
      sphere_geometry("ball", "0.25") + "</library_geometries>\n" +
      "<library_nodes>\n<node id=\"shared\">\n<translate>0 0.5 0</translate>\n"
      "<instance_geometry url=\"#ball\"/>\n</node>\n</library_nodes>\n";
  std::string nodes = camera_node("#cam", "<translate>0 1 4</translate>\n") +
                      light_node("#lamp", "<translate>0 1.9 0</translate>\n<rotate>1 0 0 90</rotate>\n") +
                      geom_node("#quad", "", {{"red", "#red"}}) +
                      geom_node("#ball", "<translate>-0.5 0.25 0</translate>\n", {{"glassy", "#glassy"}}) +
                      geom_node("#ball", "<translate>0.5 0.25 0</translate>\n", {{"metal", "#metal"}}) +
                      "<node>\n<instance_node url=\"#shared\"/>\n</node>\n";
  return dae(nodes, libs);
}

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

// ============================================================================================
// Malformed or unsupported input: a located SceneError, never a crash or a hang

TEST(ColladaError, NotXml) {
  EXPECT_TRUE(scene_error("this is not XML at all", {"XML"}));
  EXPECT_TRUE(scene_error("", {"XML"}));
  EXPECT_TRUE(scene_error(std::string("\0\1\2\3garbage", 11), {"XML"}));
  // A mismatched end tag: the message gives the line of the error.
  std::string text = "<?xml version=\"1.0\"?>\n<COLLADA>\n<asset>\n</COLLADA>\n";
  EXPECT_TRUE(scene_error(text, {"XML", ":4:"}));
  // Truncated mid-document.
  std::string doc = base_doc();
  EXPECT_TRUE(scene_error(doc.substr(0, doc.size() / 2), {"XML"}));
}

TEST(ColladaError, WrongRoot) {
  std::string text = "<?xml version=\"1.0\"?>\n<scene>\n<instance_visual_scene url=\"#S\"/>\n</scene>\n";
  EXPECT_TRUE(scene_error(text, {"bad.dae:2:", "<scene>", "COLLADA"}));
}

TEST(ColladaError, MissingScene) {
  std::string doc = with(base_doc(), "<scene>\n<instance_visual_scene url=\"#Scene\"/>\n</scene>\n", "");
  EXPECT_TRUE(scene_error(doc, {"<COLLADA", line_tag(doc, "<COLLADA"), "missing <scene>"}));
  doc = with(base_doc(), "<instance_visual_scene url=\"#Scene\"/>\n", "");
  EXPECT_TRUE(scene_error(doc, {"<scene>", line_tag(doc, "<scene>"), "<instance_visual_scene>"}));
}

TEST(ColladaError, DanglingReferences) {
  struct Case {
    std::string from, to, element;
  };
  std::vector<Case> cases = {
      {"<instance_visual_scene url=\"#Scene\"/>", "<instance_visual_scene url=\"#Nope\"/>", "<instance_visual_scene>"},
      {"<instance_geometry url=\"#quad\">", "<instance_geometry url=\"#Nope\">", "<instance_geometry>"},
      {"<instance_light url=\"#lamp\"/>", "<instance_light url=\"#Nope\"/>", "<instance_light>"},
      {"<instance_camera url=\"#cam\"/>", "<instance_camera url=\"#Nope\"/>", "<instance_camera>"},
      {"<instance_node url=\"#shared\"/>", "<instance_node url=\"#Nope\"/>", "<instance_node>"},
      {"target=\"#red\"", "target=\"#Nope\"", "<instance_material>"},
      {"<instance_effect url=\"#glassy-fx\"/>", "<instance_effect url=\"#Nope\"/>", "<instance_effect>"},
      {"<input semantic=\"POSITION\" source=\"#quad-pos\"/>", "<input semantic=\"POSITION\" source=\"#Nope\"/>", "<input>"},
      {"<input semantic=\"VERTEX\" source=\"#quad-v\" offset=\"0\"/>", "<input semantic=\"VERTEX\" source=\"#Nope\" offset=\"0\"/>",
       "<input>"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.to);
    std::string doc = with(base_doc(), c.from, c.to);
    EXPECT_TRUE(scene_error(doc, {c.element, line_tag(doc, c.to), "'#Nope'"}));
  }
  // Only local references are supported; a missing attribute is named.
  std::string doc = with(base_doc(), "<instance_geometry url=\"#quad\">", "<instance_geometry url=\"other.dae#quad\">");
  EXPECT_TRUE(scene_error(doc, {"<instance_geometry>", line_tag(doc, "other.dae#quad"), "local"}));
  doc = with(base_doc(), "<instance_light url=\"#lamp\"/>", "<instance_light/>");
  EXPECT_TRUE(scene_error(doc, {"<instance_light>", line_tag(doc, "<instance_light/>"), "'url'"}));
  // A reference to an element of the wrong kind.
  doc = with(base_doc(), "<instance_geometry url=\"#quad\">", "<instance_geometry url=\"#red\">");
  EXPECT_TRUE(scene_error(doc, {"<instance_geometry>", line_tag(doc, "url=\"#red\""), "<geometry>"}));
  doc = with(base_doc(), "<instance_light url=\"#lamp\"/>", "<instance_light url=\"#cam\"/>");
  EXPECT_TRUE(scene_error(doc, {"<instance_light>", line_tag(doc, "<instance_light url=\"#cam\"/>"), "<light>"}));
  doc = with(base_doc(), "target=\"#red\"", "target=\"#quad\"");
  EXPECT_TRUE(scene_error(doc, {"<instance_material>", line_tag(doc, "target=\"#quad\""), "<material>"}));
}

TEST(ColladaError, InstanceNodeCycleStopsAtTheDepthLimit) {
  std::string libs = kFillerLight + "<library_nodes>\n<node id=\"loop\">\n<instance_node url=\"#loop\"/>\n</node>\n</library_nodes>\n";
  std::string doc = dae(kFillerNode + "<node>\n<instance_node url=\"#loop\"/>\n</node>\n", libs);
  EXPECT_TRUE(scene_error(doc, {"<node id='loop'>", line_tag(doc, "<node id=\"loop\">"), "deeper than 128"}));
}

TEST(ColladaError, InstanceNodeFanOutStopsAtTheNodeLimit) {
  // Each library node instances the next twice: 2^60 nodes if expanded.
  std::string libs = kFillerLight + "<library_nodes>\n";
  for (int i = 0; i < 60; ++i)
    libs += "<node id=\"n" + std::to_string(i) + "\">\n<instance_node url=\"#n" + std::to_string(i + 1) +
            "\"/>\n<instance_node url=\"#n" + std::to_string(i + 1) + "\"/>\n</node>\n";
  libs += "<node id=\"n60\">\n<instance_light url=\"#filler\"/>\n</node>\n</library_nodes>\n";
  LoadLimits limits;
  limits.max_nodes = 10000;
  auto t0 = std::chrono::steady_clock::now();
  EXPECT_TRUE(scene_error(dae("<node>\n<instance_node url=\"#n0\"/>\n</node>\n", libs), {"<node", "more than 10000 nodes"}, limits));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 2.0);
}

TEST(ColladaError, BadUpAxis) {
  std::string doc = with(base_doc(), "<up_axis>Y_UP</up_axis>", "<up_axis>W_UP</up_axis>");
  EXPECT_TRUE(scene_error(doc, {"<up_axis>", line_tag(doc, "W_UP"), "'W_UP'"}));
  doc = with(base_doc(), "<up_axis>Y_UP</up_axis>", "<up_axis>y_up</up_axis>");
  EXPECT_TRUE(scene_error(doc, {"<up_axis>", line_tag(doc, "y_up")}));
}

TEST(ColladaError, NonNumericNumbers) {
  struct Case {
    std::string from, to, element, token;
  };
  std::vector<Case> cases = {
      {">-1 0 -1  1 0 -1", ">-1 0 -1  1 zero -1", "<float_array", "'zero'"},
      {">-1 0 -1  1 0 -1", ">-1,0,-1  1 0 -1", "<float_array", "'-1,0,-1'"},
      {"<translate>0 1 4</translate>", "<translate>0 1 4x</translate>", "<translate>", "'4x'"},
      {"<color sid=\"diffuse\">0.8 0.1 0.1 1</color>", "<color sid=\"diffuse\">0.8 red 0.1 1</color>", "<color", "'red'"},
      {"<ior>1.5</ior>", "<ior>one</ior>", "<ior>", "'one'"},
      {"<radius>0.25</radius>", "<radius>0.25m</radius>", "<radius>", "'0.25m'"},
      {"<xfov>45</xfov>", "<xfov>wide</xfov>", "<xfov", "'wide'"},
      {"<vcount>3 3</vcount>", "<vcount>3 three</vcount>", "<vcount>", "'three'"},
      {"<p>0 2 1  0 3 2</p>", "<p>0 2 1  0 3 two</p>", "<p>", "'two'"},
      {"<p>0 2 1  0 3 2</p>", "<p>0 2 1  0 3 -2</p>", "<p>", "'-2'"},
      {"<p>0 2 1  0 3 2</p>", "<p>0 2 1  0 3 4294967296</p>", "<p>", "'4294967296'"},
      {"<p>0 2 1  0 3 2</p>", "<p>0 2 1  0 3 2.5</p>", "<p>", "'2.5'"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.to);
    std::string doc = with(base_doc(), c.from, c.to);
    EXPECT_TRUE(scene_error(doc, {c.element, line_tag(doc, c.to), c.token}));
  }
}

TEST(ColladaError, NonFiniteNumbers) {
  for (const char* bad : {"nan", "NaN", "inf", "-inf", "infinity", "1e999", "-1e400"}) {
    SCOPED_TRACE(bad);
    std::string doc = with(base_doc(), ">-1 0 -1  1 0 -1", std::string(">-1 0 -1  1 ") + bad + " -1");
    EXPECT_TRUE(scene_error(doc, {"<float_array", line_tag(doc, "<float_array id=\"quad-arr\"")}));
    doc = with(base_doc(), "<translate>0 1 4</translate>", std::string("<translate>0 ") + bad + " 4</translate>");
    EXPECT_TRUE(scene_error(doc, {"<translate>", line_tag(doc, std::string("<translate>0 ") + bad)}));
    doc = with(base_doc(), "<ior>1.5</ior>", std::string("<ior>") + bad + "</ior>");
    EXPECT_TRUE(scene_error(doc, {"<ior>", line_tag(doc, std::string("<ior>") + bad)}));
    doc = with(base_doc(), "<color>10 10 10</color>", std::string("<color>10 ") + bad + " 10</color>");
    EXPECT_TRUE(scene_error(doc, {"<color>", line_tag(doc, std::string("<color>10 ") + bad)}));
  }
  // Finite values whose transform overflows are caught too.
  std::string doc = with(base_doc(), "<instance_geometry url=\"#quad\">",
                         "<scale>1e300 1e300 1e300</scale>\n<instance_geometry url=\"#quad\">");
  EXPECT_TRUE(scene_error(doc, {"<node>", "not finite"}));
  doc = with(base_doc(), "<instance_geometry url=\"#quad\">", "<scale>1e39 1 1</scale>\n<instance_geometry url=\"#quad\">");
  EXPECT_TRUE(scene_error(doc, {"<float_array", "single precision"}));
}

TEST(ColladaError, FloatArrayCountDisagrees) {
  std::string doc = with(base_doc(), "count=\"12\">-1 0 -1", "count=\"11\">-1 0 -1");
  EXPECT_TRUE(scene_error(doc, {"<float_array id='quad-arr'>", line_tag(doc, "count=\"11\""), "11", "12"}));
  doc = with(base_doc(), "count=\"12\">-1 0 -1", "count=\"13\">-1 0 -1");
  EXPECT_TRUE(scene_error(doc, {"<float_array", line_tag(doc, "count=\"13\""), "13"}));
  // A huge count with little data fails at once, without reserving for the count.
  doc = with(base_doc(), "count=\"12\">-1 0 -1", "count=\"2000000000\">-1 0 -1");
  auto t0 = std::chrono::steady_clock::now();
  EXPECT_TRUE(scene_error(doc, {"<float_array", line_tag(doc, "2000000000"), "2000000000"}));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 0.5);
  doc = with(base_doc(), "count=\"12\">-1 0 -1", "count=\"-12\">-1 0 -1");
  EXPECT_TRUE(scene_error(doc, {"<float_array", line_tag(doc, "count=\"-12\"")}));
}

TEST(ColladaError, VertexIndexOutOfRange) {
  std::string doc = with(base_doc(), "<p>0 2 1  0 3 2</p>", "<p>0 2 1  0 7 2</p>");
  EXPECT_TRUE(scene_error(doc, {"<p>", line_tag(doc, "0 7 2"), "index 7", "4 vertices"}));
  doc = with(base_doc(), "<p>0 2 1  0 3 2</p>", "<p>0 2 1  0 3 4</p>");
  EXPECT_TRUE(scene_error(doc, {"<p>", line_tag(doc, "0 3 4"), "index 4"}));
}

TEST(ColladaError, VcountProblems) {
  std::string doc = with(base_doc(), "<vcount>3 3</vcount>", "<vcount>3 4</vcount>");
  EXPECT_TRUE(scene_error(doc, {"<p>", line_tag(doc, "<p>0 2 1"), "7", "6"}));
  doc = with(base_doc(), "<vcount>3 3</vcount>", "<vcount>3</vcount>");
  EXPECT_TRUE(scene_error(doc, {"<p>", line_tag(doc, "<p>0 2 1")}));
  doc = with(with(base_doc(), "<vcount>3 3</vcount>", "<vcount>2 4</vcount>"), "<p>0 2 1  0 3 2</p>", "<p>0 2  1 0 3 2</p>");
  EXPECT_TRUE(scene_error(doc, {"<vcount>", line_tag(doc, "<vcount>2 4"), "at least 3"}));
  doc = with(base_doc(), "<vcount>3 3</vcount>", "<vcount>3 0 3</vcount>");
  EXPECT_TRUE(scene_error(doc, {"<vcount>", line_tag(doc, "<vcount>3 0 3")}));
  doc = with(base_doc(), "<vcount>3 3</vcount>\n", "");
  EXPECT_TRUE(scene_error(doc, {"<polylist", "missing <vcount>"}));
  doc = with(base_doc(), "<p>0 2 1  0 3 2</p>\n", "");
  EXPECT_TRUE(scene_error(doc, {"<polylist", "missing <p>"}));
}

TEST(ColladaError, IndexCountNotAMultipleOfTheInputs) {
  std::string doc = with(base_doc(), "<input semantic=\"VERTEX\" source=\"#quad-v\" offset=\"0\"/>\n",
                         "<input semantic=\"VERTEX\" source=\"#quad-v\" offset=\"0\"/>\n"
                         "<input semantic=\"NORMAL\" source=\"#n\" offset=\"1\"/>\n");
  doc = with(doc, "<p>0 2 1  0 3 2</p>", "<p>0 0 2 0 1 0  0 0 3 0 2</p>");
  EXPECT_TRUE(scene_error(doc, {"<p>", line_tag(doc, "<p>0 0 2"), "multiple"}));
  // Triangles with a length that is not a multiple of 3.
  std::string libs = kFillerLight + "<library_geometries>\n" +
                     mesh_geometry("t", "0 0 0  1 0 0  0 1 0", triangles("0 1 2 0")) + "</library_geometries>\n";
  doc = dae(kFillerNode + geom_node("#t"), libs);
  EXPECT_TRUE(scene_error(doc, {"<p>", line_tag(doc, "<p>0 1 2 0"), "multiple of 3"}));
  // Polygons with fewer than 3 vertices.
  libs = kFillerLight + "<library_geometries>\n" +
         mesh_geometry("pg", "0 0 0  1 0 0  0 1 0",
                       "<polygons count=\"1\">\n<input semantic=\"VERTEX\" source=\"#V\" offset=\"0\"/>\n<p>0 1</p>\n</polygons>\n") +
         "</library_geometries>\n";
  doc = dae(kFillerNode + geom_node("#pg"), libs);
  EXPECT_TRUE(scene_error(doc, {"<p>", line_tag(doc, "<p>0 1</p>"), "at least 3"}));
}

TEST(ColladaError, MissingMeshParts) {
  std::string doc = with(base_doc(), "<vertices id=\"quad-v\">\n<input semantic=\"POSITION\" source=\"#quad-pos\"/>\n</vertices>\n", "");
  EXPECT_TRUE(scene_error(doc, {"<mesh>", "missing <vertices>"}));
  doc = with(base_doc(), "semantic=\"POSITION\"", "semantic=\"NORMAL\"");
  EXPECT_TRUE(scene_error(doc, {"<vertices id='quad-v'>", line_tag(doc, "<vertices"), "POSITION"}));
  doc = with(base_doc(), "semantic=\"VERTEX\"", "semantic=\"NORMAL\"");
  EXPECT_TRUE(scene_error(doc, {"<polylist", line_tag(doc, "<polylist"), "VERTEX"}));
  doc = with(base_doc(), "<input semantic=\"VERTEX\" source=\"#quad-v\"", "<input semantic=\"VERTEX\" source=\"#quad-pos\"");
  EXPECT_TRUE(scene_error(doc, {"<input>", line_tag(doc, "source=\"#quad-pos\" offset"), "<vertices>"}));
  doc = with(base_doc(), "<float_array id=\"quad-arr\"", "<int_array id=\"quad-arr\"");
  doc = with(doc, "</float_array>", "</int_array>");
  EXPECT_TRUE(scene_error(doc, {"<source id='quad-pos'>", "missing <float_array>"}));
  doc = with(base_doc(), "stride=\"3\"", "stride=\"2\"");
  EXPECT_TRUE(scene_error(doc, {"<accessor>", line_tag(doc, "stride=\"2\""), "stride"}));
  doc = with(base_doc(), "<input semantic=\"VERTEX\" source=\"#quad-v\" offset=\"0\"/>",
             "<input semantic=\"VERTEX\" source=\"#quad-v\" offset=\"-1\"/>");
  EXPECT_TRUE(scene_error(doc, {"<input>", line_tag(doc, "offset=\"-1\""), "offset"}));
  doc = with(base_doc(), "<radius>0.25</radius>", "");
  EXPECT_TRUE(scene_error(doc, {"<sphere>", "missing <radius>"}));
  doc = with(base_doc(), "<sphere>", "<ball>");
  doc = with(doc, "</sphere>", "</ball>");
  EXPECT_TRUE(scene_error(doc, {"<geometry id='ball'>", line_tag(doc, "<geometry id=\"ball\""), "sphere"}));
}

TEST(ColladaError, NegativeColour) {
  std::string doc = with(base_doc(), "0.8 0.1 0.1 1", "0.8 -0.1 0.1 1");
  EXPECT_TRUE(scene_error(doc, {"<color sid='diffuse'>", line_tag(doc, "-0.1"), "negative"}));
  doc = with(base_doc(), "<color>10 10 10</color>", "<color>10 10 -10</color>");
  EXPECT_TRUE(scene_error(doc, {"<color>", line_tag(doc, "10 10 -10"), "negative"}));
  doc = with(base_doc(), "<k>3.9 2.4 2.2</k>", "<k>-3.9 2.4 2.2</k>");
  EXPECT_TRUE(scene_error(doc, {"<k>", line_tag(doc, "-3.9"), "negative"}));
  // Wrong number of colour components.
  doc = with(base_doc(), "<color>10 10 10</color>", "<color>10 10</color>");
  EXPECT_TRUE(scene_error(doc, {"<color>", line_tag(doc, "<color>10 10<"), "3 numbers"}));
}

TEST(ColladaError, MissingCglMaterialChildren) {
  struct Case {
    std::string from, element, child;
  };
  std::vector<Case> cases = {
      {"<ior>1.5</ior>\n", "<glass>", "<ior>"},
      {"<transmittance>1 1 1</transmittance>\n", "<glass>", "<transmittance>"},
      {"<reflectance>1 1 1</reflectance>\n<transmittance>", "<glass>", "<reflectance>"},
      {"<alpha>0.2</alpha>\n", "<microfacet>", "<alpha>"},
      {"<eta>0.2 0.9 1.1</eta>\n", "<microfacet>", "<eta>"},
      {"<k>3.9 2.4 2.2</k>\n", "<microfacet>", "<k>"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.from);
    std::string from = c.from, to = "";
    if (c.child == "<reflectance>") to = "<transmittance>";
    std::string doc = with(base_doc(), from, to);
    EXPECT_TRUE(scene_error(doc, {c.element, line_tag(doc, c.element), "missing " + c.child}));
  }
  // Refraction, mirror and emission need theirs too.
  auto one = [](const std::string& body) {
    return dae(geom_node("#b", "", {{"m", "#m"}}),
               material("m", cgl(body)) + "<library_geometries>\n" + sphere_geometry("b", "1") + "</library_geometries>\n");
  };
  std::string doc = one("<refraction>\n<transmittance>1 1 1</transmittance>\n<roughness>0</roughness>\n</refraction>\n");
  EXPECT_TRUE(scene_error(doc, {"<refraction>", line_tag(doc, "<refraction>"), "missing <ior>"}));
  doc = one("<refraction>\n<roughness>0</roughness>\n<ior>1.5</ior>\n</refraction>\n");
  EXPECT_TRUE(scene_error(doc, {"<refraction>", line_tag(doc, "<refraction>"), "missing <transmittance>"}));
  doc = one("<mirror>\n</mirror>\n");
  EXPECT_TRUE(scene_error(doc, {"<mirror>", line_tag(doc, "<mirror>"), "missing <reflectance>"}));
  doc = one("<emission>\n<color>1 1 1</color>\n</emission>\n");
  EXPECT_TRUE(scene_error(doc, {"<emission>", line_tag(doc, "<emission>"), "missing <radiance>"}));
  // A material without an effect.
  doc = with(base_doc(), "<instance_effect url=\"#red-fx\"/>\n", "");
  EXPECT_TRUE(scene_error(doc, {"<material id='red'>", line_tag(doc, "<material id=\"red\""), "<instance_effect>"}));
}

TEST(ColladaError, NonPositiveRadiusIorAlpha) {
  for (const char* v : {"0", "-0.25", "-0"}) {
    SCOPED_TRACE(v);
    std::string doc = with(base_doc(), "<radius>0.25</radius>", std::string("<radius>") + v + "</radius>");
    EXPECT_TRUE(scene_error(doc, {"<radius>", line_tag(doc, std::string("<radius>") + v), "positive"}));
    doc = with(base_doc(), "<ior>1.5</ior>", std::string("<ior>") + v + "</ior>");
    EXPECT_TRUE(scene_error(doc, {"<ior>", line_tag(doc, std::string("<ior>") + v), "positive"}));
    doc = with(base_doc(), "<alpha>0.2</alpha>", std::string("<alpha>") + v + "</alpha>");
    EXPECT_TRUE(scene_error(doc, {"<alpha>", line_tag(doc, std::string("<alpha>") + v), "positive"}));
  }
  // A zero scale gives a zero world radius.
  std::string doc = with(base_doc(), "<translate>-0.5 0.25 0</translate>", "<scale>0 1 1</scale>");
  EXPECT_TRUE(scene_error(doc, {"<sphere>", "radius"}));
}

TEST(ColladaError, LightProblems) {
  std::string doc = with(base_doc(), "<area>\n<color>10 10 10</color>\n</area>", "<laser>\n<color>10 10 10</color>\n</laser>");
  EXPECT_TRUE(scene_error(doc, {"<laser>", line_tag(doc, "<laser>"), "unsupported light type 'laser'"}));
  doc = with(base_doc(), "<area>\n<color>10 10 10</color>\n</area>", "<area>\n</area>");
  EXPECT_TRUE(scene_error(doc, {"<area>", line_tag(doc, "<area>"), "missing <color>"}));
  // A CGL technique with no light inside is an empty technique, not a silent fallback.
  doc = with(base_doc(), "<area>\n<color>10 10 10</color>\n</area>\n", "");
  EXPECT_TRUE(scene_error(doc, {"<technique>", line_tag(doc, "<technique profile=\"CGL\">\n</technique>"), "empty light technique"}));
  std::string none = "<library_lights>\n<light id=\"x\">\n</light>\n</library_lights>\n";
  doc = dae(light_node("#x"), none);
  EXPECT_TRUE(scene_error(doc, {"<light id='x'>", line_tag(doc, "<light id=\"x\""), "no CGL or common technique"}));
  std::string spot = light_lib("s", "<spot>\n<color>1 1 1</color>\n<falloff_angle>0</falloff_angle>\n</spot>\n");
  doc = dae(light_node("#s"), spot);
  EXPECT_TRUE(scene_error(doc, {"<spot>", line_tag(doc, "<spot>"), "falloff_angle"}));
  spot = light_lib("s", "<spot>\n<color>1 1 1</color>\n<falloff_exponent>-1</falloff_exponent>\n</spot>\n");
  doc = dae(light_node("#s"), spot);
  EXPECT_TRUE(scene_error(doc, {"<spot>", line_tag(doc, "<spot>"), "falloff_exponent"}));
}

TEST(ColladaError, CameraProblems) {
  std::string doc = with(base_doc(), "<perspective>", "<orthographic>");
  doc = with(doc, "</perspective>", "</orthographic>");
  EXPECT_TRUE(scene_error(doc, {"<camera id='cam'>", line_tag(doc, "<camera id=\"cam\""), "perspective"}));
  doc = with(base_doc(), "<aspect_ratio>1.5</aspect_ratio>\n", "");
  EXPECT_TRUE(scene_error(doc, {"<perspective>", line_tag(doc, "<perspective>"), "<yfov> or <aspect_ratio>"}));
  doc = with(base_doc(), "<xfov>45</xfov>", "<xfov>180</xfov>");
  EXPECT_TRUE(scene_error(doc, {"<perspective>", line_tag(doc, "<perspective>"), "field of view"}));
  doc = with(base_doc(), "<zfar>100</zfar>", "<zfar>0.05</zfar>");
  EXPECT_TRUE(scene_error(doc, {"<perspective>", line_tag(doc, "<perspective>"), "znear"}));
  doc = with(base_doc(), "<xfov>45</xfov>", "<xfov>45 50</xfov>");
  EXPECT_TRUE(scene_error(doc, {"<xfov>", line_tag(doc, "<xfov>45 50"), "one number"}));
}

TEST(ColladaError, TransformProblems) {
  struct Case {
    std::string to, element, what;
  };
  std::vector<Case> cases = {
      {"<matrix>1 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1  0</matrix>", "<matrix>", "16 numbers"},
      {"<matrix>1 0 0 0  0 1 0 0  0 0 1</matrix>", "<matrix>", "16 numbers"},
      {"<translate>1 2</translate>", "<translate>", "3 numbers"},
      {"<scale>1 2 3 4</scale>", "<scale>", "3 numbers"},
      {"<rotate>0 0 1</rotate>", "<rotate>", "4 numbers"},
      {"<rotate>0 0 0 90</rotate>", "<rotate>", "zero length"},
      {"<lookat>1 1 1  1 1 1  0 1 0</lookat>", "<lookat>", "degenerate"},
      {"<lookat>0 0 0  0 1 0  0 1 0</lookat>", "<lookat>", "degenerate"},
      {"<lookat>0 0 0  0 0 -1</lookat>", "<lookat>", "9 numbers"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.to);
    std::string doc = with(base_doc(), "<translate>0 1 4</translate>", c.to);
    EXPECT_TRUE(scene_error(doc, {c.element, line_tag(doc, c.to), c.what}));
  }
}

TEST(ColladaError, EmptyScene) {
  std::string doc = dae("", "");
  EXPECT_TRUE(scene_error(doc, {"<visual_scene id='Scene'>", line_tag(doc, "<visual_scene"), "no geometry and no lights"}));
  // A camera alone, or a group node with nothing in it, is still empty.
  doc = dae(camera_node("#c") + "<node>\n<node/>\n</node>\n", camera_lib("c", "<xfov>40</xfov>\n<aspect_ratio>1</aspect_ratio>\n"));
  EXPECT_TRUE(scene_error(doc, {"<visual_scene", "no geometry and no lights"}));
  // A mesh whose every triangle is degenerate (repeated vertices) is dropped, leaving nothing.
  std::string libs = "<library_geometries>\n" + mesh_geometry("d", "0 0 0  1 0 0  0 1 0", triangles("0 0 1  2 2 2")) +
                     "</library_geometries>\n";
  ::testing::internal::CaptureStderr();
  EXPECT_TRUE(scene_error(dae(geom_node("#d"), libs), {"<visual_scene", "no geometry and no lights"}));
  ::testing::internal::GetCapturedStderr();
}

TEST(ColladaError, NodesNestedTooDeep) {
  // 1000 levels, far past the default limit of 128: an error naming the node, no stack exhaustion.
  std::string nodes;
  for (int i = 0; i < 1000; ++i) nodes += "<node id=\"n" + std::to_string(i) + "\">\n";
  nodes += "<instance_light url=\"#filler\"/>\n";
  for (int i = 0; i < 1000; ++i) nodes += "</node>\n";
  std::string doc = dae(nodes, kFillerLight);
  EXPECT_TRUE(scene_error(doc, {"<node id='n129'>", line_tag(doc, "<node id=\"n129\">"), "deeper than 128"}));
  // A smaller configured limit is honoured.
  LoadLimits limits;
  limits.max_node_depth = 5;
  EXPECT_TRUE(scene_error(doc, {"<node id='n6'>", line_tag(doc, "<node id=\"n6\">"), "deeper than 5"}, limits));
  // Far deeper XML (pugixml parses without recursion) is still a clean error.
  std::string deep = "<?xml version=\"1.0\"?>\n<COLLADA>\n<library_visual_scenes>\n<visual_scene id=\"Scene\">\n";
  for (int i = 0; i < 100000; ++i) deep += "<node>";
  for (int i = 0; i < 100000; ++i) deep += "</node>";
  deep += "\n</visual_scene>\n</library_visual_scenes>\n<scene>\n<instance_visual_scene url=\"#Scene\"/>\n</scene>\n</COLLADA>\n";
  EXPECT_TRUE(scene_error(deep, {"<node>", ":5:", "deeper than 128"}));
}

TEST(ColladaError, TooManyTriangles) {
  // The base document has 2 mesh triangles; the quad instanced three times makes 6.
  std::string doc = with(base_doc(), "<node>\n<instance_node url=\"#shared\"/>\n</node>\n",
                         "<node>\n<instance_node url=\"#shared\"/>\n</node>\n" + geom_node("#quad") + geom_node("#quad"));
  LoadLimits limits;
  limits.max_triangles = 6;
  EXPECT_EQ(parse_collada(doc, "ok.dae", limits).triangle_count(), 6u);
  limits.max_triangles = 5;
  EXPECT_TRUE(scene_error(doc, {"<p>", line_tag(doc, "<p>0 2 1"), "more than 5 triangles"}, limits));
  // One big n-gon counts its fan triangles.
  std::string libs = kFillerLight + "<library_geometries>\n" +
                     mesh_geometry("ng", "0 0 0  1 0 0  2 1 0  1 2 0  0 1 0", polylist("5", "0 1 2 3 4")) +
                     "</library_geometries>\n";
  limits.max_triangles = 2;
  doc = dae(kFillerNode + geom_node("#ng"), libs);
  EXPECT_TRUE(scene_error(doc, {"<p>", line_tag(doc, "<p>0 1 2 3 4"), "more than 2 triangles"}, limits));
}

TEST(ColladaError, FileLimitsAndMissingFile) {
  std::string path = test::temp_dir() + "/collada_size_limit.dae";
  std::string doc = base_doc();
  {
    std::ofstream out(path, std::ios::binary);
    out << doc;
  }
  LoadLimits limits;
  limits.max_file_bytes = doc.size();
  SceneDesc s = load_collada(path, limits);
  EXPECT_EQ(s.source, path);
  EXPECT_EQ(s.spheres.size(), 3u);
  limits.max_file_bytes = doc.size() - 1;
  try {
    load_collada(path, limits);
    ADD_FAILURE() << "a file over max_file_bytes loaded";
  } catch (const SceneError& e) {
    std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
    EXPECT_NE(msg.find(std::to_string(doc.size())), std::string::npos) << msg;
  }
  // Errors from a file name the file's path.
  {
    std::ofstream out(path, std::ios::binary);
    out << with(doc, "<up_axis>Y_UP</up_axis>", "<up_axis>Q_UP</up_axis>");
  }
  try {
    load_collada(path);
    ADD_FAILURE() << "a bad file loaded";
  } catch (const SceneError& e) {
    std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path + line_tag(doc, "<up_axis>") + " <up_axis>", 0), 0u) << msg;
  }
  std::remove(path.c_str());
  std::string missing = test::temp_dir() + "/no/such/scene.dae";
  try {
    load_collada(missing);
    ADD_FAILURE() << "a missing file loaded";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  // A directory is not a scene file.
  EXPECT_THROW(load_collada(test::temp_dir()), SceneError);
}

TEST(ColladaError, TruncationsAndMutationsNeverCrash) {
  // Every prefix of a valid document, and random byte mutations of it, must either load or throw
  // SceneError: no other exception, no crash, no hang.
  const std::string doc = base_doc();
  size_t loaded = 0, failed = 0;
  auto attempt = [&](const std::string& text) {
    try {
      parse_collada(text, "fuzz.dae");
      ++loaded;
    } catch (const SceneError&) {
      ++failed;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a SceneError: " << e.what() << "\n--- input ---\n" << text;
    }
  };
  ::testing::internal::CaptureStderr();
  for (size_t n = 0; n < doc.size(); n += 3) attempt(doc.substr(0, n));
  std::mt19937 rng(184);
  const std::string alphabet = "<>/=\"# \n0123456789.-+eEnaxyz_";
  for (int i = 0; i < 3000; ++i) {
    std::string t = doc;
    int edits = 1 + int(rng() % 3);
    for (int e = 0; e < edits; ++e) {
      size_t at = rng() % t.size();
      switch (rng() % 3) {
        case 0: t[at] = alphabet[rng() % alphabet.size()]; break;
        case 1: t.erase(at, 1 + rng() % 8); break;
        default: t.insert(at, 1, alphabet[rng() % alphabet.size()]); break;
      }
      if (t.empty()) t = "x";
    }
    attempt(t);
  }
  ::testing::internal::GetCapturedStderr();
  EXPECT_GT(loaded, 0u);
  EXPECT_GT(failed, 0u);
}

// ============================================================================================
// The course scenes in ../shared/scenes-cs184

const MeshDesc* find_mesh(const SceneDesc& s, const std::string& name) {
  for (const MeshDesc& m : s.meshes)
    if (m.name == name) return &m;
  return nullptr;
}
const Material& mesh_material(const SceneDesc& s, const std::string& name) {
  const MeshDesc* m = find_mesh(s, name);
  static const Material none;
  EXPECT_NE(m, nullptr) << "no mesh " << name;
  if (!m || m->tri_material.empty()) return none;
  return s.materials.at(m->tri_material[0]);
}

// The Cornell box that every CB scene shares: 5 walls x 2 triangles, x,z in [-1,1], y in [0,1.5].
void expect_cornell_box(const SceneDesc& s) {
  for (const char* wall : {"ceiling-mesh", "floor-mesh", "leftWall-mesh", "rightWall-mesh", "backWall-mesh"}) {
    const MeshDesc* m = find_mesh(s, wall);
    ASSERT_NE(m, nullptr) << wall;
    EXPECT_EQ(m->indices.size(), 6u) << wall;
    EXPECT_TRUE(m->normals.empty()) << wall << " is flat";
    for (const Vec3& p : m->positions) {
      EXPECT_LE(std::fabs(p.x), 1.0f + 1e-4f) << wall;
      EXPECT_LE(std::fabs(p.z), 1.0f + 5e-3f) << wall;
      EXPECT_GE(p.y, -1e-4f) << wall;
      EXPECT_LE(p.y, 1.5f + 1e-4f) << wall;
    }
  }
  EXPECT_TRUE(vec_near(mesh_material(s, "floor-mesh").albedo, {0.6f, 0.6f, 0.6f}));
  EXPECT_TRUE(vec_near(mesh_material(s, "ceiling-mesh").albedo, {0.6f, 0.6f, 0.6f}));
  EXPECT_TRUE(vec_near(mesh_material(s, "backWall-mesh").albedo, {0.6f, 0.6f, 0.6f}));
  EXPECT_TRUE(vec_near(mesh_material(s, "leftWall-mesh").albedo, {0.6f, 0.2f, 0.2f}));
  EXPECT_TRUE(vec_near(mesh_material(s, "rightWall-mesh").albedo, {0.2f, 0.2f, 0.6f}));
}

// The 0.6 x 0.8 area light at y = 1.49 facing down, radiance 10.
void expect_cornell_area_light(const SceneDesc& s) {
  ASSERT_EQ(s.lights.size(), 1u);
  const LightDesc& l = s.lights[0];
  EXPECT_EQ(l.type, LightType::area);
  EXPECT_TRUE(vec_near(l.color, {10, 10, 10}));
  EXPECT_NEAR(l.position.y, 1.49f, 1e-5f);
  EXPECT_NEAR(l.position.x, 0.0f, 1e-5f);
  EXPECT_NEAR(l.position.z, 0.0f, 5e-3f);
  EXPECT_TRUE(vec_near(l.direction, {0, -1, 0}, 1e-5f));
  EXPECT_NEAR(std::fabs(l.dim_x.x), 0.6f, 1e-5f);
  EXPECT_NEAR(std::fabs(l.dim_y.z), 0.8f, 1e-5f);
  EXPECT_NEAR(length(l.dim_x) * length(l.dim_y), 0.48f, 1e-5f);
  EXPECT_NEAR(dot(l.dim_x, l.direction), 0.0f, 1e-5f);
  EXPECT_NEAR(dot(l.dim_y, l.direction), 0.0f, 1e-5f);
}

void expect_course_camera(const SceneDesc& s, float aspect, float z) {
  ASSERT_TRUE(s.camera.present);
  EXPECT_FLOAT_EQ(s.camera.xfov_deg, 49.13434f);
  EXPECT_NEAR(s.camera.aspect, aspect, 1e-5f);
  EXPECT_FLOAT_EQ(s.camera.znear, 0.1f);
  EXPECT_FLOAT_EQ(s.camera.zfar, 100);
  EXPECT_TRUE(vec_near(s.camera.world.point({0, 0, 0}), {0, 0, z}));
}

TEST(ColladaCourseScene, CBempty) {
  PT_REQUIRE_SHARED_SCENE(path, "CBempty.dae");
  SceneDesc s = load_collada(path);
  EXPECT_EQ(s.source, path);
  EXPECT_EQ(s.triangle_count(), 10u);
  EXPECT_EQ(s.meshes.size(), 5u);
  EXPECT_TRUE(s.spheres.empty());
  expect_cornell_box(s);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].type, LightType::point);
  EXPECT_TRUE(vec_near(s.lights[0].color, {5, 5, 5}));
  EXPECT_TRUE(vec_near(s.lights[0].position, {0, 1.49f, 0.004315853f}, 1e-5f));
  expect_course_camera(s, 1.777778f, 3);
}

TEST(ColladaCourseScene, CBspheres) {
  PT_REQUIRE_SHARED_SCENE(path, "CBspheres.dae");
  SceneDesc s = load_collada(path);
  EXPECT_EQ(s.triangle_count(), 10u);
  expect_cornell_box(s);
  expect_cornell_area_light(s);
  expect_course_camera(s, 1.333333f, 3);
  ASSERT_EQ(s.spheres.size(), 2u);
  // Sphere1 (glass) at (-0.4, 0.3, 0.3) Z-up -> (0.4, 0.3, 0.3); Sphere2 (mirror) -> (-0.4, 0.3, -0.3).
  EXPECT_TRUE(vec_near(s.spheres[0].center, {0.4f, 0.3f, 0.3f}));
  EXPECT_TRUE(vec_near(s.spheres[1].center, {-0.4f, 0.3f, -0.3f}));
  for (const SphereDesc& sp : s.spheres) EXPECT_NEAR(sp.radius, 0.3f, 1e-6f);
  const Material& glass = s.materials.at(s.spheres[0].material);
  EXPECT_EQ(glass.type, MaterialType::glass);
  EXPECT_FLOAT_EQ(glass.ior, 1.45f);
  EXPECT_TRUE(vec_near(glass.albedo, {1, 1, 1}));
  EXPECT_TRUE(vec_near(glass.transmittance, {1, 1, 1}));
  const Material& mirror = s.materials.at(s.spheres[1].material);
  EXPECT_EQ(mirror.type, MaterialType::mirror);
  EXPECT_TRUE(vec_near(mirror.albedo, {1, 1, 1}));
  // The light mesh's node is commented out: no emissive geometry.
  EXPECT_EQ(find_mesh(s, "light-mesh"), nullptr);
}

TEST(ColladaCourseScene, CBspheresLambertian) {
  PT_REQUIRE_SHARED_SCENE(path, "CBspheres_lambertian.dae");
  SceneDesc s = load_collada(path);
  EXPECT_EQ(s.triangle_count(), 10u);
  expect_cornell_box(s);
  expect_cornell_area_light(s);
  ASSERT_EQ(s.spheres.size(), 2u);
  for (const SphereDesc& sp : s.spheres) {
    EXPECT_NEAR(sp.radius, 0.3f, 1e-6f);
    const Material& m = s.materials.at(sp.material);
    EXPECT_EQ(m.type, MaterialType::diffuse);
    EXPECT_TRUE(vec_near(m.albedo, {0.8f, 0.8f, 0.8f}));
  }
}

TEST(ColladaCourseScene, CBspheresMicrofacetAlAg) {
  PT_REQUIRE_SHARED_SCENE(path, "CBspheres_microfacet_al_ag.dae");
  SceneDesc s = load_collada(path);
  EXPECT_EQ(s.triangle_count(), 10u);
  expect_cornell_box(s);
  expect_cornell_area_light(s);
  ASSERT_EQ(s.spheres.size(), 2u);
  const Material* silver = nullptr;
  const Material* aluminium = nullptr;
  for (const SphereDesc& sp : s.spheres) {
    EXPECT_NEAR(sp.radius, 0.3f, 1e-6f);
    const Material& m = s.materials.at(sp.material);
    EXPECT_EQ(m.type, MaterialType::microfacet);
    if (m.alpha == 0.25f) silver = &m;
    if (m.alpha == 0.025f) aluminium = &m;
  }
  ASSERT_NE(silver, nullptr) << "no sphere with alpha 0.25";
  ASSERT_NE(aluminium, nullptr) << "no sphere with alpha 0.025";
  EXPECT_TRUE(vec_near(silver->eta, {0.059193f, 0.059881f, 0.047366f}));
  EXPECT_TRUE(vec_near(silver->k, {4.1283f, 3.5892f, 2.8132f}));
  EXPECT_TRUE(vec_near(aluminium->eta, {1.3352f, 1.0109f, 0.68955f}));
  EXPECT_TRUE(vec_near(aluminium->k, {7.3398f, 6.6157f, 5.6471f}));
}

TEST(ColladaCourseScene, CBbunny) {
  PT_REQUIRE_SHARED_SCENE(path, "CBbunny.dae");
  SceneDesc s = load_collada(path);
  EXPECT_EQ(s.triangle_count(), 10u + 28576u);
  expect_cornell_box(s);
  expect_cornell_area_light(s);
  expect_course_camera(s, 1.777778f, -3);  // the camera is on the -z side
  const MeshDesc* bunny = find_mesh(s, "Mesh-mesh");
  ASSERT_NE(bunny, nullptr);
  EXPECT_EQ(bunny->indices.size(), 3u * 28576u);
  const Material& m = mesh_material(s, "Mesh-mesh");
  EXPECT_EQ(m.type, MaterialType::diffuse);
  EXPECT_TRUE(vec_near(m.albedo, {0.5f, 0.5f, 0.5f}));
  // Curved: smooth unit normals, one per vertex.
  ASSERT_EQ(bunny->normals.size(), bunny->positions.size());
  for (size_t i = 0; i < bunny->normals.size(); i += 97) EXPECT_NEAR(length(bunny->normals[i]), 1.0f, 1e-4f) << i;
  // The bunny sits inside the box.
  Bounds3 b;
  for (const Vec3& p : bunny->positions) b.expand(p);
  EXPECT_GT(b.lo.y, -1e-3f);
  EXPECT_LT(b.hi.y, 1.5f);
  EXPECT_GT(b.lo.x, -1.0f);
  EXPECT_LT(b.hi.x, 1.0f);
}

TEST(ColladaCourseScene, CBdragon) {
  PT_REQUIRE_SHARED_SCENE(path, "CBdragon.dae");
  SceneDesc s = load_collada(path);
  const MeshDesc* dragon = find_mesh(s, "dragon-mesh");
  const MeshDesc* quad = find_mesh(s, "light-mesh");
  ASSERT_NE(dragon, nullptr);
  ASSERT_NE(quad, nullptr);
  EXPECT_EQ(dragon->indices.size(), 3u * 100000u);
  EXPECT_EQ(dragon->positions.size(), 50000u);
  EXPECT_EQ(quad->indices.size(), 6u);
  EXPECT_EQ(s.triangle_count(), 100000u + 10u + 2u);
  expect_cornell_box(s);
  expect_cornell_area_light(s);
  // Mirror dragon (its common diffuse 0.28 is ignored).
  const Material& dm = mesh_material(s, "dragon-mesh");
  EXPECT_EQ(dm.type, MaterialType::mirror);
  EXPECT_TRUE(vec_near(dm.albedo, {1.0f, 0.8f, 0.4f}));
  // The active emissive quad: 0.8 x 0.6 at y = 1.49, coplanar with the area light.
  const Material& qm = mesh_material(s, "light-mesh");
  EXPECT_EQ(qm.type, MaterialType::emission);
  EXPECT_TRUE(vec_near(qm.radiance, {10, 10, 10}));
  EXPECT_NEAR(mesh_area(*quad), 0.48, 1e-5);
  for (const Vec3& p : quad->positions) EXPECT_NEAR(p.y, 1.49f, 1e-5f);
  // Its winding faces down into the box, as its file normals say.
  for (size_t t = 0; t < quad->indices.size(); t += 3) {
    const Vec3* v = quad->positions.data();
    EXPECT_LT(cross(v[quad->indices[t + 1]] - v[quad->indices[t]], v[quad->indices[t + 2]] - v[quad->indices[t]]).y, 0);
  }
  // Curved dragon: unit vertex normals.
  ASSERT_EQ(dragon->normals.size(), dragon->positions.size());
  for (size_t i = 0; i < dragon->normals.size(); i += 101) EXPECT_NEAR(length(dragon->normals[i]), 1.0f, 1e-4f) << i;
}

}  // namespace
}  // namespace pt
