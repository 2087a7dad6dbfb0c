// glTF documents for the tests, built as JSON (nlohmann) with their binary data in a data: URI or
// a .glb BIN chunk, so that each test can break one thing and look for its JSON path in the error.
#pragma once

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "gltf.h"
#include "render_scene.h"
#include "session.h"

namespace pt::test {

using json = nlohmann::json;

inline std::string base64(const std::string& in) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    uint32_t v = uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8 | uint8_t(in[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += k[(v >> s) & 63];
  }
  if (i + 1 == in.size()) {
    uint32_t v = uint32_t(uint8_t(in[i])) << 16;
    out += k[(v >> 18) & 63], out += k[(v >> 12) & 63], out += "==";
  } else if (i + 2 == in.size()) {
    uint32_t v = uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8;
    out += k[(v >> 18) & 63], out += k[(v >> 12) & 63], out += k[(v >> 6) & 63], out += '=';
  }
  return out;
}

template <class T>
std::string bytes_of(const std::vector<T>& v) {
  return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

struct GltfDoc {
  json doc = json{{"asset", {{"version", "2.0"}}}, {"scene", 0}, {"scenes", json::array({json{{"nodes", json::array()}}})},
                  {"nodes", json::array()}, {"meshes", json::array()}, {"materials", json::array()},
                  {"accessors", json::array()}, {"bufferViews", json::array()}};
  std::string bin;

  // A bufferView over `bytes`, appended to the buffer (4-byte aligned).
  int view(const std::string& bytes, int stride = 0) {
    while (bin.size() % 4) bin += '\0';
    json v{{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes.size()}};
    if (stride) v["byteStride"] = stride;
    bin += bytes;
    doc["bufferViews"].push_back(v);
    return int(doc["bufferViews"].size()) - 1;
  }
  int accessor(int view, int component_type, size_t count, const char* type, bool normalized = false) {
    json a{{"bufferView", view}, {"componentType", component_type}, {"count", count}, {"type", type}};
    if (normalized) a["normalized"] = true;
    doc["accessors"].push_back(a);
    return int(doc["accessors"].size()) - 1;
  }
  int floats(const std::vector<float>& v, const char* type, size_t per) {
    return accessor(view(bytes_of(v)), 5126, v.size() / per, type);
  }
  int indices(const std::vector<uint16_t>& v) { return accessor(view(bytes_of(v)), 5123, v.size(), "SCALAR"); }
  int material(const json& m) {
    doc["materials"].push_back(m);
    return int(doc["materials"].size()) - 1;
  }
  // A mesh of one TRIANGLES primitive and a root node showing it; returns the node.
  int mesh(const json& attributes, int indices, int material, const json& node = json::object()) {
    json prim{{"attributes", attributes}};
    if (indices >= 0) prim["indices"] = indices;
    if (material >= 0) prim["material"] = material;
    doc["meshes"].push_back(json{{"primitives", json::array({prim})}});
    json n = node;
    n["mesh"] = int(doc["meshes"].size()) - 1;
    return root(n);
  }
  int root(const json& node) {
    doc["nodes"].push_back(node);
    const int i = int(doc["nodes"].size()) - 1;
    doc["scenes"][0]["nodes"].push_back(i);
    return i;
  }
  void light(const json& light, const json& node) {
    doc["extensions"]["KHR_lights_punctual"]["lights"].push_back(light);
    json n = node;
    n["extensions"]["KHR_lights_punctual"]["light"] = int(doc["extensions"]["KHR_lights_punctual"]["lights"].size()) - 1;
    root(n);
    doc["extensionsUsed"] = json::array({"KHR_lights_punctual"});
  }
  // The .gltf text: the buffer as a base64 data: URI.
  std::string text() const {
    json d = doc;
    if (!bin.empty())
      d["buffers"] = json::array({json{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
    return d.dump();
  }
  // The .glb bytes: JSON chunk, then the buffer as the BIN chunk.
  std::string glb() const {
    json d = doc;
    std::string b = bin;
    while (b.size() % 4) b += '\0';
    if (!b.empty()) d["buffers"] = json::array({json{{"byteLength", bin.size()}}});
    std::string j = d.dump();
    while (j.size() % 4) j += ' ';
    auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    std::string out = "glTF" + u32(2) + u32(uint32_t(12 + 8 + j.size() + (b.empty() ? 0 : 8 + b.size())));
    out += u32(uint32_t(j.size())) + "JSON" + j;
    if (!b.empty()) out += u32(uint32_t(b.size())) + std::string("BIN\0", 4) + b;
    return out;
  }
};

// A glTF document rendered at 48x48 (no adaptive sampling, 2 threads, `seed`), checked for NaN.
inline ImageRGB render_gltf(const std::string& text, int spp, int depth, uint64_t seed = 0) {
  RenderParams p;
  p.width = p.height = 48;
  p.spp = spp;
  p.max_depth = depth;
  p.adaptive = false;
  p.threads = 2;
  p.seed = seed;
  auto scene = make_render_scene(parse_gltf(text, "t.gltf", false), p);
  RenderSession s(*scene, p);
  s.render_all();
  EXPECT_EQ(s.stats().nonfinite, 0u);
  return s.image();
}

// What a white Lambertian quad facing +z reflects under the default light (an unlit glTF scene's):
// the environment's radiance plus the sun's irradiance x cos / pi.
inline const double kDefaultLightOnTheQuad = kDefaultEnvironment + kDefaultSunIrradiance * kDefaultSunDirection.z / M_PI;

// A 2 x 2 quad in the z = 0 plane facing +z (uv (0, 0) at its top left), material 0: a white
// diffuse surface; `extra` attributes may be added by the caller through doc.
inline GltfDoc quad_doc() {
  GltfDoc g;
  int pos = g.floats({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, "VEC3", 3);
  g.doc["accessors"][size_t(pos)]["min"] = {-1, -1, 0};
  g.doc["accessors"][size_t(pos)]["max"] = {1, 1, 0};
  int idx = g.indices({0, 1, 2, 0, 2, 3});
  int mat = g.material(json{{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0}}}});
  g.mesh(json{{"POSITION", pos}}, idx, mat);
  return g;
}

// Parses `text` as `name` and succeeds when a SceneError names the file and starts its location
// with `path` (a JSON path, or a phrase for errors before the JSON).
inline ::testing::AssertionResult fails_at(const std::string& text, const std::string& path, const std::string& name = "bad.gltf",
                                           const LoadLimits& limits = {}, const std::string& base_dir = "") {
  try {
    parse_gltf(text, name, name.size() > 4 && name.compare(name.size() - 4, 4, ".glb") == 0, limits, base_dir);
  } catch (const SceneError& e) {
    const std::string want = name + ": " + path;
    if (std::string(e.what()).compare(0, want.size(), want) == 0) return ::testing::AssertionSuccess() << e.what();
    return ::testing::AssertionFailure() << "the error is '" << e.what() << "', expected it to start with '" << want << "'";
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << "not a SceneError: " << e.what();
  }
  return ::testing::AssertionFailure() << "loaded without an error";
}

}  // namespace pt::test
