// CS184 COLLADA reader: pugixml DOM -> SceneDesc, every error located by file, element and line.
// The dialect is described in scenes/README.md; deviations from the course parser in docs/cs184-compat.md.
#include "collada.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <unordered_map>
#include <pugixml.hpp>

namespace pt {
namespace {

// User text quoted in a message, cut short: an id or URL of a megabyte must not become the message.
std::string clip(const std::string& s, size_t n = 60) { return s.size() <= n ? s : s.substr(0, n) + "..."; }

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
    std::fprintf(stderr, "warning: %s: %s\n", where(node).c_str(), msg.c_str());
  }
  // Every number and index read counts, again when instancing reads an array again: instancing
  // cannot multiply the work without bound.
  void count_value(const pugi::xml_node& node) const {
    if (++m_values > m_limits.max_values)
      fail(node, "more than " + std::to_string(m_limits.max_values) + " numbers read (instancing included)");
  }

  // ---- values ----
  std::vector<double> numbers(const pugi::xml_node& node) const {
    std::vector<double> out;
    const char* s = node.child_value();
    const char* end = s + std::strlen(s);
    while (s < end) {
      while (s < end && std::isspace((unsigned char)*s)) ++s;
      if (s >= end) break;
      double v;
      const char* start = s;
      if (*s == '+') ++s;
      auto r = std::from_chars(s, end, v);
      if (r.ec != std::errc() || (r.ptr < end && !std::isspace((unsigned char)*r.ptr))) {
        const char* e = start;
        while (e < end && !std::isspace((unsigned char)*e)) ++e;
        fail(node, "'" + std::string(start, std::min<size_t>(e - start, 40)) + "' is not a number");
      }
      if (!std::isfinite(v)) fail(node, "non-finite number '" + clip(std::string(start, r.ptr - start)) + "'");
      count_value(node);
      out.push_back(v);
      s = r.ptr;
    }
    return out;
  }
  std::vector<uint32_t> indices(const pugi::xml_node& node) const {
    std::vector<uint32_t> out;
    const char* s = node.child_value();
    const char* end = s + std::strlen(s);
    while (s < end) {
      while (s < end && std::isspace((unsigned char)*s)) ++s;
      if (s >= end) break;
      uint32_t v;
      auto r = std::from_chars(s, end, v);
      if (r.ec != std::errc() || (r.ptr < end && !std::isspace((unsigned char)*r.ptr))) {
        const char* e = s;
        while (e < end && !std::isspace((unsigned char)*e)) ++e;
        fail(node, "'" + std::string(s, std::min<size_t>(e - s, 40)) + "' is not a non-negative integer index");
      }
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
  SceneDesc m_scene;
  Mat4 m_up;
};

SceneDesc Reader::read() {
  if (m_text.size() > m_limits.max_file_bytes)
    throw SceneError(m_name + ": " + std::to_string(m_text.size()) + " bytes, over the limit of " +
                     std::to_string(m_limits.max_file_bytes));
  // Elements and attributes, counted before pugixml builds a DOM node for each: millions of tiny
  // elements fail here in one pass over the text instead of after gigabytes of nodes.
  size_t markup = 0;
  for (size_t i = 0; i + 1 < m_text.size(); ++i)
    markup += (m_text[i] == '<' && m_text[i + 1] != '/') || m_text[i] == '=';
  if (markup > m_limits.max_markup)
    throw SceneError(m_name + ": more than " + std::to_string(m_limits.max_markup) + " XML elements and attributes");
  pugi::xml_parse_result res = m_doc.load_buffer(m_text.data(), m_text.size(), pugi::parse_default, pugi::encoding_auto);
  if (!res) {
    int line = 1 + int(std::count(m_text.begin(), m_text.begin() + std::min<size_t>(res.offset, m_text.size()), '\n'));
    throw SceneError(m_name + ":" + std::to_string(line) + ": XML error: " + res.description());
  }
  pugi::xml_node root = m_doc.document_element();
  if (std::string(root.name()) != "COLLADA")
    fail(root, "the root element must be <COLLADA>");
  m_scene.source = m_name;

  // Every element with an id can be referenced by url="#id".
  // Iterative walk (documents can nest deeply; recursion depth is bounded by pugixml's own parse).
  std::vector<pugi::xml_node> stack{root};
  if (auto id = root.attribute("id")) m_ids.emplace(id.value(), root);
  while (!stack.empty()) {
    pugi::xml_node n = stack.back();
    stack.pop_back();
    for (pugi::xml_node c = n.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      if (auto id = c.attribute("id")) m_ids.emplace(id.value(), c);
      stack.push_back(c);
    }
  }

  // Up axis: the world is Y-up internally (course mapping, see cs184-spec).
  m_up = Mat4::identity();
  if (pugi::xml_node asset = root.child("asset")) {
    if (pugi::xml_node up = asset.child("up_axis")) {
      std::string axis = up.child_value();
      axis.erase(0, axis.find_first_not_of(" \t\r\n"));
      axis.erase(axis.find_last_not_of(" \t\r\n") + 1);
      Mat4 m = Mat4::zero();
      m.m[3][3] = 1;
      if (axis == "Y_UP") {
        m = Mat4::identity();
      } else if (axis == "Z_UP") {  // (x, y, z) -> (-x, z, y)
        m.m[0][0] = -1; m.m[1][2] = 1; m.m[2][1] = 1;
      } else if (axis == "X_UP") {  // (x, y, z) -> (y, x, -z)
        m.m[0][1] = 1; m.m[1][0] = 1; m.m[2][2] = -1;
      } else {
        fail(up, "up_axis must be X_UP, Y_UP or Z_UP, got '" + clip(axis) + "'");
      }
      m_up = m;
    }
  }

  pugi::xml_node scene = root.child("scene");
  if (!scene) fail(root, "missing <scene>");
  pugi::xml_node ivs = scene.child("instance_visual_scene");
  if (!ivs) fail(scene, "missing <instance_visual_scene>");
  pugi::xml_node vs = lookup_url(ivs);
  if (std::string(vs.name()) != "visual_scene") fail(ivs, "url does not name a <visual_scene>");
  for (pugi::xml_node n : vs.children("node")) read_node(n, m_up, 0);

  if (m_scene.meshes.empty() && m_scene.spheres.empty() && m_scene.lights.empty())
    fail(vs, "the scene has no geometry and no lights");
  if (m_warnings > m_limits.max_warnings)
    std::fprintf(stderr, "warning: %s: %d more warnings not shown\n", m_name.c_str(), m_warnings - m_limits.max_warnings);
  return std::move(m_scene);
}

Mat4 Reader::read_local_transform(const pugi::xml_node& node) const {
  // COLLADA: transform elements apply in document order, each post-multiplied.
  Mat4 local = Mat4::identity();
  for (pugi::xml_node c = node.first_child(); c; c = c.next_sibling()) {
    std::string tag = c.name();
    Mat4 t = Mat4::identity();
    if (tag == "matrix") {
      auto v = numbers(c);
      if (v.size() > 16 || v.size() < 12) fail(c, "expected 16 numbers, found " + std::to_string(v.size()));
      if (v.size() < 16) warn(c, "only " + std::to_string(v.size()) + " numbers; the rest are read as 0");
      v.resize(16, 0.0);
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) t.m[i][j] = v[i * 4 + j];
    } else if (tag == "translate") {
      auto v = numbers(c);
      if (v.size() != 3) fail(c, "expected 3 numbers, found " + std::to_string(v.size()));
      t.m[0][3] = v[0]; t.m[1][3] = v[1]; t.m[2][3] = v[2];
    } else if (tag == "scale") {
      auto v = numbers(c);
      if (v.size() != 3) fail(c, "expected 3 numbers, found " + std::to_string(v.size()));
      t.m[0][0] = v[0]; t.m[1][1] = v[1]; t.m[2][2] = v[2];
    } else if (tag == "rotate") {  // axis x y z, angle in degrees (Rodrigues)
      auto v = numbers(c);
      if (v.size() != 4) fail(c, "expected 4 numbers (axis and degrees), found " + std::to_string(v.size()));
      double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      if (len == 0) fail(c, "rotation axis has zero length");
      double x = v[0] / len, y = v[1] / len, z = v[2] / len, a = v[3] * M_PI / 180.0;
      double cs = std::cos(a), sn = std::sin(a), ic = 1 - cs;
      double r[3][3] = {{cs + x * x * ic, x * y * ic - z * sn, x * z * ic + y * sn},
                        {y * x * ic + z * sn, cs + y * y * ic, y * z * ic - x * sn},
                        {z * x * ic - y * sn, z * y * ic + x * sn, cs + z * z * ic}};
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) t.m[i][j] = r[i][j];
    } else if (tag == "lookat") {  // eye, interest, up -> camera-to-world
      auto v = numbers(c);
      if (v.size() != 9) fail(c, "expected 9 numbers, found " + std::to_string(v.size()));
      Vec3 eye{float(v[0]), float(v[1]), float(v[2])}, at{float(v[3]), float(v[4]), float(v[5])},
          up{float(v[6]), float(v[7]), float(v[8])};
      Vec3 back = normalize(eye - at), right = normalize(cross(up, back));
      if (length(back) == 0 || length(right) == 0) fail(c, "degenerate lookat (eye = target or up parallel to view)");
      Vec3 u = cross(back, right);
      for (int i = 0; i < 3; ++i) {
        t.m[i][0] = right[i]; t.m[i][1] = u[i]; t.m[i][2] = back[i]; t.m[i][3] = eye[i];
      }
    } else if (tag == "skew") {
      warn(c, "<skew> is not supported and is ignored");
      continue;
    } else {
      continue;
    }
    local = local * t;
  }
  return local;
}

void Reader::read_node(const pugi::xml_node& node, const Mat4& parent, int depth) {
  if (depth > m_limits.max_node_depth) fail(node, "nodes nested deeper than " + std::to_string(m_limits.max_node_depth));
  if (++m_node_count > m_limits.max_nodes) fail(node, "more than " + std::to_string(m_limits.max_nodes) + " nodes");
  Mat4 world = parent * read_local_transform(node);
  if (!std::isfinite(world.det3())) fail(node, "transform is not finite");
  for (pugi::xml_node c = node.first_child(); c; c = c.next_sibling()) {
    std::string tag = c.name();
    if (tag == "node") read_node(c, world, depth + 1);
    else if (tag == "instance_node") {
      pugi::xml_node target = lookup_url(c);
      if (std::string(target.name()) != "node") fail(c, "url does not name a <node>");
      read_node(target, world, depth + 1);
    } else if (tag == "instance_camera") read_camera(c, world);
    else if (tag == "instance_light") read_light(c, world);
    else if (tag == "instance_geometry") read_geometry(c, world);
  }
}

void Reader::read_camera(const pugi::xml_node& inst, const Mat4& world) {
  pugi::xml_node cam = lookup_url(inst);
  if (std::string(cam.name()) != "camera") fail(inst, "url does not name a <camera>");
  pugi::xml_node persp = cam.child("optics").child("technique_common").child("perspective");
  if (!persp) fail(cam, "only <optics><technique_common><perspective> cameras are supported");
  CameraDesc c;
  c.present = true;
  c.xfov_deg = float(scalar_or(persp, "xfov", 0));
  c.yfov_deg = float(scalar_or(persp, "yfov", 0));
  c.aspect = float(scalar_or(persp, "aspect_ratio", 0));
  if (c.xfov_deg == 0 && c.yfov_deg == 0) c.xfov_deg = 50;
  if (c.yfov_deg == 0 && c.aspect <= 0) fail(persp, "needs <yfov> or <aspect_ratio>");
  // yfov alone is valid COLLADA (the course rejects only a camera with neither yfov nor aspect_ratio):
  // xfov stays 0 and the camera derives it from yfov and the image aspect.
  for (float f : {c.xfov_deg, c.yfov_deg})
    if (f < 0 || f >= 180) fail(persp, "field of view must be in (0, 180) degrees");
  c.znear = float(scalar_or(persp, "znear", 0.001));
  c.zfar = float(scalar_or(persp, "zfar", 1000));
  if (!(c.znear >= 0) || !(c.zfar > c.znear)) fail(persp, "needs 0 <= znear < zfar");
  c.world = world;
  m_scene.camera = c;  // with several cameras the last wins, as in the course
}

void Reader::read_light(const pugi::xml_node& inst, const Mat4& world) {
  pugi::xml_node light = lookup_url(inst);
  if (std::string(light.name()) != "light") fail(inst, "url does not name a <light>");
  pugi::xml_node tech;
  for (pugi::xml_node t : light.child("extra").children("technique"))
    if (std::string(t.attribute("profile").value()) == "CGL") tech = t;
  if (!tech) {
    for (pugi::xml_node t : light.child("profile_COMMON").children("technique"))
      if (std::string(t.attribute("sid").value()) == "common") tech = t;
  }
  if (!tech) tech = light.child("technique_common");
  if (!tech) fail(light, "no CGL or common technique");
  pugi::xml_node kind = tech.first_child();
  while (kind && kind.type() != pugi::node_element) kind = kind.next_sibling();
  if (!kind) fail(tech, "empty light technique");
  std::string type = kind.name();

  LightDesc l;
  l.name = light.attribute("id").value();
  l.color = color(kind, "color");
  Vec3 centre = world.point(Vec3(0, 0, 0));
  if (type == "area") {
    l.type = LightType::area;
    l.position = centre;
    l.direction = normalize(world.vector(Vec3(0, 0, -1)));
    l.dim_x = world.vector(Vec3(-1, 0, 0));
    l.dim_y = world.vector(Vec3(0, 1, 0));
    if (length(l.direction) == 0) fail(kind, "area light transform is degenerate");
  } else if (type == "point") {
    l.type = LightType::point;
    l.position = centre;
  } else if (type == "spot") {
    l.type = LightType::spot;
    l.position = centre;
    l.direction = normalize(world.vector(Vec3(0, 0, -1)));
    l.spot_angle_deg = float(scalar_or(kind, "falloff_angle", 180));
    l.spot_exponent = float(scalar_or(kind, "falloff_exponent", 0));
    if (!(l.spot_angle_deg > 0 && l.spot_angle_deg <= 360)) fail(kind, "falloff_angle must be in (0, 360] degrees");
    if (l.spot_exponent < 0) fail(kind, "falloff_exponent must not be negative");
    if (length(l.direction) == 0) fail(kind, "spot light transform is degenerate");
  } else if (type == "directional") {
    l.type = LightType::directional;
    // The course takes M * (0,0,-1) as the direction towards the light (cs184-spec (c); cow.dae is lit
    // from above), so light travels the opposite way; the translation the course folds in is dropped.
    l.direction = -normalize(world.vector(Vec3(0, 0, -1)));
    if (length(l.direction) == 0) fail(kind, "directional light transform is degenerate");
  } else if (type == "ambient") {
    l.type = LightType::ambient;
  } else {
    fail(kind, "unsupported light type '" + clip(type) + "' (area, point, spot, directional, ambient)");
  }
  m_scene.lights.push_back(l);
}

int Reader::default_material() {
  if (m_default_material < 0) {
    Material m;
    m.name = "default";
    m_default_material = int(m_scene.materials.size());
    m_scene.materials.push_back(m);
  }
  return m_default_material;
}

int Reader::resolve_material(const pugi::xml_node& inst_material) {
  pugi::xml_node mat = lookup_url(inst_material, "target");
  if (std::string(mat.name()) != "material") fail(inst_material, "target does not name a <material>");
  std::string id = mat.attribute("id").value();
  auto it = m_material_index.find(id);
  if (it != m_material_index.end()) return it->second;
  pugi::xml_node ie = mat.child("instance_effect");
  if (!ie) fail(mat, "missing <instance_effect>");
  pugi::xml_node effect = lookup_url(ie);
  if (std::string(effect.name()) != "effect") fail(ie, "url does not name an <effect>");
  Material m = read_effect(effect, id);
  int index = int(m_scene.materials.size());
  m_scene.materials.push_back(m);
  m_material_index.emplace(id, index);
  return index;
}

Material Reader::read_effect(const pugi::xml_node& effect, const std::string& name) const {
  Material m;
  m.name = name;
  pugi::xml_node cgl;
  for (pugi::xml_node t : effect.child("extra").children("technique"))
    if (std::string(t.attribute("profile").value()) == "CGL") cgl = t;
  bool found = false;
  // The last recognised CGL child defines the BSDF, as in the course parser.
  for (pugi::xml_node c = cgl.first_child(); c; c = c.next_sibling()) {
    std::string tag = c.name();
    Material n;
    n.name = name;
    if (tag == "emission") {
      n.type = MaterialType::emission;
      n.radiance = color(c, "radiance");
    } else if (tag == "mirror") {
      n.type = MaterialType::mirror;
      n.albedo = color(c, "reflectance");
    } else if (tag == "glass" || tag == "refraction") {
      n.type = tag == "glass" ? MaterialType::glass : MaterialType::refraction;
      n.transmittance = color(c, "transmittance");
      n.albedo = tag == "glass" ? color(c, "reflectance") : Vec3(0.0f);
      n.ior = float(scalar(c, "ior"));
      if (!(n.ior > 0)) fail(c.child("ior"), "ior must be positive");
    } else if (tag == "microfacet") {
      n.type = MaterialType::microfacet;
      n.alpha = float(scalar(c, "alpha"));
      n.eta = color(c, "eta");
      n.k = color(c, "k");
      if (!(n.alpha > 0)) fail(c.child("alpha"), "alpha must be positive");
    } else {
      continue;
    }
    m = n;
    found = true;
  }
  if (found) return m;
  // Common profile: the diffuse colour of phong / lambert / blinn; anything else is 0.5 grey.
  for (pugi::xml_node t : effect.child("profile_COMMON").children("technique")) {
    for (const char* shader : {"phong", "lambert", "blinn"}) {
      pugi::xml_node d = t.child(shader).child("diffuse");
      if (d && d.child("color")) {
        m.albedo = color(d, "color");
        return m;
      }
    }
  }
  return m;
}

void Reader::read_geometry(const pugi::xml_node& inst, const Mat4& world) {
  pugi::xml_node geom = lookup_url(inst);
  if (std::string(geom.name()) != "geometry") fail(inst, "url does not name a <geometry>");
  std::string name = geom.attribute("id").value();
  if (pugi::xml_node mesh = geom.child("mesh")) {
    read_mesh(mesh, inst, world, name);
    return;
  }
  pugi::xml_node sphere;
  for (pugi::xml_node t : geom.child("extra").children("technique"))
    if (std::string(t.attribute("profile").value()) == "CGL" && t.child("sphere")) sphere = t.child("sphere");
  if (!sphere) fail(geom, "neither a <mesh> nor a CGL <sphere>");
  SphereDesc s;
  s.name = name;
  s.center = world.point(Vec3(0, 0, 0));
  double r = scalar(sphere, "radius");
  if (!(r > 0)) fail(sphere.child("radius"), "sphere radius must be positive");
  s.radius = float(r * length(world.vector(Vec3(1, 0, 0))));
  if (!(s.radius > 0) || !std::isfinite(s.radius)) fail(sphere, "sphere transform gives a zero or infinite radius");
  pugi::xml_node im = inst.child("bind_material").child("technique_common").child("instance_material");
  s.material = im ? resolve_material(im) : default_material();
  m_scene.spheres.push_back(s);
}

void Reader::read_mesh(const pugi::xml_node& mesh, const pugi::xml_node& inst, const Mat4& world,
                       const std::string& name) {
  // Material bindings: symbol -> material index.
  std::unordered_map<std::string, int> bound;
  int first_bound = -1;
  for (pugi::xml_node im : inst.child("bind_material").child("technique_common").children("instance_material")) {
    int idx = resolve_material(im);
    bound.emplace(im.attribute("symbol").value(), idx);
    if (first_bound < 0) first_bound = idx;
  }

  pugi::xml_node vertices = mesh.child("vertices");
  if (!vertices) fail(mesh, "missing <vertices>");
  pugi::xml_node pos_input;
  for (pugi::xml_node in : vertices.children("input"))
    if (std::string(in.attribute("semantic").value()) == "POSITION") pos_input = in;
  if (!pos_input) fail(vertices, "missing <input semantic='POSITION'>");
  pugi::xml_node source = lookup_url(pos_input, "source");
  if (std::string(source.name()) != "source") fail(pos_input, "source does not name a <source>");
  pugi::xml_node fa = source.child("float_array");
  if (!fa) fail(source, "missing <float_array>");
  std::vector<double> raw = numbers(fa);
  if (auto count = fa.attribute("count")) {
    if (count.as_ullong() != raw.size())
      fail(fa, "count says " + clip(count.value()) + " but " + std::to_string(raw.size()) + " numbers are present");
  }
  size_t stride = 3;
  if (pugi::xml_node acc = source.child("technique_common").child("accessor")) {
    stride = acc.attribute("stride").as_uint(3);
    if (stride < 3) fail(acc, "position stride must be at least 3");
  }
  size_t vertex_count = raw.size() / stride;

  MeshDesc out;
  out.name = name;
  bool flip = world.det3() < 0;  // keep outward winding under mirroring transforms
  out.positions.resize(vertex_count);
  for (size_t i = 0; i < vertex_count; ++i)
    out.positions[i] = world.point(Vec3(float(raw[i * stride]), float(raw[i * stride + 1]), float(raw[i * stride + 2])));
  for (const Vec3& p : out.positions)
    if (!is_finite(p)) fail(fa, "vertex position overflows single precision after transform");

  auto add_polygon = [&](const uint32_t* idx, size_t n, int material, const pugi::xml_node& where) {
    for (size_t i = 0; i < n; ++i)
      if (idx[i] >= vertex_count)
        fail(where, "vertex index " + std::to_string(idx[i]) + " out of range (" + std::to_string(vertex_count) + " vertices)");
    // Fan triangulation; triangles that repeat a vertex are dropped.
    for (size_t i = 1; i + 1 < n; ++i) {
      uint32_t a = idx[0], b = idx[i], c = idx[i + 1];
      if (a == b || b == c || a == c) continue;
      if (flip) std::swap(b, c);
      out.indices.insert(out.indices.end(), {a, b, c});
      out.tri_material.push_back(material);
      if (++m_triangle_count > m_limits.max_triangles)
        fail(where, "more than " + std::to_string(m_limits.max_triangles) + " triangles");
    }
  };

  for (pugi::xml_node prim = mesh.first_child(); prim; prim = prim.next_sibling()) {
    std::string tag = prim.name();
    if (tag != "polylist" && tag != "triangles" && tag != "polygons") {
      if (tag == "lines" || tag == "linestrips" || tag == "trifans" || tag == "tristrips")
        warn(prim, "<" + tag + "> is not supported and is skipped");
      continue;
    }
    size_t offset_count = 0;
    long vertex_offset = -1;
    for (pugi::xml_node in : prim.children("input")) {
      long off = in.attribute("offset").as_int(0);
      if (off < 0 || off > 64) fail(in, "offset out of range");
      offset_count = std::max<size_t>(offset_count, size_t(off) + 1);
      if (std::string(in.attribute("semantic").value()) == "VERTEX") {
        if (lookup_url(in, "source") != vertices) fail(in, "VERTEX input must reference the mesh's <vertices>");
        vertex_offset = off;
      }
    }
    if (vertex_offset < 0) fail(prim, "missing <input semantic='VERTEX'>");
    int material = first_bound >= 0 ? first_bound : default_material();
    if (auto sym = prim.attribute("material")) {
      auto it = bound.find(sym.value());
      if (it != bound.end()) material = it->second;
    }
    std::vector<uint32_t> poly;
    auto vertex_indices = [&](const pugi::xml_node& p) {
      std::vector<uint32_t> all = indices(p);
      if (all.size() % offset_count != 0)
        fail(p, std::to_string(all.size()) + " indices is not a multiple of the " + std::to_string(offset_count) + " inputs");
      std::vector<uint32_t> v(all.size() / offset_count);
      for (size_t i = 0; i < v.size(); ++i) v[i] = all[i * offset_count + vertex_offset];
      return v;
    };
    if (tag == "polylist") {
      pugi::xml_node vc = prim.child("vcount"), p = prim.child("p");
      if (!vc) fail(prim, "missing <vcount>");
      if (!p) fail(prim, "missing <p>");
      std::vector<uint32_t> counts = indices(vc);
      std::vector<uint32_t> v = vertex_indices(p);
      size_t total = 0;
      for (uint32_t c : counts) {
        if (c < 3) fail(vc, "a polygon needs at least 3 vertices, found " + std::to_string(c));
        total += c;
      }
      if (total != v.size())
        fail(p, "<vcount> sums to " + std::to_string(total) + " vertices but <p> holds " + std::to_string(v.size()));
      size_t at = 0;
      for (uint32_t c : counts) {
        add_polygon(v.data() + at, c, material, p);
        at += c;
      }
    } else if (tag == "triangles") {
      pugi::xml_node p = prim.child("p");
      if (!p) fail(prim, "missing <p>");
      std::vector<uint32_t> v = vertex_indices(p);
      if (v.size() % 3 != 0) fail(p, "triangle list length is not a multiple of 3");
      for (size_t i = 0; i < v.size(); i += 3) add_polygon(v.data() + i, 3, material, p);
    } else {  // polygons: one <p> per polygon; <ph> holes keep their outer ring
      for (pugi::xml_node c = prim.first_child(); c; c = c.next_sibling()) {
        pugi::xml_node p;
        if (std::string(c.name()) == "p") p = c;
        else if (std::string(c.name()) == "ph") p = c.child("p");
        if (!p) continue;
        std::vector<uint32_t> v = vertex_indices(p);
        if (v.size() < 3) fail(p, "a polygon needs at least 3 vertices");
        add_polygon(v.data(), v.size(), material, p);
      }
    }
  }
  if (out.indices.empty()) {
    warn(mesh, "mesh has no triangles and is skipped");
    return;
  }
  compute_vertex_normals(out);
  m_scene.meshes.push_back(std::move(out));
}

}  // namespace

SceneDesc parse_collada(const std::string& text, const std::string& name, const LoadLimits& limits) {
  Reader r(text, name, limits);
  return r.read();
}

SceneDesc load_collada(const std::string& path, const LoadLimits& limits) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw SceneError(path + ": cannot open file");
  std::streamoff size = in.tellg();
  if (size < 0) throw SceneError(path + ": cannot read file");
  if (size_t(size) > limits.max_file_bytes)
    throw SceneError(path + ": file is " + std::to_string(size) + " bytes, over the limit of " +
                     std::to_string(limits.max_file_bytes));
  std::string text(size_t(size), '\0');
  in.seekg(0);
  if (!in.read(text.data(), size)) throw SceneError(path + ": cannot read file");
  return parse_collada(text, path, limits);
}

}  // namespace pt
