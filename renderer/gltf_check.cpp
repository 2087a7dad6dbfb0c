// The glTF checks of materials, meshes, the node hierarchy, scenes, cameras, lights, skins and
// animations (gltf_check.h), and the JSON parse within the limits that runs them all.
#include "gltf_check.h"

namespace pt::gltf_detail {

void Checker::materials() {
  const json* list = array(m_doc, "materials", "");
  if (!list) return;
  for (size_t i = 0; i < list->size(); ++i) {
    const json& m = (*list)[i];
    const std::string path = "/materials/" + std::to_string(i);
    if (const json* pbr = object(m, "pbrMetallicRoughness", path)) {
      const std::string at = path + "/pbrMetallicRoughness";
      numbers(*pbr, "baseColorFactor", at, 4, 0, 1);
      number(*pbr, "metallicFactor", at, false, 0, 1);
      number(*pbr, "roughnessFactor", at, false, 0, 1);
      texture_info(*pbr, "baseColorTexture", at, true);
      texture_info(*pbr, "metallicRoughnessTexture", at, true);
    }
    texture_info(m, "normalTexture", path, true);
    texture_info(m, "occlusionTexture", path);  // a path tracer finds occlusion itself
    texture_info(m, "emissiveTexture", path, true);
    numbers(m, "emissiveFactor", path, 3, 0, 1);
    string(m, "alphaMode", path);
    number(m, "alphaCutoff", path, false, 0, HUGE_VAL);
    boolean(m, "doubleSided", path);
    if (const json* ext = object(m, "extensions", path)) {
      const std::string at = path + "/extensions";
      if (const json* e = object(*ext, "KHR_materials_emissive_strength", at))
        number(*e, "emissiveStrength", at + "/KHR_materials_emissive_strength", false, 0, 1e30);
      if (const json* e = object(*ext, "KHR_materials_transmission", at)) {
        number(*e, "transmissionFactor", at + "/KHR_materials_transmission", false, 0, 1);
        texture_info(*e, "transmissionTexture", at + "/KHR_materials_transmission", true);
      }
      if (const json* e = object(*ext, "KHR_materials_specular", at)) {
        number(*e, "specularFactor", at + "/KHR_materials_specular", false, 0, 1);
        numbers(*e, "specularColorFactor", at + "/KHR_materials_specular", 3, 0, 1e3);
        texture_info(*e, "specularTexture", at + "/KHR_materials_specular", true);
        texture_info(*e, "specularColorTexture", at + "/KHR_materials_specular", true);
      }
      if (const json* e = object(*ext, "KHR_materials_clearcoat", at)) {
        const std::string c = at + "/KHR_materials_clearcoat";
        number(*e, "clearcoatFactor", c, false, 0, 1);
        number(*e, "clearcoatRoughnessFactor", c, false, 0, 1);
        texture_info(*e, "clearcoatTexture", c, true);
        texture_info(*e, "clearcoatRoughnessTexture", c, true);
        texture_info(*e, "clearcoatNormalTexture", c, true);
      }
      if (const json* e = object(*ext, "KHR_materials_sheen", at)) {
        const std::string s = at + "/KHR_materials_sheen";
        numbers(*e, "sheenColorFactor", s, 3, 0, 1);
        number(*e, "sheenRoughnessFactor", s, false, 0, 1);
        texture_info(*e, "sheenColorTexture", s, true);
        texture_info(*e, "sheenRoughnessTexture", s, true);
      }
      if (const json* e = object(*ext, "KHR_materials_volume", at)) {
        const std::string v = at + "/KHR_materials_volume";
        number(*e, "thicknessFactor", v, false, 0, HUGE_VAL);
        if (number(*e, "attenuationDistance", v, false, 0, HUGE_VAL, 1) <= 0)
          fail(v + "/attenuationDistance", "must be above 0");
        numbers(*e, "attenuationColor", v, 3, 0, 1);
        texture_info(*e, "thicknessTexture", v);
      }
      object(*ext, "KHR_materials_unlit", at);
      if (const json* e = object(*ext, "KHR_materials_ior", at)) {
        double ior = number(*e, "ior", at + "/KHR_materials_ior", false, 0, 1e3, 1.5);
        if (ior != 0 && ior < 1) fail(at + "/KHR_materials_ior/ior", "must be 0 or at least 1");
      }
    }
  }
}

void Checker::meshes() {
  const json* list = array(m_doc, "meshes", "");
  if (!list) return;
  for (size_t i = 0; i < list->size(); ++i) {
    const std::string path = "/meshes/" + std::to_string(i);
    const json* prims = array((*list)[i], "primitives", path);
    if (!prims || prims->empty()) fail(path, "needs a non-empty 'primitives' array");
    numbers((*list)[i], "weights", path, 0);
    for (size_t p = 0; p < prims->size(); ++p) {
      const json& prim = (*prims)[p];
      const std::string at = path + "/primitives/" + std::to_string(p);
      const json* attrs = object(prim, "attributes", at, true);
      for (auto it = attrs->begin(); it != attrs->end(); ++it) index(*attrs, it.key().c_str(), at + "/attributes", "accessors", true);
      index(prim, "indices", at, "accessors");
      index(prim, "material", at, "materials");
      integer(prim, "mode", at, false, 0, 6, 4);
      if (const json* targets = array(prim, "targets", at)) {
        for (size_t t = 0; t < targets->size(); ++t)
          for (auto it = (*targets)[t].begin(); it != (*targets)[t].end(); ++it)
            index((*targets)[t], it.key().c_str(), at + "/targets/" + std::to_string(t), "accessors", true);
      }
    }
  }
}

void Checker::nodes_and_scenes() {
  const size_t n = count("nodes");
  size_t lights = 0;
  if (const json* ext = object(m_doc, "extensions", ""))
    if (const json* punctual = object(*ext, "KHR_lights_punctual", "/extensions"))
      if (const json* list = array(*punctual, "lights", "/extensions/KHR_lights_punctual")) lights = list->size();
  std::vector<int64_t> parent(n, -1);
  if (const json* list = array(m_doc, "nodes", "")) {
    for (size_t i = 0; i < n; ++i) {
      const json& node = (*list)[i];
      const std::string path = "/nodes/" + std::to_string(i);
      index(node, "mesh", path, "meshes");
      index(node, "camera", path, "cameras");
      index(node, "skin", path, "skins");
      numbers(node, "matrix", path, 16);
      numbers(node, "translation", path, 3);
      numbers(node, "rotation", path, 4, -1, 1);
      numbers(node, "scale", path, 3);
      numbers(node, "weights", path, 0);
      if (node.contains("matrix") && (node.contains("translation") || node.contains("rotation") || node.contains("scale")))
        fail(path, "has both 'matrix' and translation / rotation / scale");
      if (const json* children = array(node, "children", path, false)) {
        for (size_t j = 0; j < children->size(); ++j) {
          const std::string at = path + "/children/" + std::to_string(j);
          const json& c = (*children)[j];
          if (!c.is_number_integer() || c.get<int64_t>() < 0 || c.get<uint64_t>() >= n)
            fail(at, "must be the index of a node (" + std::to_string(n) + ")");
          size_t child = c.get<size_t>();
          if (child == i) fail(at, "node " + std::to_string(i) + " is its own child");
          if (parent[child] >= 0)
            fail(at, "node " + std::to_string(child) + " already has a parent (node " + std::to_string(parent[child]) +
                         "): the nodes must form trees");
          parent[child] = int64_t(i);
        }
      }
      if (const json* ext = object(node, "extensions", path))
        if (const json* l = object(*ext, "KHR_lights_punctual", path + "/extensions")) {
          const std::string at = path + "/extensions/KHR_lights_punctual";
          int64_t li = integer(*l, "light", at, true, 0, INT32_MAX);
          if (size_t(li) >= lights) fail(at + "/light", std::to_string(li) + " names no KHR_lights_punctual light (" + std::to_string(lights) + ")");
        }
    }
  }
  // With one parent each, a cycle is a walk up the parents that comes back: each node is walked
  // once (stamp: the walk that reached it).
  std::vector<size_t> stamp(n, SIZE_MAX);
  for (size_t i = 0; i < n; ++i) {
    size_t at = i;
    while (stamp[at] == SIZE_MAX) {
      stamp[at] = i;
      if (parent[at] < 0) break;
      at = size_t(parent[at]);
      if (stamp[at] == i) fail("/nodes/" + std::to_string(at), "is its own ancestor: the node hierarchy has a cycle");
    }
  }
  if (const json* list = array(m_doc, "scenes", "")) {
    for (size_t i = 0; i < list->size(); ++i) {
      const std::string path = "/scenes/" + std::to_string(i);
      const json* roots = array((*list)[i], "nodes", path, false);
      if (!roots) continue;
      for (size_t j = 0; j < roots->size(); ++j) {
        const std::string at = path + "/nodes/" + std::to_string(j);
        const json& r = (*roots)[j];
        if (!r.is_number_integer() || r.get<int64_t>() < 0 || r.get<uint64_t>() >= n)
          fail(at, "must be the index of a node (" + std::to_string(n) + ")");
        if (parent[r.get<size_t>()] >= 0)
          fail(at, "node " + std::to_string(r.get<size_t>()) + " is a child of node " + std::to_string(parent[r.get<size_t>()]) +
                       ", not a root");
      }
    }
  }
  index(m_doc, "scene", "", "scenes");
}

void Checker::cameras_and_lights() {
  if (const json* list = array(m_doc, "cameras", "")) {
    for (size_t i = 0; i < list->size(); ++i) {
      const json& c = (*list)[i];
      const std::string path = "/cameras/" + std::to_string(i);
      const std::string type = string(c, "type", path, true);
      if (type == "perspective") {
        const json* p = object(c, "perspective", path, true);
        const std::string at = path + "/perspective";
        number(*p, "yfov", at, true, 1e-6, 3.14159);
        double znear = number(*p, "znear", at, true, 0, 1e30);
        if (p->contains("zfar") && number(*p, "zfar", at, true, 0, HUGE_VAL) <= znear) fail(at + "/zfar", "must exceed znear");
        number(*p, "aspectRatio", at, false, 1e-6, 1e6);
      } else if (type == "orthographic") {
        const json* o = object(c, "orthographic", path, true);
        for (const char* key : {"xmag", "ymag", "zfar", "znear"}) number(*o, key, path + "/orthographic", true, -1e30, 1e30);
      } else {
        fail(path + "/type", "'" + clip(printable(type)) + "' is not perspective or orthographic");
      }
    }
  }
  const json* ext = object(m_doc, "extensions", "");
  const json* punctual = ext ? object(*ext, "KHR_lights_punctual", "/extensions") : nullptr;
  const json* list = punctual ? array(*punctual, "lights", "/extensions/KHR_lights_punctual") : nullptr;
  if (!list) return;
  for (size_t i = 0; i < list->size(); ++i) {
    const json& l = (*list)[i];
    const std::string path = "/extensions/KHR_lights_punctual/lights/" + std::to_string(i);
    const std::string type = string(l, "type", path, true);
    if (type != "point" && type != "spot" && type != "directional")
      fail(path + "/type", "'" + clip(printable(type)) + "' is not point, spot or directional");
    numbers(l, "color", path, 3, 0, 1e6);
    number(l, "intensity", path, false, 0, 1e30);
    number(l, "range", path, false, 1e-30, HUGE_VAL);
    if (type == "spot") {
      const json* spot = object(l, "spot", path, true);
      double outer = number(*spot, "outerConeAngle", path + "/spot", false, 1e-6, 1.5707964, 0.7853981634);
      number(*spot, "innerConeAngle", path + "/spot", false, 0, outer - 1e-9, 0);
    }
  }
}

void Checker::skins_and_animations() {
  if (const json* list = array(m_doc, "skins", "")) {
    for (size_t i = 0; i < list->size(); ++i) {
      const std::string path = "/skins/" + std::to_string(i);
      const json* joints = array((*list)[i], "joints", path, false);
      if (!joints || joints->empty()) fail(path, "needs a non-empty 'joints' array");
      for (size_t j = 0; j < joints->size(); ++j)
        if (!(*joints)[j].is_number_integer() || (*joints)[j].get<int64_t>() < 0 || (*joints)[j].get<uint64_t>() >= count("nodes"))
          fail(path + "/joints/" + std::to_string(j), "must be the index of a node");
      index((*list)[i], "inverseBindMatrices", path, "accessors");
      index((*list)[i], "skeleton", path, "nodes");
    }
  }
  if (const json* list = array(m_doc, "animations", "")) {
    for (size_t i = 0; i < list->size(); ++i) {
      const std::string path = "/animations/" + std::to_string(i);
      const json* samplers = array((*list)[i], "samplers", path);
      const json* channels = array((*list)[i], "channels", path);
      if (!samplers || !channels) fail(path, "needs 'samplers' and 'channels' arrays");
      for (size_t s = 0; s < samplers->size(); ++s) {
        const std::string at = path + "/samplers/" + std::to_string(s);
        index((*samplers)[s], "input", at, "accessors", true);
        index((*samplers)[s], "output", at, "accessors", true);
        string((*samplers)[s], "interpolation", at);
      }
      for (size_t c = 0; c < channels->size(); ++c) {
        const std::string at = path + "/channels/" + std::to_string(c);
        integer((*channels)[c], "sampler", at, true, 0, int64_t(samplers->size()) - 1);
        const json* target = object((*channels)[c], "target", at, true);
        index(*target, "node", at + "/target", "nodes");
        string(*target, "path", at + "/target", true);
      }
    }
  }
}

Checked Checker::run() {
  asset_and_extensions();
  buffers();
  accessors();
  images_and_textures();
  materials();
  meshes();
  nodes_and_scenes();
  cameras_and_lights();
  skins_and_animations();
  return m_checked;
}

Checked check_json(const Context& ctx, const Parts& parts) {
  size_t values = 0;
  // Counted as they parse: a file of millions of tiny values or deep nesting stops here, before
  // it is held (tinygltf also walks extras recursively).
  auto limit = [&](int depth, json::parse_event_t event, json&) {
    if (depth > ctx.limits.max_json_depth)
      throw SceneError(ctx.name + ": JSON nested deeper than " + std::to_string(ctx.limits.max_json_depth) + " levels");
    if (event != json::parse_event_t::key && event != json::parse_event_t::object_end &&
        event != json::parse_event_t::array_end && ++values > ctx.limits.max_json_values)
      throw SceneError(ctx.name + ": more than " + std::to_string(ctx.limits.max_json_values) + " JSON values");
    return true;
  };
  json doc;
  try {
    doc = json::parse(parts.json.begin(), parts.json.end(), limit);
  } catch (const json::exception& e) {  // a syntax error, or a number too large for a double
    std::string what = e.what();
    size_t bracket = what.find("] ");
    throw SceneError(ctx.name + ": JSON error: " + printable(bracket == std::string::npos ? what : what.substr(bracket + 2)));
  }
  if (!doc.is_object()) ctx.fail("", "the JSON root must be an object");
  return Checker(ctx, doc, parts.bin_size).run();
}

}  // namespace pt::gltf_detail
