// Hostile scene files: every input the fuzzer (tests/fuzz_collada.cpp) ever crashed on, kept in
// tests/fuzz-regressions/, loads or fails with a SceneError; and the classic attacks (entity
// expansion, absurd counts, deep nesting, huge files, millions of tiny elements, instancing
// amplification, warning floods) fail fast with an error naming the limit.
#include <dirent.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "collada.h"
#include "scene_file.h"
#include "session.h"
#include "test_util.h"

namespace pt {
namespace {

// A minimal valid document around `libs` (library sections) and `nodes` (visual scene children).
std::string dae(const std::string& nodes, const std::string& libs = "") {
  return "<?xml version=\"1.0\"?>\n<COLLADA>\n" + libs +
         "<library_visual_scenes>\n<visual_scene id=\"Scene\">\n" + nodes +
         "</visual_scene>\n</library_visual_scenes>\n"
         "<scene>\n<instance_visual_scene url=\"#Scene\"/>\n</scene>\n</COLLADA>\n";
}

const std::string kLight =
    "<library_lights>\n<light id=\"lamp\">\n<technique_common>\n<point>\n<color>1 1 1</color>\n</point>\n"
    "</technique_common>\n</light>\n</library_lights>\n";
const std::string kLightNode = "<node>\n<instance_light url=\"#lamp\"/>\n</node>\n";

// A mesh <geometry id=id> over `positions` with a triangle list `p`.
std::string mesh(const std::string& id, const std::string& positions, size_t count, const std::string& p) {
  return "<geometry id=\"" + id + "\">\n<mesh>\n<source id=\"" + id + "-pos\">\n<float_array id=\"" + id +
         "-arr\" count=\"" + std::to_string(count) + "\">" + positions + "</float_array>\n</source>\n" +
         "<vertices id=\"" + id + "-v\">\n<input semantic=\"POSITION\" source=\"#" + id + "-pos\"/>\n</vertices>\n" +
         "<triangles>\n<input semantic=\"VERTEX\" source=\"#" + id + "-v\" offset=\"0\"/>\n<p>" + p +
         "</p>\n</triangles>\n</mesh>\n</geometry>\n";
}

// "Fails fast" is measured in CPU seconds of this process, which the machine's load does not
// stretch (ctest -j and the sanitizers run many of these at once); the bounds are 10-1000x what a
// release build takes, and an unbounded expansion never finishes at all.
double cpu_seconds_since(double t0) { return test::cpu_seconds() - t0; }

// Parses `text`; returns the SceneError message, or "" when it loaded. Any other exception fails.
std::string load_error(const std::string& text, const LoadLimits& limits = {}) {
  try {
    parse_collada(text, "hostile.dae", limits);
    return "";
  } catch (const SceneError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a SceneError: " << e.what();
    return e.what();
  }
}

#define EXPECT_HAS(msg, part) EXPECT_NE((msg).find(part), std::string::npos) << (msg)

// ---- the fuzzer's regressions ----

// What the fuzz target does with one input: the same limits, the same calls.
void run_like_the_fuzzer(const std::string& text, const std::string& name) {
  LoadLimits limits;
  limits.max_file_bytes = size_t(4) << 20;
  limits.max_triangles = 200'000;
  limits.max_nodes = 20'000;
  limits.max_markup = 200'000;
  limits.max_values = 2'000'000;
  SceneDesc desc;
  try {
    desc = parse_scene(text, name, limits);  // COLLADA or glTF, as the fuzzers read them
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(name, 0), 0u) << "the message does not name the file: " << e.what();
    return;
  }
  for (bool file_camera : {false, true}) {
    RenderParams params;
    params.width = 8;
    params.height = 6;
    params.spp = 1;
    params.file_camera = file_camera;
    try {
      auto scene = make_render_scene(desc, params);
      autofocus_distance(*scene, 0.5f, 0.5f);
      // Unlike the fuzzer, render too: a bad ray once aborted the process inside Embree.
      RenderSession session(*scene, params);
      session.render_pass(1);
    } catch (const std::runtime_error&) {
    }
  }
}

TEST(FuzzRegressions, EveryCrashInputNowLoadsAndRendersOrFailsCleanly) {
  std::vector<std::string> files;
  if (DIR* d = opendir(PT_FUZZ_REGRESSIONS)) {
    while (dirent* e = readdir(d))
      if (e->d_name[0] != '.') files.push_back(e->d_name);
    closedir(d);
  }
  ASSERT_FALSE(files.empty()) << "no inputs in " << PT_FUZZ_REGRESSIONS;
  ::testing::internal::CaptureStderr();  // the loader's warnings
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    std::ifstream in(std::string(PT_FUZZ_REGRESSIONS) + "/" + f, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    const double t0 = test::cpu_seconds();
    run_like_the_fuzzer(text.str(), f);
    EXPECT_LT(cpu_seconds_since(t0), 10.0);
  }
  ::testing::internal::GetCapturedStderr();
}

// ---- classic attacks ----

TEST(HostileScene, BillionLaughsIsNotExpanded) {
  // pugixml keeps a DOCTYPE's entities unexpanded: "&lol9;" stays eight characters, not 10^9 "lol"s.
  std::string doctype = "<!DOCTYPE COLLADA [\n<!ENTITY lol \"lol\">\n";
  for (int i = 1; i <= 9; ++i) {
    doctype += "<!ENTITY lol" + std::to_string(i) + " \"";
    for (int k = 0; k < 10; ++k) doctype += "&lol" + (i == 1 ? std::string() : std::to_string(i - 1)) + ";";
    doctype += "\">\n";
  }
  doctype += "]>\n";
  std::string doc = dae(kLightNode, kLight);
  doc.insert(doc.find("<COLLADA>"), doctype);
  const double t0 = test::cpu_seconds();
  EXPECT_EQ(load_error(doc), "");  // the DOCTYPE is skipped; the rest is a valid scene
  std::string in_numbers = doc;
  in_numbers.replace(in_numbers.find("1 1 1"), 5, "&lol9; 1 1");
  std::string msg = load_error(in_numbers);
  EXPECT_HAS(msg, "'&lol9;' is not a number");
  EXPECT_LT(msg.size(), 300u);
  std::string in_id = doc;
  in_id.replace(in_id.find("id=\"lamp\""), 9, "id=\"&lol9;\"");
  EXPECT_HAS(load_error(in_id), "reference '#lamp' names no element");
  EXPECT_LT(cpu_seconds_since(t0), 5.0);
}

TEST(HostileScene, AbsurdCountsAllocateNothing) {
  std::string doc = dae("<node>\n<instance_geometry url=\"#m\"/>\n</node>\n",
                        "<library_geometries>\n" + mesh("m", "0 0 0  1 0 0  0 1 0", 2000000000, "0 1 2") +
                            "</library_geometries>\n");
  EXPECT_HAS(load_error(doc), "count says 2000000000 but 9 numbers are present");
  std::string stride = dae("<node>\n<instance_geometry url=\"#m\"/>\n</node>\n",
                           "<library_geometries>\n" + mesh("m", "0 0 0  1 0 0  0 1 0", 9, "0 1 2") +
                               "</library_geometries>\n");
  stride.replace(stride.find("</source>"), 9,
                 "<technique_common><accessor stride=\"4294967295\"/></technique_common></source>");
  EXPECT_HAS(load_error(stride), "vertex index 0 out of range (0 vertices)");
  std::string vcount = dae("<node>\n<instance_geometry url=\"#m\"/>\n</node>\n",
                           "<library_geometries>\n" + mesh("m", "0 0 0  1 0 0  0 1 0", 9, "0 1 2") +
                               "</library_geometries>\n");
  vcount.replace(vcount.find("<triangles>"), 11, "<polylist><vcount>4294967295 4294967295</vcount>");
  vcount.replace(vcount.find("</triangles>"), 12, "</polylist>");
  EXPECT_HAS(load_error(vcount), "<vcount> sums to 8589934590 vertices but <p> holds 3");
}

TEST(HostileScene, DeepNestingFailsAtTheDepthLimitWithoutRecursing) {
  const int depth = 200000;
  std::string nested;
  nested.reserve(size_t(depth) * 14);
  for (int i = 0; i < depth; ++i) nested += "<node>";
  nested += kLightNode;
  for (int i = 0; i < depth; ++i) nested += "</node>";
  const double t0 = test::cpu_seconds();
  EXPECT_HAS(load_error(dae(nested, kLight)), "nodes nested deeper than 128");
  // Elements the reader does not walk may nest as deep as they like: pugixml parses iteratively.
  std::string extra;
  for (int i = 0; i < depth; ++i) extra += "<extra>";
  for (int i = 0; i < depth; ++i) extra += "</extra>";
  EXPECT_EQ(load_error(dae(kLightNode, kLight + "<library_x>" + extra + "</library_x>\n")), "");
  EXPECT_LT(cpu_seconds_since(t0), 10.0);
}

TEST(HostileScene, HugeFilesAreRefusedBeforeReading) {
  LoadLimits limits;
  limits.max_file_bytes = 1000;
  std::string doc = dae(kLightNode, kLight) + std::string(2000, ' ');
  EXPECT_HAS(load_error(doc, limits), "bytes, over the limit of 1000");
  std::string path = test::temp_dir() + "/hostile_huge.dae";
  {
    std::ofstream out(path, std::ios::binary);
    out << doc;
  }
  try {
    load_collada(path, limits);
    ADD_FAILURE() << "a file over the limit loaded";
  } catch (const SceneError& e) {
    EXPECT_HAS(std::string(e.what()), "over the limit of 1000");
  }
  std::remove(path.c_str());
}

TEST(HostileScene, MillionsOfTinyElementsFailBeforeTheDom) {
  std::string flood;
  const size_t n = 5'000'000;
  flood.reserve(n * 4);
  for (size_t i = 0; i < n; ++i) flood += "<a/>";
  std::string attrs = "<library_x ";
  for (size_t i = 0; i < n; ++i) attrs += "a" + std::to_string(i) + "=\"\" ";
  const double t0 = test::cpu_seconds();
  EXPECT_HAS(load_error(dae(kLightNode, kLight + "<library_x>" + flood + "</library_x>\n")),
             "more than 4000000 XML elements and attributes");
  EXPECT_HAS(load_error(dae(kLightNode, kLight + attrs + "/>\n")), "more than 4000000 XML elements and attributes");
  EXPECT_LT(cpu_seconds_since(t0), 5.0);
}

TEST(HostileScene, InstancingCannotMultiplyTheWorkWithoutBound) {
  // A mesh of 30000 degenerate triangles (no triangle survives, so the triangle limit never
  // trips) reached through 2^20 instancing paths.
  std::string positions = "0 0 0  1 0 0  0 1 0", p;
  for (int i = 0; i < 30000; ++i) p += "0 0 1 ";
  std::string libs = kLight + "<library_geometries>\n" + mesh("m", positions, 9, p) + "</library_geometries>\n" +
                     "<library_nodes>\n";
  for (int i = 0; i < 20; ++i)
    libs += "<node id=\"n" + std::to_string(i) + "\">\n<instance_node url=\"#n" + std::to_string(i + 1) +
            "\"/>\n<instance_node url=\"#n" + std::to_string(i + 1) + "\"/>\n</node>\n";
  libs += "<node id=\"n20\">\n<instance_geometry url=\"#m\"/>\n</node>\n</library_nodes>\n";
  LoadLimits limits;
  limits.max_values = 5'000'000;
  const double t0 = test::cpu_seconds();
  ::testing::internal::CaptureStderr();  // "mesh has no triangles" warnings
  std::string msg = load_error(dae(kLightNode + "<node>\n<instance_node url=\"#n0\"/>\n</node>\n", libs), limits);
  std::string warnings = ::testing::internal::GetCapturedStderr();
  EXPECT_HAS(msg, "more than 5000000 numbers read (instancing included)");
  EXPECT_LT(cpu_seconds_since(t0), 5.0);
  EXPECT_LE(std::count(warnings.begin(), warnings.end(), '\n'), 20) << warnings.substr(0, 2000);
}

TEST(HostileScene, WarningFloodIsCapped) {
  std::string skews;
  for (int i = 0; i < 100000; ++i) skews += "<skew>0 1 0 0 1 0 0</skew>";
  ::testing::internal::CaptureStderr();
  const double t0 = test::cpu_seconds();
  EXPECT_EQ(load_error(dae("<node>\n" + skews + "<instance_light url=\"#lamp\"/>\n</node>\n", kLight)), "");
  std::string warnings = ::testing::internal::GetCapturedStderr();
  EXPECT_LT(cpu_seconds_since(t0), 5.0);
  EXPECT_EQ(std::count(warnings.begin(), warnings.end(), '\n'), 21) << warnings.substr(0, 2000);
  EXPECT_HAS(warnings, "99981 more warnings not shown");  // the skews and the missing camera
}

TEST(HostileScene, HugeIdsAndUrlsAreClippedInMessages) {
  std::string big(1 << 20, 'x');
  std::string msg = load_error(dae("<node>\n<instance_light url=\"#" + big + "\"/>\n</node>\n", kLight));
  EXPECT_HAS(msg, "names no element");
  EXPECT_LT(msg.size(), 400u);
  msg = load_error(dae("<node id=\"" + big + "\">\n<instance_light url=\"" + big + "\"/>\n</node>\n", kLight));
  EXPECT_HAS(msg, "only local references");
  EXPECT_LT(msg.size(), 400u);
}

}  // namespace
}  // namespace pt
