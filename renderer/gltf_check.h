// The glTF checker's shared part (gltf_json.cpp: container, buffers, accessors, images;
// gltf_check.cpp: materials, meshes, nodes, scenes, cameras, lights, skins, animations): JSON
// values read with their path, each wrong one a SceneError naming it. Internal to the reader.
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "gltf_reader.h"

namespace pt::gltf_detail {

using json = nlohmann::json;

// Text from a parser's message made safe to print: control and non-ASCII bytes become '?'.
inline std::string printable(const std::string& s, size_t n = 200) {
  std::string out = s.substr(0, n);
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  return s.size() > n ? out + "..." : out;
}

class Checker {
 public:
  Checker(const Context& ctx, const json& doc, size_t bin_size) : m_ctx(ctx), m_doc(doc), m_bin_size(bin_size) {}

  Checked run();

 private:
  [[noreturn]] void fail(const std::string& path, const std::string& msg) const { m_ctx.fail(path, msg); }

  // The array `key` of the root (or of `o`), each element an object; null when absent.
  const json* array(const json& o, const char* key, const std::string& path, bool of_objects = true) const {
    auto it = o.find(key);
    if (it == o.end()) return nullptr;
    if (!it->is_array()) fail(path + "/" + key, "must be an array");
    if (of_objects)
      for (size_t i = 0; i < it->size(); ++i)
        if (!(*it)[i].is_object()) fail(path + "/" + key + "/" + std::to_string(i), "must be an object");
    return &*it;
  }
  size_t count(const char* key) const {
    auto it = m_doc.find(key);
    return it != m_doc.end() && it->is_array() ? it->size() : 0;
  }
  const json* object(const json& o, const char* key, const std::string& path, bool required = false) const {
    auto it = o.find(key);
    if (it == o.end()) {
      if (required) fail(path, std::string("missing '") + key + "'");
      return nullptr;
    }
    if (!it->is_object()) fail(path + "/" + key, "must be an object");
    return &*it;
  }
  // An integer in [lo, hi], or `def` when absent and not required.
  int64_t integer(const json& o, const char* key, const std::string& path, bool required, int64_t lo, int64_t hi,
                  int64_t def = 0) const {
    auto it = o.find(key);
    if (it == o.end()) {
      if (required) fail(path, std::string("missing '") + key + "'");
      return def;
    }
    const std::string at = path + "/" + key;
    if (!it->is_number_integer()) fail(at, "must be an integer");
    if (it->is_number_unsigned() ? it->get<uint64_t>() > uint64_t(hi) : it->get<int64_t>() > hi)
      fail(at, "must be at most " + std::to_string(hi));
    int64_t v = it->get<int64_t>();
    if (v < lo) fail(at, "must be at least " + std::to_string(lo));
    return v;
  }
  // An index into the root array `target`.
  int64_t index(const json& o, const char* key, const std::string& path, const char* target, bool required = false) const {
    if (!o.contains(key) && !required) return -1;
    int64_t v = integer(o, key, path, true, 0, INT32_MAX);
    if (size_t(v) >= count(target))
      fail(path + "/" + key, std::to_string(v) + " names no element of '" + target + "' (" + std::to_string(count(target)) + ")");
    return v;
  }
  double number(const json& o, const char* key, const std::string& path, bool required, double lo, double hi,
                double def = 0) const {
    auto it = o.find(key);
    if (it == o.end()) {
      if (required) fail(path, std::string("missing '") + key + "'");
      return def;
    }
    const std::string at = path + "/" + key;
    if (!it->is_number()) fail(at, "must be a number");
    double v = it->get<double>();
    if (!std::isfinite(v)) fail(at, "must be finite");
    if (v < lo || v > hi) fail(at, "must be between " + std::to_string(lo) + " and " + std::to_string(hi));
    return v;
  }
  void numbers(const json& o, const char* key, const std::string& path, size_t n, double lo = -HUGE_VAL,
               double hi = HUGE_VAL) const {
    auto it = o.find(key);
    if (it == o.end()) return;
    const std::string at = path + "/" + key;
    if (!it->is_array() || (n && it->size() != n)) fail(at, "must be an array of " + std::to_string(n) + " numbers");
    for (size_t i = 0; i < it->size(); ++i) number(*it, i, at, lo, hi);
  }
  void number(const json& arr, size_t i, const std::string& path, double lo, double hi) const {
    const json& v = arr[i];
    const std::string at = path + "/" + std::to_string(i);
    if (!v.is_number() || !std::isfinite(v.get<double>())) fail(at, "must be a finite number");
    if (v.get<double>() < lo || v.get<double>() > hi)
      fail(at, "must be between " + std::to_string(lo) + " and " + std::to_string(hi));
  }
  std::string string(const json& o, const char* key, const std::string& path, bool required = false) const {
    auto it = o.find(key);
    if (it == o.end()) {
      if (required) fail(path, std::string("missing '") + key + "'");
      return "";
    }
    if (!it->is_string()) fail(path + "/" + key, "must be a string");
    return it->get<std::string>();
  }
  void boolean(const json& o, const char* key, const std::string& path) const {
    if (o.contains(key) && !o[key].is_boolean()) fail(path + "/" + key, "must be true or false");
  }
  // A textureInfo: `index` into textures, `texCoord` a set number. With `read`, its image is one
  // the materials read (decoded; the others never are).
  void texture_info(const json& o, const char* key, const std::string& path, bool read = false) {
    const json* t = object(o, key, path);
    if (!t) return;
    const std::string at = path + "/" + key;
    int64_t tex = index(*t, "index", at, "textures", true);
    integer(*t, "texCoord", at, false, 0, 255);
    number(*t, "scale", at, false, -1e9, 1e9, 1);
    number(*t, "strength", at, false, 0, 1, 1);
    if (const json* ext = object(*t, "extensions", at))
      if (const json* tt = object(*ext, "KHR_texture_transform", at + "/extensions")) {
        const std::string tat = at + "/extensions/KHR_texture_transform";
        numbers(*tt, "offset", tat, 2, -1e6, 1e6);
        numbers(*tt, "scale", tat, 2, -1e6, 1e6);
        number(*tt, "rotation", tat, false, -1e6, 1e6);
        integer(*tt, "texCoord", tat, false, 0, 255);
      }
    const json& texture = m_doc["textures"][size_t(tex)];
    if (read && texture.contains("source")) m_checked.decode_image[size_t(texture["source"].get<int64_t>())] = true;
  }
  void check_uri(const json& o, const std::string& path, int64_t byte_length, bool image);
  void asset_and_extensions();
  void buffers();
  void accessors();
  void images_and_textures();
  void materials();
  void meshes();
  void nodes_and_scenes();
  void cameras_and_lights();
  void skins_and_animations();

  const Context& m_ctx;
  const json& m_doc;
  size_t m_bin_size;
  Checked m_checked;
  std::vector<int64_t> m_buffer_length, m_view_length;
};

}  // namespace pt::gltf_detail
