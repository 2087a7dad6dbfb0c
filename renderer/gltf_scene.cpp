// glTF nodes -> SceneDesc: the hierarchy with its transforms (matrix or TRS), TRIANGLES primitives
// read through their accessors (float or quantized), cameras and KHR_lights_punctual lights; the
// entry point parse_gltf that runs the reader's stages. Mapping choices: docs/gltf.md.
#include <cmath>
#include <cstring>

#include "gltf_reader.h"

namespace pt::gltf_detail {

namespace {

constexpr double kDeg = 180.0 / 3.14159265358979323846;

// A light or camera axis from a node's world transform (glTF: both look along local -Z).
Vec3 local_minus_z(const Mat4& world) { return normalize(world.vector(Vec3(0, 0, -1))); }

bool finite(const Mat4& m) {
  for (const auto& row : m.m)
    for (double v : row)
      if (!std::isfinite(v)) return false;
  return true;
}

// One component of an attribute as a float: normalized integers mapped to [0, 1] or [-1, 1]
// (glTF 2.0, 3.11; KHR_mesh_quantization).
float component(int type, bool norm, const uint8_t* q) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float v; std::memcpy(&v, q, 4); return v; }
    case TINYGLTF_COMPONENT_TYPE_BYTE: { int8_t x; std::memcpy(&x, q, 1); return norm ? std::max(x / 127.0f, -1.0f) : x; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return norm ? *q / 255.0f : *q;
    case TINYGLTF_COMPONENT_TYPE_SHORT: { int16_t x; std::memcpy(&x, q, 2); return norm ? std::max(x / 32767.0f, -1.0f) : x; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t x; std::memcpy(&x, q, 2); return norm ? x / 65535.0f : x; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t x; std::memcpy(&x, q, 4); return float(x); }
  }
  return 0;
}

uint32_t index_value(int csize, const uint8_t* p) {
  if (csize == 1) return *p;
  if (csize == 2) { uint16_t x; std::memcpy(&x, p, 2); return x; }
  uint32_t x;
  std::memcpy(&x, p, 4);
  return x;
}

class Builder {
 public:
  Builder(const Context& ctx, const tinygltf::Model& model, Images& images)
      : m_ctx(ctx), m_model(model), m_materials(ctx, model, images, m_desc) {}

  SceneDesc run();

 private:
  [[noreturn]] void fail(const std::string& path, const std::string& msg) const { m_ctx.fail(path, msg); }
  Mat4 local_transform(const tinygltf::Node& node, const std::string& path) const;
  void visit(int index, const Mat4& parent, int depth);
  void add_primitive(const tinygltf::Primitive& prim, const Mat4& world, const std::string& path, const std::string& name);
  void add_camera(const tinygltf::Node& node, const Mat4& world, const std::string& path);
  // A normal-mapped mesh's tangents: the file's TANGENT (world space), else generated from the
  // normal map's uv set (compute_tangents); none without texture coordinates.
  void add_tangents(MeshDesc& mesh, int tangent_accessor, bool has_uvs, int set, const Mat4& world, const std::string& apath);
  void add_light(int index, const Mat4& world, const std::string& path);
  // Accessor `index` (at `path`, which names it) as `n` floats an element, normalized integers
  // mapped to [0, 1] or [-1, 1] (glTF 2.0, 3.11; KHR_mesh_quantization); `ncomp` lists the
  // accessor types it may have (components). Counts every value against the limit.
  std::vector<float> read_floats(int index, const std::string& path, std::initializer_list<int> ncomp, int& got) const;
  std::vector<uint32_t> read_indices(int index, const std::string& path) const;
  const uint8_t* element_data(const tinygltf::Accessor& a, const std::string& path, size_t elem, size_t& stride) const;
  // A sparse accessor's substitutions (glTF 2.0, 3.6.2.3): calls put(element, bytes of its value)
  // for each, after checking that the indices increase strictly and stay below the count.
  template <class Put>
  void for_each_sparse(const tinygltf::Accessor& a, const std::string& path, size_t elem, Put&& put) const;
  const uint8_t* view_bytes(int view, size_t offset, size_t bytes, const std::string& path) const;
  void count_values(size_t n, const std::string& path) const {
    m_values += n;
    if (m_values > m_ctx.limits.max_values)
      fail(path, "more than " + std::to_string(m_ctx.limits.max_values) + " numbers read (instancing included)");
  }

  const Context& m_ctx;
  const tinygltf::Model& m_model;
  SceneDesc m_desc;
  MaterialMaker m_materials;
  mutable size_t m_values = 0;
  size_t m_nodes = 0, m_triangles = 0;
};

Mat4 Builder::local_transform(const tinygltf::Node& node, const std::string& path) const {
  Mat4 m;
  if (node.matrix.size() == 16) {  // column-major
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m.m[r][c] = node.matrix[size_t(c * 4 + r)];
    return m;
  }
  // T * R * S (glTF 2.0, 3.5.3); the rotation is a unit quaternion (x, y, z, w).
  Mat4 t, r, s;
  if (node.translation.size() == 3)
    for (int i = 0; i < 3; ++i) t.m[i][3] = node.translation[size_t(i)];
  if (node.scale.size() == 3)
    for (int i = 0; i < 3; ++i) s.m[i][i] = node.scale[size_t(i)];
  if (node.rotation.size() == 4) {
    double x = node.rotation[0], y = node.rotation[1], z = node.rotation[2], w = node.rotation[3];
    double len = std::sqrt(x * x + y * y + z * z + w * w);
    if (!(len > 1e-6)) fail(path + "/rotation", "is not a rotation (a quaternion of length 0)");
    x /= len, y /= len, z /= len, w /= len;
    double q[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                      {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                      {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r.m[i][j] = q[i][j];
  }
  return t * r * s;
}

const uint8_t* Builder::element_data(const tinygltf::Accessor& a, const std::string& path, size_t elem, size_t& stride) const {
  if (a.bufferView < 0) return nullptr;  // all zeros (glTF 2.0, 3.6.2.3), or a sparse accessor's base
  const tinygltf::BufferView& view = m_model.bufferViews[size_t(a.bufferView)];
  const tinygltf::Buffer& buffer = m_model.buffers[size_t(view.buffer)];
  stride = view.byteStride ? view.byteStride : elem;
  // The checks placed every element inside the view; the view inside the data tinygltf holds.
  const size_t begin = view.byteOffset + a.byteOffset, end = begin + stride * (a.count - 1) + elem;
  if (view.byteOffset + view.byteLength > buffer.data.size() || end > view.byteOffset + view.byteLength)
    fail(path, "the accessor's bytes lie outside its buffer");
  return buffer.data.data() + begin;
}

const uint8_t* Builder::view_bytes(int view_index, size_t offset, size_t bytes, const std::string& path) const {
  const tinygltf::BufferView& view = m_model.bufferViews[size_t(view_index)];
  const tinygltf::Buffer& buffer = m_model.buffers[size_t(view.buffer)];
  if (view.byteOffset + view.byteLength > buffer.data.size() || offset > view.byteLength || bytes > view.byteLength - offset)
    fail(path, std::to_string(bytes) + " bytes from byte " + std::to_string(offset) + " lie outside bufferView " +
                   std::to_string(view_index) + " (" + std::to_string(view.byteLength) + " bytes)");
  return buffer.data.data() + view.byteOffset + offset;
}

template <class Put>
void Builder::for_each_sparse(const tinygltf::Accessor& a, const std::string& path, size_t elem, Put&& put) const {
  if (!a.sparse.isSparse) return;
  const auto& sp = a.sparse;
  const std::string at = path + "/sparse";
  if (sp.count <= 0 || size_t(sp.count) > a.count)
    fail(at + "/count", std::to_string(sp.count) + " substitutions for " + std::to_string(a.count) + " elements");
  count_values(size_t(sp.count), at);
  const int isize = sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? 1
                    : sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 2
                                                                                         : 4;
  const size_t n = size_t(sp.count);
  const uint8_t* idx = view_bytes(sp.indices.bufferView, size_t(sp.indices.byteOffset), n * size_t(isize), at + "/indices");
  const uint8_t* val = view_bytes(sp.values.bufferView, size_t(sp.values.byteOffset), n * elem, at + "/values");
  int64_t last = -1;
  for (size_t k = 0; k < n; ++k) {
    const uint32_t i = index_value(isize, idx + k * size_t(isize));
    if (i >= a.count)
      fail(at + "/indices", "index " + std::to_string(i) + " (element " + std::to_string(k) + ") is out of range: the accessor has " +
                                std::to_string(a.count) + " elements");
    if (int64_t(i) <= last)
      fail(at + "/indices", "index " + std::to_string(i) + " (element " + std::to_string(k) + ") does not increase strictly");
    last = i;
    put(size_t(i), val + k * elem);
  }
}

std::vector<float> Builder::read_floats(int index, const std::string& path, std::initializer_list<int> ncomp, int& got) const {
  const tinygltf::Accessor& a = m_model.accessors[size_t(index)];
  const std::string at = path + " (accessor " + std::to_string(index) + ")";
  int n = tinygltf::GetNumComponentsInType(uint32_t(a.type));
  bool ok = a.type != TINYGLTF_TYPE_MAT2 && a.type != TINYGLTF_TYPE_MAT3 && a.type != TINYGLTF_TYPE_MAT4;
  bool listed = false;
  for (int c : ncomp) listed |= c == n;
  if (!ok || !listed) fail(at, "has the wrong type for this attribute");
  int csize = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
  if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) fail(at, "32-bit integers are not an attribute type");
  got = n;
  count_values(a.count * size_t(n), at);
  std::vector<float> out(a.count * size_t(n), 0.0f);
  size_t stride = 0;
  const uint8_t* p = element_data(a, at, size_t(n * csize), stride);
  const bool norm = a.normalized;
  auto decode = [&](size_t i, const uint8_t* q) {
    for (int c = 0; c < n; ++c) {
      const float v = component(a.componentType, norm, q + c * csize);
      if (!std::isfinite(v)) fail(at, "element " + std::to_string(i) + " is not finite (NaN or infinity)");
      out[i * size_t(n) + size_t(c)] = v;
    }
  };
  if (p)
    for (size_t i = 0; i < a.count; ++i, p += stride) decode(i, p);
  for_each_sparse(a, at, size_t(n * csize), decode);
  return out;
}

std::vector<uint32_t> Builder::read_indices(int index, const std::string& path) const {
  const tinygltf::Accessor& a = m_model.accessors[size_t(index)];
  const std::string at = path + " (accessor " + std::to_string(index) + ")";
  if (a.type != TINYGLTF_TYPE_SCALAR) fail(at, "indices must be SCALAR");
  int csize = 0;
  switch (a.componentType) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: csize = 1; break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: csize = 2; break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: csize = 4; break;
    default: fail(at, "indices must be unsigned bytes, shorts or ints");
  }
  count_values(a.count, at);
  std::vector<uint32_t> out(a.count, 0);
  size_t stride = 0;
  const uint8_t* p = element_data(a, at, size_t(csize), stride);
  if (p)
    for (size_t i = 0; i < a.count; ++i, p += stride) out[i] = index_value(csize, p);
  for_each_sparse(a, at, size_t(csize), [&](size_t i, const uint8_t* q) { out[i] = index_value(csize, q); });
  return out;
}

void Builder::add_primitive(const tinygltf::Primitive& prim, const Mat4& world, const std::string& path,
                            const std::string& name) {
  const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  if (mode != TINYGLTF_MODE_TRIANGLES) {
    static const char* const names[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP", "TRIANGLES", "TRIANGLE_STRIP", "TRIANGLE_FAN"};
    const std::string mode_name = mode >= 0 && mode <= 6 ? names[mode] : "?";
    m_ctx.warn("mode " + std::to_string(mode), path + "/mode",
               "primitive mode " + std::to_string(mode) + " (" + mode_name + ") is not supported: such primitives are skipped");
    return;
  }
  auto attr = [&](const char* key) {
    auto it = prim.attributes.find(key);
    return it == prim.attributes.end() ? -1 : it->second;
  };
  if (attr("POSITION") < 0) {
    m_ctx.warn("no POSITION", path, "a primitive without POSITION is skipped");
    return;
  }
  if (!prim.targets.empty()) m_ctx.warn("morph targets", path + "/targets", "morph targets are ignored");
  MeshDesc mesh;
  mesh.name = name;
  int n = 0;
  const std::string apath = path + "/attributes/";
  std::vector<float> pos = read_floats(attr("POSITION"), apath + "POSITION", {3}, n);
  const size_t nv = pos.size() / 3;
  mesh.positions.resize(nv);
  for (size_t v = 0; v < nv; ++v) {
    mesh.positions[v] = world.point(Vec3(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]));
    if (!is_finite(mesh.positions[v]))
      fail(apath + "POSITION", "vertex " + std::to_string(v) + " is not finite after the node's transform");
  }
  // Indices, or every three vertices a triangle.
  if (prim.indices >= 0) {
    mesh.indices = read_indices(prim.indices, path + "/indices");
    for (size_t i = 0; i < mesh.indices.size(); ++i)
      if (mesh.indices[i] >= nv)
        fail(path + "/indices", "index " + std::to_string(mesh.indices[i]) + " (element " + std::to_string(i) +
                                    ") is out of range: POSITION has " + std::to_string(nv) + " vertices");
  } else {
    mesh.indices.resize(nv);
    for (size_t v = 0; v < nv; ++v) mesh.indices[v] = uint32_t(v);
  }
  if (mesh.indices.size() % 3) {
    m_ctx.warn("partial triangle", prim.indices >= 0 ? path + "/indices" : apath + "POSITION",
               std::to_string(mesh.indices.size()) + " vertices of TRIANGLES is not a multiple of 3: the last ones are ignored");
    mesh.indices.resize(mesh.indices.size() / 3 * 3);
  }
  const size_t tris = mesh.indices.size() / 3;
  m_triangles += tris;
  if (m_triangles > m_ctx.limits.max_triangles)
    fail(path, "more than " + std::to_string(m_ctx.limits.max_triangles) + " triangles (instancing included)");
  // A mirroring transform turns the winding, and glTF's front faces with it (3.7.2.1).
  if (world.det3() < 0)
    for (size_t t = 0; t < tris; ++t) std::swap(mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]);
  auto same_count = [&](const char* key, size_t count) {
    if (count != nv)
      fail(apath + key, std::to_string(count) + " elements, POSITION has " + std::to_string(nv));
  };
  if (attr("NORMAL") >= 0) {
    std::vector<float> nrm = read_floats(attr("NORMAL"), apath + "NORMAL", {3}, n);
    same_count("NORMAL", nrm.size() / 3);
    mesh.normals.resize(nv);
    for (size_t v = 0; v < nv; ++v) mesh.normals[v] = normalize(world.normal(Vec3(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2])));
  }
  const int mat = m_materials.material(prim.material, attr("COLOR_0") >= 0, path + "/material");
  const PbrParams& pm = m_desc.materials[size_t(mat)].pbr;
  for (int set = 0; set < 2; ++set) {
    bool read = false;
    for (const TextureRef* r : pm.texture_refs())
      read |= r->used() && r->set == set;
    if (!read) continue;
    const std::string key = "TEXCOORD_" + std::to_string(set);
    std::vector<Vec2>& uvs = set == 0 ? mesh.uvs : mesh.uvs1;
    uvs.assign(nv, Vec2{});
    if (attr(key.c_str()) >= 0) {
      std::vector<float> uv = read_floats(attr(key.c_str()), apath + key, {2}, n);
      same_count(key.c_str(), uv.size() / 2);
      for (size_t v = 0; v < nv; ++v) uvs[v] = Vec2{uv[2 * v], uv[2 * v + 1]};
    } else {
      m_ctx.warn("no " + key, apath + key, "missing: the material's textures are read at uv (0, 0)" +
                                               std::string(pm.normal_tex.used() ? ", and its normal map is ignored" : ""));
    }
  }
  if (pm.vertex_color) {
    std::vector<float> c = read_floats(attr("COLOR_0"), apath + "COLOR_0", {3, 4}, n);
    same_count("COLOR_0", c.size() / size_t(n));
    mesh.colors.resize(nv);
    for (size_t v = 0; v < nv; ++v) mesh.colors[v] = Vec3(c[size_t(n) * v], c[size_t(n) * v + 1], c[size_t(n) * v + 2]);
    bool translucent = false;  // COLOR_0's alpha multiplies the base colour's (glTF 2.0, 3.9.2)
    for (size_t v = 0; n == 4 && pm.alpha_tested() && v < nv; ++v) translucent |= c[4 * v + 3] < 1;
    if (translucent) {
      mesh.color_alpha.resize(nv);
      for (size_t v = 0; v < nv; ++v) mesh.color_alpha[v] = c[4 * v + 3];
    }
  }
  if (const TextureRef* t = pm.tangent_space_tex())
    add_tangents(mesh, attr("TANGENT"), attr(("TEXCOORD_" + std::to_string(t->set)).c_str()) >= 0, t->set, world, apath);
  mesh.tri_material.assign(tris, mat);
  if (tris) m_desc.meshes.push_back(std::move(mesh));
}

void Builder::add_tangents(MeshDesc& mesh, int tangent_accessor, bool has_uvs, int set, const Mat4& world,
                           const std::string& apath) {
  const size_t nv = mesh.positions.size();
  if (!has_uvs) {  // warned: the normal map is ignored (zero tangents bend nothing)
    mesh.tangents.assign(nv, {0, 0, 0, 1});
    return;
  }
  if (tangent_accessor >= 0) {
    int n = 0;
    std::vector<float> t = read_floats(tangent_accessor, apath + "TANGENT", {4}, n);
    if (t.size() / 4 != nv) fail(apath + "TANGENT", std::to_string(t.size() / 4) + " elements, POSITION has " + std::to_string(nv));
    mesh.tangents.resize(nv);
    size_t zero = 0;
    for (size_t v = 0; v < nv; ++v) {
      const Vec3 d = world.vector(Vec3(t[4 * v], t[4 * v + 1], t[4 * v + 2]));
      if (!(length_squared(d) > 0)) ++zero;
      // A mirroring transform flips the bitangent's handedness with the winding.
      const float sign = (t[4 * v + 3] < 0) != (world.det3() < 0) ? -1.0f : 1.0f;
      mesh.tangents[v] = {d.x, d.y, d.z, sign};
    }
    if (zero)
      m_ctx.warn("zero tangent", apath + "TANGENT", std::to_string(zero) + " tangents of length 0: the normal map is "
                                                        "not applied there");
    return;
  }
  compute_tangents(mesh, set);
}

void Builder::add_camera(const tinygltf::Node& node, const Mat4& world, const std::string& path) {
  const tinygltf::Camera& c = m_model.cameras[size_t(node.camera)];
  const std::string at = "/cameras/" + std::to_string(node.camera);
  if (c.type != "perspective") {
    m_ctx.warn("orthographic", at, "orthographic cameras are not supported: the scene's bounds are framed in perspective");
    return;
  }
  if (m_desc.camera.present) {
    m_ctx.warn("cameras", path + "/camera", "the scene has several cameras: the first one found is used");
    return;
  }
  CameraDesc& cd = m_desc.camera;
  cd.present = true;
  cd.as_authored = true;
  cd.xfov_deg = 0;
  cd.yfov_deg = float(c.perspective.yfov * kDeg);
  cd.aspect = float(c.perspective.aspectRatio);
  cd.znear = float(c.perspective.znear);
  cd.zfar = c.perspective.zfar > 0 ? float(c.perspective.zfar) : kInf;  // absent: infinite
  cd.world = world;
}

void Builder::add_light(int index, const Mat4& world, const std::string& path) {
  const tinygltf::Light& gl = m_model.lights[size_t(index)];
  const std::string at = "/extensions/KHR_lights_punctual/lights/" + std::to_string(index);
  LightDesc l;
  l.name = gl.name.empty() ? at : gl.name;
  Vec3 color(1.0f);
  if (gl.color.size() == 3) color = Vec3(float(gl.color[0]), float(gl.color[1]), float(gl.color[2]));
  // Candela for point and spot lights, lux for directional ones: both lumens over the unit (gltf.h).
  l.color = radiometric_from_photometric(color, gl.intensity);
  if (gl.range > 0)
    m_ctx.warn("range", at + "/range", "'range' is ignored: lights fall off with the inverse square of the distance");
  l.position = world.point(Vec3(0, 0, 0));
  l.direction = local_minus_z(world);
  if (gl.type != "point" && !(length(l.direction) > 0.5f)) fail(path, "the light's transform is degenerate");
  if (gl.type == "point") {
    l.type = LightType::point;
  } else if (gl.type == "spot") {
    l.type = LightType::spot;
    l.spot_angle_deg = float(2 * gl.spot.outerConeAngle * kDeg);
    l.spot_inner_deg = float(2 * gl.spot.innerConeAngle * kDeg);
  } else {
    l.type = LightType::directional;
  }
  if (!is_finite(l.position) || !is_finite(l.color)) fail(path, "the light's position or power is not finite");
  m_desc.lights.push_back(l);
}

void Builder::visit(int index, const Mat4& parent, int depth) {
  const std::string path = "/nodes/" + std::to_string(index);
  if (depth > m_ctx.limits.max_node_depth) fail(path, "nodes nested deeper than " + std::to_string(m_ctx.limits.max_node_depth));
  if (++m_nodes > m_ctx.limits.max_nodes) fail(path, "more than " + std::to_string(m_ctx.limits.max_nodes) + " nodes");
  const tinygltf::Node& node = m_model.nodes[size_t(index)];
  const Mat4 world = parent * local_transform(node, path);
  if (!finite(world) || !std::isfinite(world.det3())) fail(path, "the transform is not finite");
  if (node.skin >= 0) m_ctx.warn("skins", path + "/skin", "skins are ignored: meshes render in their bind pose");
  if (node.mesh >= 0) {
    const tinygltf::Mesh& mesh = m_model.meshes[size_t(node.mesh)];
    const std::string base = mesh.name.empty() ? (node.name.empty() ? "mesh " + std::to_string(node.mesh) : node.name) : mesh.name;
    for (size_t p = 0; p < mesh.primitives.size(); ++p)
      add_primitive(mesh.primitives[p], world, "/meshes/" + std::to_string(node.mesh) + "/primitives/" + std::to_string(p),
                    mesh.primitives.size() > 1 ? base + "/" + std::to_string(p) : base);
  }
  if (node.camera >= 0) add_camera(node, world, path);
  auto ext = node.extensions.find("KHR_lights_punctual");
  if (ext != node.extensions.end() && ext->second.Has("light"))
    add_light(ext->second.Get("light").GetNumberAsInt(), world, path + "/extensions/KHR_lights_punctual");
  for (int child : node.children) visit(child, world, depth + 1);
}

SceneDesc Builder::run() {
  m_desc.source = m_ctx.name;
  m_desc.default_light = true;
  if (!m_model.animations.empty()) m_ctx.warn("animations", "/animations", "animations are ignored: the scene renders as the nodes place it");
  std::vector<int> roots;
  std::string where = "/scenes";
  int scene = m_model.defaultScene >= 0 ? m_model.defaultScene : (m_model.scenes.empty() ? -1 : 0);
  if (scene >= 0) {
    roots = m_model.scenes[size_t(scene)].nodes;
    where += "/" + std::to_string(scene);
  } else {  // no scene: every root node (the checks made the nodes trees)
    std::vector<bool> child(m_model.nodes.size(), false);
    for (const tinygltf::Node& n : m_model.nodes)
      for (int c : n.children) child[size_t(c)] = true;
    for (size_t i = 0; i < child.size(); ++i)
      if (!child[i]) roots.push_back(int(i));
    if (!roots.empty()) m_ctx.warn("no scene", "/scenes", "the file names no scene: every root node is rendered");
  }
  for (int r : roots) visit(r, Mat4::identity(), 0);
  m_desc.camera.overview = !m_desc.camera.present;
  if (m_desc.meshes.empty() && m_desc.lights.empty()) fail(where, "the scene has no triangles and no lights");
  return std::move(m_desc);
}

}  // namespace

SceneDesc build_scene(const Context& ctx, const tinygltf::Model& model, Images& images) {
  return Builder(ctx, model, images).run();
}

}  // namespace pt::gltf_detail

namespace pt {

SceneDesc parse_gltf(const std::string& bytes, const std::string& name, bool binary, const LoadLimits& limits,
                     const std::string& base_dir) {
  using namespace gltf_detail;
  Context ctx;
  ctx.name = name;
  ctx.limits = limits;
  ctx.base_dir = base_dir;
  ctx.binary = binary;
  // tinygltf takes 32-bit lengths.
  const size_t max_bytes = std::min<size_t>(limits.max_file_bytes, 0xFFFFFFFFu);
  if (bytes.size() > max_bytes)
    throw SceneError(name + ": " + std::to_string(bytes.size()) + " bytes, over the limit of " + std::to_string(max_bytes));
  Parts parts = split_file(ctx, bytes);
  Checked checked = check_json(ctx, parts);
  Images images;
  std::vector<std::string> files_read;
  tinygltf::Model model = run_tinygltf(ctx, bytes, parts, checked, images, files_read);
  SceneDesc desc = build_scene(ctx, model, images);
  desc.input_files = std::move(files_read);
  desc.warnings = ctx.take_warnings();
  return desc;
}

}  // namespace pt
