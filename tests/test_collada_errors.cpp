// The COLLADA reader on malformed or unsupported input: each a SceneError naming file, element and
// line; never a crash or a hang.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
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

// The largest single allocation made while g_watch is set: "fails without reserving for the
// count" is then a number of bytes, which no machine's speed or load changes.
static std::atomic<bool> g_watch{false};
static std::atomic<size_t> g_largest{0};
void* operator new(size_t n) {
  if (g_watch.load(std::memory_order_relaxed) && n > g_largest.load(std::memory_order_relaxed)) g_largest = n;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }

namespace pt {
namespace {

using namespace collada_docs;

// The largest allocation `f` makes.
template <class F>
size_t largest_allocation(F f) {
  g_largest = 0;
  g_watch = true;
  f();
  g_watch = false;
  return g_largest;
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
  const double t0 = test::cpu_seconds();  // CPU time: the machine's load does not stretch it
  EXPECT_TRUE(scene_error(dae("<node>\n<instance_node url=\"#n0\"/>\n</node>\n", libs), {"<node", "more than 10000 nodes"}, limits));
  EXPECT_LT(test::cpu_seconds() - t0, 2.0);  // stopping at the limit takes milliseconds
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
  // A huge count with little data fails at once, without reserving for the count (8-16 GB): no
  // allocation is larger than a few times the document.
  doc = with(base_doc(), "count=\"12\">-1 0 -1", "count=\"2000000000\">-1 0 -1");
  size_t largest = largest_allocation(
      [&] { EXPECT_TRUE(scene_error(doc, {"<float_array", line_tag(doc, "2000000000"), "2000000000"})); });
  EXPECT_LT(largest, 64 * doc.size() + 65536) << "bytes in one allocation";
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

}  // namespace
}  // namespace pt
