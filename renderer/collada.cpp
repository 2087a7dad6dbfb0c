// CS184 COLLADA reader: pugixml DOM -> SceneDesc, every error located by file, element and line.
// The dialect is described in scenes/README.md; deviations from the course parser in docs/cs184-compat.md.
#include "collada.h"

#include "collada_reader.h"
#include "scene_file.h"

namespace pt {
namespace collada_detail {

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
    fail(root, "not a COLLADA scene: the root element is <" + clip(root.name()) + ">, not <COLLADA>");
  m_scene.source = m_name;

  // Every element with an id can be referenced by url="#id".
  // Iterative walk (documents can nest deeply; recursion depth is bounded by pugixml's own parse).
  // With duplicate ids, references reach the first in document order (the walk visits children in
  // reverse, so later nodes are replaced by earlier ones).
  std::vector<pugi::xml_node> stack{root};
  std::vector<pugi::xml_node> with_id;
  while (!stack.empty()) {
    pugi::xml_node n = stack.back();
    stack.pop_back();
    if (n.attribute("id")) with_id.push_back(n);
    for (pugi::xml_node c = n.last_child(); c; c = c.previous_sibling())
      if (c.type() == pugi::node_element) stack.push_back(c);
  }
  for (const pugi::xml_node& n : with_id) {
    auto [it, fresh] = m_ids.emplace(n.attribute("id").value(), n);
    if (!fresh) warn(n, "duplicate id '" + clip(n.attribute("id").value()) + "': references reach the first, " + where(it->second));
  }
  // Parts of COLLADA the renderer has no use for: said once each, not silently dropped.
  for (const char* lib : {"library_animations", "library_controllers", "library_physics_scenes"})
    if (pugi::xml_node l = root.child(lib))
      if (l.first_child()) warn(l, std::string("<") + lib + "> is ignored (" +
                                   (lib[8] == 'a' ? "animations are not rendered: the scene as posed"
                                    : lib[8] == 'c' ? "skins and morphs: their meshes are not rendered"
                                                    : "physics is not simulated") + ")");

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
  if (!m_scene.camera.present)
    warn(vs, "no <instance_camera>: the course framing looks along -Z at the scene's bounding box");
  m_scene.warnings = std::move(m_warning_lines);
  if (m_warnings > m_limits.max_warnings) {
    m_scene.warnings.push_back(m_name + ": " + std::to_string(m_warnings - m_limits.max_warnings) + " more warnings not shown");
    std::fprintf(stderr, "warning: %s\n", m_scene.warnings.back().c_str());
  }
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
    else if (tag == "instance_controller") warn(c, "<instance_controller> (a skinned or morphed mesh) is not rendered");
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
    if (c.type() != pugi::node_element) continue;
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
      warn(c, "<" + clip(tag) + "> is not a CGL material (emission, mirror, glass, refraction, microfacet): skipped");
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
      if (d && d.child("texture")) {
        warn(d, "a diffuse texture is not read from COLLADA: rendered as the default 0.5 grey diffuse");
        return m;
      }
    }
  }
  warn(effect, "no CGL material and no phong, lambert or blinn diffuse colour: rendered as the default 0.5 grey diffuse");
  return m;
}

}  // namespace collada_detail

using collada_detail::Reader;

SceneDesc parse_collada(const std::string& text, const std::string& name, const LoadLimits& limits) {
  Reader r(text, name, limits);
  return r.read();
}

SceneDesc load_collada(const std::string& path, const LoadLimits& limits) {
  return parse_collada(read_scene_bytes(path, limits), path, limits);
}

}  // namespace pt
