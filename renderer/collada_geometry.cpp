// The COLLADA reader's geometry: <mesh> primitives (polylist, triangles, polygons) fanned into
// triangles, and the CGL <sphere> extension.
#include <string>
#include <unordered_map>
#include <vector>

#include "collada_reader.h"

namespace pt {
namespace collada_detail {

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
      else warn(prim, "material symbol '" + clip(sym.value()) + "' is not bound by an <instance_material>: " +
                (first_bound >= 0 ? "the first bound material is used" : "rendered as the default 0.5 grey diffuse"));
    }
    // A count that disagrees with the data: the data is rendered, and the disagreement said.
    auto check_count = [&](size_t found) {
      if (auto count = prim.attribute("count"))
        if (count.as_ullong() != found)
          warn(prim, "count says " + clip(count.value()) + " but the data holds " + std::to_string(found) + "; the data is used");
    };
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
      check_count(counts.size());
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
      check_count(v.size() / 3);
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

}  // namespace collada_detail
}  // namespace pt
