// The glTF reader on broken and hostile files: each a SceneError naming the file and the JSON path
// of what is wrong, never a crash, a hang or a read outside the scene's folder.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <random>

#include "gltf_docs.h"
#include "image.h"
#include "render_scene.h"
#include "scene_file.h"
#include "test_util.h"

using namespace pt;
using test::fails_at;
using test::GltfDoc;
using test::json;

namespace {

// A w x h PNG (through the image module, as textures are decoded).
std::string png(int w, int h) {
  std::vector<uint8_t> rgb(size_t(w) * size_t(h) * 3, 200);
  return encode_png8(rgb, w, h);
}

// The quad with its base colour read from `image_uri`.
GltfDoc textured_quad(const std::string& image_uri) {
  GltfDoc g = test::quad_doc();
  g.doc["images"] = json::array({json{{"uri", image_uri}}});
  g.doc["textures"] = json::array({json{{"source", 0}}});
  g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  return g;
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

}  // namespace

TEST(GltfErrors, BadJsonAndMissingParts) {
  EXPECT_TRUE(fails_at(R"({"asset": {"version": "2.0"},)", "JSON error: "));
  EXPECT_TRUE(fails_at("[1, 2]", "/: the JSON root must be an object"));
  EXPECT_TRUE(fails_at(R"({"asset": {"version": "2.0"}, "x": 41e308})", "JSON error: "));  // beyond a double (fuzzer)
  EXPECT_TRUE(fails_at("{}", "/: missing 'asset'"));
  EXPECT_TRUE(fails_at(R"({"asset": {"version": "1.0"}})", "/asset/version: '1.0' is not glTF 2.x"));
  GltfDoc g = test::quad_doc();
  g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = "x";
  EXPECT_TRUE(fails_at(g.text(), "/meshes/0/primitives/0/attributes/POSITION: must be an integer"));
  g = test::quad_doc();
  g.doc["accessors"][0].erase("componentType");
  EXPECT_TRUE(fails_at(g.text(), "/accessors/0: missing 'componentType'"));
  g = test::quad_doc();
  g.doc["meshes"][0]["primitives"][0]["material"] = 5;
  EXPECT_TRUE(fails_at(g.text(), "/meshes/0/primitives/0/material: 5 names no element of 'materials' (1)"));
  g = test::quad_doc();
  g.doc["scenes"][0]["nodes"] = {0, 0};
  g.doc["scene"] = 3;
  EXPECT_TRUE(fails_at(g.text(), "/scene: 3 names no element of 'scenes' (1)"));
}

TEST(GltfErrors, TruncatedAndLyingBuffers) {
  GltfDoc g = test::quad_doc();  // 48 bytes of positions, 12 of indices: 60 bytes
  json d = json::parse(g.text());
  d["buffers"][0]["byteLength"] = 100;  // the data URI is short of what the file declares
  EXPECT_TRUE(fails_at(d.dump(), "/buffers/0/uri: the data URI holds 60 bytes, byteLength says 100"));
  d["buffers"][0]["byteLength"] = 40;  // ... or holds more than it says
  EXPECT_TRUE(fails_at(d.dump(), "/buffers/0/uri: the data URI holds 60 bytes, byteLength says 40"));
  d["buffers"][0]["byteLength"] = 60;
  d["buffers"][0]["uri"] = "data:application/octet-stream;base64,AAAA*AAA";
  EXPECT_TRUE(fails_at(d.dump(), "/buffers/0/uri: the data URI's payload is not base64"));
  d["buffers"][0]["uri"] = "data:image/webp;base64,AAAA";
  EXPECT_TRUE(fails_at(d.dump(), "/buffers/0/uri: data URI 'data:image/webp;base64' is not"));

  // A .glb cut short, or whose BIN chunk is shorter than its buffer says.
  const std::string glb = g.glb();
  EXPECT_TRUE(fails_at(glb.substr(0, glb.size() / 2), "not a valid .glb: the header says", "bad.glb"));
  std::string cut = glb.substr(0, glb.size() - 8);
  uint32_t len = uint32_t(cut.size());
  std::memcpy(&cut[8], &len, 4);
  EXPECT_TRUE(fails_at(cut, "not a valid .glb: the BIN chunk's length runs past the file", "bad.glb"));
  GltfDoc h = g;
  h.bin.resize(h.bin.size() - 12);  // BIN holds 48 bytes, the views reach 60
  std::string short_bin = h.glb();
  EXPECT_TRUE(fails_at(short_bin, "/bufferViews/1: bytes 48 to 60 lie outside buffer 0 (48 bytes)", "bad.glb"));
}

TEST(GltfErrors, AccessorsAndIndicesOutOfRange) {
  GltfDoc g = test::quad_doc();
  g.doc["accessors"][0]["count"] = 5;  // 5 x 12 bytes in a 48-byte view
  EXPECT_TRUE(fails_at(g.text(), "/accessors/0: 5 elements of 12 bytes from byte 0 (stride 12) end at byte 60, past bufferView 0"));
  g = test::quad_doc();
  g.doc["accessors"][0]["byteOffset"] = 4;
  EXPECT_TRUE(fails_at(g.text(), "/accessors/0: 4 elements of 12 bytes from byte 4"));
  g = test::quad_doc();
  g.doc["bufferViews"][0]["byteLength"] = 1000;
  EXPECT_TRUE(fails_at(g.text(), "/bufferViews/0: bytes 0 to 1000 lie outside buffer 0"));
  // Huge declared counts: over the limit at once, or not backed by the view.
  g = test::quad_doc();
  g.doc["accessors"][0]["count"] = 4000000000u;
  EXPECT_TRUE(fails_at(g.text(), "/accessors/0/count: must be at most 400000000"));
  g.doc["accessors"][0]["count"] = 10000000;
  EXPECT_TRUE(fails_at(g.text(), "/accessors/0: 10000000 elements"));
  // An index past the vertices.
  g = test::quad_doc();
  g.bin[48 + 4] = 7;  // the third index
  EXPECT_TRUE(fails_at(g.text(), "/meshes/0/primitives/0/indices: index 7 (element 2) is out of range: POSITION has 4 vertices"));
  g = test::quad_doc();
  g.doc["accessors"][0]["type"] = "VEC2";
  EXPECT_TRUE(fails_at(g.text(), "/meshes/0/primitives/0/attributes/POSITION (accessor 0): has the wrong type"));
}

// Sparse accessors (glTF 2.0, 3.6.2.3) substitute elements: the quad's third corner moves up to
// z = 0.5. Indices out of range or not strictly increasing are located errors.
TEST(GltfErrors, SparseAccessorsSubstituteAndCheckTheirIndices) {
  auto sparse_doc = [](const std::vector<uint16_t>& which, const std::vector<float>& values) {
    GltfDoc g = test::quad_doc();
    const int iv = g.view(test::bytes_of(which)), vv = g.view(test::bytes_of(values));
    g.doc["accessors"][0]["sparse"] = {{"count", which.size()},
                                       {"indices", {{"bufferView", iv}, {"componentType", 5123}}},
                                       {"values", {{"bufferView", vv}}}};
    g.doc["accessors"][0]["max"] = {1, 1, 1};
    return g;
  };
  SceneDesc d = parse_gltf(sparse_doc({2}, {1, 1, 0.5f}).text(), "sparse.gltf", false);
  ASSERT_EQ(d.meshes.size(), 1u);
  EXPECT_EQ(d.meshes[0].positions[2].z, 0.5f);
  EXPECT_EQ(d.meshes[0].positions[1].z, 0.0f);
  const std::string at = "/meshes/0/primitives/0/attributes/POSITION (accessor 0)/sparse";
  EXPECT_TRUE(fails_at(sparse_doc({9}, {1, 1, 0.5f}).text(), at + "/indices: index 9 (element 0) is out of range"));
  EXPECT_TRUE(fails_at(sparse_doc({2, 1}, {1, 1, 0.5f, 1, 1, 0.5f}).text(),
                       at + "/indices: index 1 (element 1) does not increase strictly"));
  EXPECT_TRUE(fails_at(sparse_doc({1, 2}, {1, 1, 0.5f}).text(), at + "/values: 24 bytes from byte 0 lie outside"));
}

TEST(GltfErrors, NonFiniteTransformsAndPositions) {
  GltfDoc g = test::quad_doc();
  g.doc["nodes"][0] = json{{"scale", {1e300, 1, 1}}, {"children", {1}}};
  g.doc["nodes"].push_back(json{{"mesh", 0}, {"scale", {1e300, 1, 1}}});
  EXPECT_TRUE(fails_at(g.text(), "/nodes/1: the transform is not finite"));
  g = test::quad_doc();
  g.doc["nodes"][0]["scale"] = {1e39, 1, 1};  // finite as a double, infinite as our float
  EXPECT_TRUE(fails_at(g.text(), "/meshes/0/primitives/0/attributes/POSITION: vertex 0 is not finite after the node's transform"));
  g = test::quad_doc();
  const float nan = std::nanf("");
  std::memcpy(&g.bin[12], &nan, 4);  // vertex 1's x
  EXPECT_TRUE(fails_at(g.text(), "/meshes/0/primitives/0/attributes/POSITION (accessor 0): element 1 is not finite"));
  g = test::quad_doc();
  g.doc["nodes"][0]["rotation"] = {0, 0, 0, 0};
  EXPECT_TRUE(fails_at(g.text(), "/nodes/0/rotation: is not a rotation"));
  g = test::quad_doc();
  g.doc["nodes"][0]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  g.doc["nodes"][0]["scale"] = {1, 1, 1};
  EXPECT_TRUE(fails_at(g.text(), "/nodes/0: has both 'matrix' and translation / rotation / scale"));
}

TEST(GltfErrors, NodeHierarchyMustBeTrees) {
  GltfDoc g = test::quad_doc();
  g.doc["nodes"].push_back(json{{"children", {2}}});
  g.doc["nodes"].push_back(json{{"children", {1}}});  // 1 -> 2 -> 1, neither a root
  EXPECT_TRUE(fails_at(g.text(), "/nodes/1: is its own ancestor: the node hierarchy has a cycle"));
  g = test::quad_doc();
  g.doc["nodes"][0]["children"] = {0};
  EXPECT_TRUE(fails_at(g.text(), "/nodes/0/children/0: node 0 is its own child"));
  g = test::quad_doc();
  g.doc["nodes"].push_back(json{{"children", {0}}});
  g.doc["nodes"].push_back(json{{"children", {0}}});
  EXPECT_TRUE(fails_at(g.text(), "/nodes/2/children/0: node 0 already has a parent (node 1)"));
  g = test::quad_doc();
  g.doc["nodes"].push_back(json{{"children", {0}}});
  EXPECT_TRUE(fails_at(g.text(), "/scenes/0/nodes/0: node 0 is a child of node 1, not a root"));
  // Depth is bounded however the trees are shaped.
  g = test::quad_doc();
  LoadLimits limits;
  limits.max_node_depth = 3;
  for (int i = 0; i < 5; ++i) g.doc["nodes"][size_t(i)]["children"] = {i + 1}, g.doc["nodes"].push_back(json::object());
  EXPECT_TRUE(fails_at(g.text(), "/nodes/4: nodes nested deeper than 3", "bad.gltf", limits));
}

TEST(GltfErrors, ExtensionsRequiredMustBeSupported) {
  GltfDoc g = test::quad_doc();
  g.doc["extensionsRequired"] = {"KHR_materials_emissive_strength", "KHR_draco_mesh_compression"};
  EXPECT_TRUE(fails_at(g.text(), "/extensionsRequired/1: extension 'KHR_draco_mesh_compression' is required and not supported"));
}

TEST(GltfErrors, JsonLimits) {
  std::string deep = R"({"asset": {"version": "2.0"}, "extras": )" + std::string(200, '[') + std::string(200, ']') + "}";
  EXPECT_TRUE(fails_at(deep, "JSON nested deeper than 64 levels"));
  LoadLimits limits;
  limits.max_json_values = 20;
  EXPECT_TRUE(fails_at(test::quad_doc().text(), "more than 20 JSON values", "bad.gltf", limits));
  limits = LoadLimits();
  limits.max_file_bytes = 100;
  EXPECT_TRUE(fails_at(test::quad_doc().text(), "", "bad.gltf", limits));
}

TEST(GltfErrors, ExternalFilesOnlyInsideTheScenesFolder) {
  GltfDoc g = test::quad_doc();
  json d = json::parse(g.text());
  d["buffers"][0]["uri"] = "quad.bin";
  EXPECT_TRUE(fails_at(d.dump(), "/buffers/0/uri: refers to the file 'quad.bin'; only self-contained glTF is read here"));
  const std::string dir = test::temp_dir() + "/gltf_external";
  std::filesystem::create_directories(dir);
  write_file(dir + "/quad.bin", g.bin);
  SceneDesc ok = parse_gltf(d.dump(), "ext.gltf", false, {}, dir);  // inside the folder: read
  EXPECT_EQ(ok.meshes.size(), 1u);
  for (const char* uri : {"../quad.bin", "/etc/passwd", "file:///etc/passwd", "sub/../../quad.bin", "%2e%2e/quad.bin"}) {
    d["buffers"][0]["uri"] = uri;
    EXPECT_TRUE(fails_at(d.dump(), "/buffers/0/uri: '", "bad.gltf", {}, dir)) << uri;
  }
  std::filesystem::remove(dir + "/link.bin");
  write_file(test::temp_dir() + "/outside.bin", g.bin);
  ASSERT_EQ(symlink((test::temp_dir() + "/outside.bin").c_str(), (dir + "/link.bin").c_str()), 0);
  d["buffers"][0]["uri"] = "link.bin";
  EXPECT_TRUE(fails_at(d.dump(), "/buffers/0/uri: 'link.bin' leads out of the scene's folder", "bad.gltf", {}, dir));
  write_file(dir + "/short.bin", g.bin.substr(0, 10));
  d["buffers"][0]["uri"] = "short.bin";
  EXPECT_TRUE(fails_at(d.dump(), "/buffers/0/uri: 'short.bin' is 10 bytes, byteLength says 60", "bad.gltf", {}, dir));
  // An image file that is missing fails where a material reads it.
  GltfDoc t = textured_quad("missing.png");
  EXPECT_TRUE(fails_at(t.text(), "/materials/0/pbrMetallicRoughness/baseColorTexture: image 0 of texture 0 could not be read",
                       "bad.gltf", {}, dir));
}

TEST(GltfErrors, TextureLimitsAndBadImages) {
  GltfDoc g = textured_quad("data:image/png;base64," + test::base64(png(64, 64)));
  g.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = g.floats({0, 0, 1, 0, 1, 1, 0, 1}, "VEC2", 2);
  EXPECT_EQ(parse_gltf(g.text(), "ok.gltf", false).textures.size(), 1u);
  LoadLimits limits;
  limits.max_texture_pixels = 100;
  EXPECT_TRUE(fails_at(g.text(), "/images/0: 64x64 pixels, over the limit of 100", "bad.gltf", limits));
  limits = LoadLimits();
  limits.max_texture_bytes = 10000;  // 64 x 64 x 3 = 12288
  EXPECT_TRUE(fails_at(g.text(), "/images/0: the textures take more than 10000 bytes decoded", "bad.gltf", limits));
  g.doc["images"][0]["uri"] = "data:image/png;base64," + test::base64("not a png at all");
  EXPECT_TRUE(fails_at(g.text(), "/images/0: not a PNG or JPEG image"));
  std::string truncated = png(64, 64);
  g.doc["images"][0]["uri"] = "data:image/png;base64," + test::base64(truncated.substr(0, truncated.size() / 2));
  EXPECT_TRUE(fails_at(g.text(), "/images/0: "));
  g.doc["images"][0] = json{{"bufferView", 7}};
  EXPECT_TRUE(fails_at(g.text(), "/images/0/bufferView: 7 names no element of 'bufferViews'"));
  g.doc["images"][0] = json{{"uri", "data:image/png;base64," + test::base64(png(4, 4))}};
  g.doc["samplers"] = json::array({json{{"wrapS", 1234}}});
  g.doc["textures"][0]["sampler"] = 0;
  EXPECT_TRUE(fails_at(g.text(), "/samplers/0/wrapS: 1234 is not CLAMP_TO_EDGE, MIRRORED_REPEAT or REPEAT"));
}

// Damaged copies of our scenes (bytes flipped, cut short): each loads or fails with a SceneError,
// never anything else.
TEST(GltfErrors, DamagedFilesFailCleanly) {
  std::mt19937 rng(184);
  for (const char* name : {"showcase.gltf", "cornell_gltf.glb"}) {
    const std::string original = read_scene_bytes(test::own_scene(name));
    int failed = 0;
    for (int i = 0; i < 150; ++i) {
      std::string text = original;
      if (i % 3 == 0) {
        text.resize(std::uniform_int_distribution<size_t>(0, text.size())(rng));
      } else {
        // Flips in the JSON (the first 4 KiB) mostly: where the structure is.
        for (int k = 0; k < 1 + i % 4; ++k)
          text[std::uniform_int_distribution<size_t>(0, std::min<size_t>(text.size(), 4096) - 1)(rng)] ^=
              char(1 << std::uniform_int_distribution<int>(0, 7)(rng));
      }
      try {
        SceneDesc d = parse_scene(text, name);
        make_scene_base(d);
      } catch (const SceneError&) {
        ++failed;
      } catch (const std::exception& e) {
        ADD_FAILURE() << name << " damage " << i << ": not a SceneError: " << e.what();
      }
    }
    EXPECT_GT(failed, 50) << name;
  }
}
