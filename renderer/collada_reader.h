// The COLLADA reader's internals, shared by collada.cpp (document, nodes, cameras, lights,
// materials) and collada_geometry.cpp (meshes and CGL spheres). Not part of the renderer's API.
#pragma once

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <vector>
#include <pugixml.hpp>

#include "collada.h"

namespace pt {
namespace collada_detail {

// User text quoted in a message, cut short: an id or URL of a megabyte must not become the message.
// The cut never splits a UTF-8 character (a Blender export's long Japanese object name would
// otherwise make the message invalid UTF-8).
inline std::string clip(const std::string& s, size_t n = 60) {
  if (s.size() <= n) return s;
  for (int back = 0; back < 3 && n > 0 && (static_cast<unsigned char>(s[n]) & 0xc0) == 0x80; ++back) --n;
  return s.substr(0, n) + "...";
}

class Reader {
 public:
  Reader(const std::string& text, const std::string& name, const LoadLimits& limits)
      : m_text(text), m_name(name), m_limits(limits) {}

  SceneDesc read();

 private:
  // ---- errors ----
  int line_of(const pugi::xml_node& node) const {
    ptrdiff_t off = node.offset_debug();
    if (off < 0) return 0;
    return 1 + int(std::count(m_text.begin(), m_text.begin() + std::min<size_t>(off, m_text.size()), '\n'));
  }
  std::string where(const pugi::xml_node& node) const {
    std::ostringstream s;
    s << m_name;
    if (node) {
      int line = line_of(node);
      if (line > 0) s << ":" << line;
      s << ": <" << clip(node.name());
      if (auto id = node.attribute("id")) s << " id='" << clip(id.value()) << "'";
      else if (auto sid = node.attribute("sid")) s << " sid='" << clip(sid.value()) << "'";
      s << ">";
    }
    return s.str();
  }
  [[noreturn]] void fail(const pugi::xml_node& node, const std::string& msg) const {
    throw SceneError(where(node) + ": " + msg);
  }
  // Capped per file: a million <skew> elements must not print a million lines (each line number
  // also costs a scan of the text).
  void warn(const pugi::xml_node& node, const std::string& msg) const {
    if (++m_warnings > m_limits.max_warnings) return;
    m_warning_lines.push_back(where(node) + ": " + msg);
    std::fprintf(stderr, "warning: %s\n", m_warning_lines.back().c_str());
  }
  // Every number and index read counts, again when instancing reads an array again: instancing
  // cannot multiply the work without bound.
  void count_value(const pugi::xml_node& node) const {
    if (++m_values > m_limits.max_values)
      fail(node, "more than " + std::to_string(m_limits.max_values) + " numbers read (instancing included)");
  }

  // ---- values ----
  std::vector<double> numbers(const pugi::xml_node& node) const { return values<double>(node, "a number"); }
  std::vector<uint32_t> indices(const pugi::xml_node& node) const {
    return values<uint32_t>(node, "a non-negative integer index");
  }
  // The whitespace-separated values of `node`'s text, each counted against the limits; a token that
  // does not parse as T fails naming it as not `what`. Numbers may carry a '+' (from_chars takes none)
  // and must be finite.
  template <class T>
  std::vector<T> values(const pugi::xml_node& node, const char* what) const {
    constexpr bool real = std::is_floating_point_v<T>;
    std::vector<T> out;
    const char* s = node.child_value();
    const char* end = s + std::strlen(s);
    while (s < end) {
      while (s < end && std::isspace((unsigned char)*s)) ++s;
      if (s >= end) break;
      T v;
      const char* start = s;
      if (real && *s == '+') ++s;
      auto r = std::from_chars(s, end, v);
      if (r.ec != std::errc() || (r.ptr < end && !std::isspace((unsigned char)*r.ptr))) {
        const char* e = start;
        while (e < end && !std::isspace((unsigned char)*e)) ++e;
        fail(node, "'" + std::string(start, std::min<size_t>(e - start, 40)) + "' is not " + what);
      }
      if constexpr (real)
        if (!std::isfinite(v)) fail(node, "non-finite number '" + clip(std::string(start, r.ptr - start)) + "'");
      count_value(node);
      out.push_back(v);
      s = r.ptr;
    }
    return out;
  }
  pugi::xml_node require(const pugi::xml_node& parent, const char* child) const {
    pugi::xml_node c = parent.child(child);
    if (!c) fail(parent, std::string("missing <") + child + ">");
    return c;
  }
  double scalar(const pugi::xml_node& parent, const char* child) const {
    pugi::xml_node c = require(parent, child);
    auto v = numbers(c);
    if (v.size() != 1) fail(c, "expected one number, found " + std::to_string(v.size()));
    return v[0];
  }
  double scalar_or(const pugi::xml_node& parent, const char* child, double def) const {
    return parent.child(child) ? scalar(parent, child) : def;
  }
  // An RGB triple; a fourth (alpha) value is allowed and ignored. Negative colours are rejected.
  Vec3 color(const pugi::xml_node& parent, const char* child) const {
    pugi::xml_node c = require(parent, child);
    auto v = numbers(c);
    if (v.size() != 3 && v.size() != 4) fail(c, "expected 3 numbers (RGB), found " + std::to_string(v.size()));
    if (v[0] < 0 || v[1] < 0 || v[2] < 0) fail(c, "colour components must not be negative");
    return Vec3(float(v[0]), float(v[1]), float(v[2]));
  }
  pugi::xml_node lookup_url(const pugi::xml_node& node, const char* attr = "url") const {
    std::string url = node.attribute(attr).value();
    if (url.empty()) fail(node, std::string("missing attribute '") + attr + "'");
    if (url[0] != '#') fail(node, "only local references ('#id') are supported, got '" + clip(url) + "'");
    auto it = m_ids.find(url.substr(1));
    if (it == m_ids.end()) fail(node, "reference '" + clip(url) + "' names no element");
    return it->second;
  }

  // ---- scene parts ----
  Mat4 read_local_transform(const pugi::xml_node& node) const;
  void read_node(const pugi::xml_node& node, const Mat4& parent, int depth);
  void read_camera(const pugi::xml_node& inst, const Mat4& world);
  void read_light(const pugi::xml_node& inst, const Mat4& world);
  void read_geometry(const pugi::xml_node& inst, const Mat4& world);
  void read_mesh(const pugi::xml_node& mesh, const pugi::xml_node& inst, const Mat4& world, const std::string& name);
  int resolve_material(const pugi::xml_node& inst_material_node);
  int default_material();
  Material read_effect(const pugi::xml_node& effect, const std::string& name) const;

  const std::string& m_text;
  std::string m_name;
  LoadLimits m_limits;
  pugi::xml_document m_doc;
  std::unordered_map<std::string, pugi::xml_node> m_ids;
  std::unordered_map<std::string, int> m_material_index;  // by material element id
  int m_default_material = -1;
  size_t m_node_count = 0;
  size_t m_triangle_count = 0;
  mutable size_t m_values = 0;
  mutable int m_warnings = 0;
  mutable std::vector<std::string> m_warning_lines;
  SceneDesc m_scene;
  Mat4 m_up;
};

}  // namespace collada_detail
}  // namespace pt
