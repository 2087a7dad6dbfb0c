// THE Embree file: builds the Embree 3 scene once and answers intersect / occluded queries.
// Triangles (meshes and emitter panels) are Embree triangle geometry; spheres are Embree user
// geometry with an exact test, never tessellated.
#include "accel.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "accel_math.h"
#include "loop_forms.h"

namespace pt {

namespace {

struct DeviceError {
  std::mutex mutex;
  std::string message;
};

void on_device_error(void* user, RTCError code, const char* str) {
  auto* err = static_cast<DeviceError*>(user);
  std::lock_guard<std::mutex> lock(err->mutex);
  if (err->message.empty()) err->message = "Embree error " + std::to_string(int(code)) + ": " + (str ? str : "");
}

// Embree reports every allocation (BVH and its own geometry buffers) here: the true footprint.
bool on_memory(void* user, ssize_t bytes, bool) {
  static_cast<std::atomic<long long>*>(user)->fetch_add(bytes, std::memory_order_relaxed);
  return true;
}

enum class GeomKind { mesh, spheres, panels };

struct GeomInfo {
  GeomKind kind = GeomKind::mesh;
  const float* positions = nullptr;   // Embree-owned vertex buffer (3 floats a vertex)
  const uint32_t* indices = nullptr;  // Embree-owned index buffer
  std::vector<float> normals;         // shading normals, 3 floats a vertex and 1 of padding; empty for flat meshes
  std::vector<TriangleInfo> tris;     // per triangle
  // Vertex attributes for Accel::attributes, each empty when the mesh has none.
  std::vector<Vec2> uv0, uv1;
  std::vector<Vec3> colors;
  std::vector<float> color_alpha;
  std::vector<std::array<float, 4>> tangents;
  bool has_attributes() const {
    return !uv0.empty() || !uv1.empty() || !colors.empty() || !color_alpha.empty() || !tangents.empty();
  }
  const float* spheres = nullptr;     // x y z r per sphere
  std::vector<float> sphere_data;     // what `spheres` points to (Embree user geometry reads it)
  std::vector<int> sphere_material;
  TriangleData triangles{};  // a view of the above for refine_triangle, set once all geometry is in place
};

void sphere_bounds(const RTCBoundsFunctionArguments* args) {
  const float* s = static_cast<const float*>(args->geometryUserPtr) + 4 * args->primID;
  RTCBounds* b = args->bounds_o;
  b->lower_x = s[0] - s[3];
  b->lower_y = s[1] - s[3];
  b->lower_z = s[2] - s[3];
  b->upper_x = s[0] + s[3];
  b->upper_y = s[1] + s[3];
  b->upper_z = s[2] + s[3];
}

// Ray i of a ray packet against sphere s (accel_math.h).
inline bool sphere_hit_lane(const float* s, RTCRayN* ray, unsigned N, unsigned i, float& t) {
  return sphere_hit(s, RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i), RTCRayN_org_z(ray, N, i),
                        RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i),
                        RTCRayN_tnear(ray, N, i), RTCRayN_tfar(ray, N, i), t);
}

// Rays i..i+3 of a packet, which Embree lays out field by field.
inline RayLanes4 lanes4(RTCRayN* ray, unsigned N, unsigned i, const int* valid) {
  return {&RTCRayN_org_x(ray, N, i), &RTCRayN_org_y(ray, N, i), &RTCRayN_org_z(ray, N, i),
          &RTCRayN_dir_x(ray, N, i), &RTCRayN_dir_y(ray, N, i), &RTCRayN_dir_z(ray, N, i),
          &RTCRayN_tnear(ray, N, i), &RTCRayN_tfar(ray, N, i), valid + i};
}

// A hit of ray i at t: Embree's hit record, the normal unnormalised (refine_hit normalises it).
inline void sphere_record(const RTCIntersectFunctionNArguments* args, const float* s, unsigned i, float t) {
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, args->N);
  RTCRayN_tfar(ray, args->N, i) = t;
  float px = RTCRayN_org_x(ray, args->N, i) + t * RTCRayN_dir_x(ray, args->N, i);
  float py = RTCRayN_org_y(ray, args->N, i) + t * RTCRayN_dir_y(ray, args->N, i);
  float pz = RTCRayN_org_z(ray, args->N, i) + t * RTCRayN_dir_z(ray, args->N, i);
  RTCHitN_Ng_x(hit, args->N, i) = px - s[0];
  RTCHitN_Ng_y(hit, args->N, i) = py - s[1];
  RTCHitN_Ng_z(hit, args->N, i) = pz - s[2];
  RTCHitN_u(hit, args->N, i) = 0;
  RTCHitN_v(hit, args->N, i) = 0;
  RTCHitN_primID(hit, args->N, i) = args->primID;
  RTCHitN_geomID(hit, args->N, i) = args->geomID;
  RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
}

void sphere_intersect(const RTCIntersectFunctionNArguments* args) {
  const float* s = static_cast<const float*>(args->geometryUserPtr) + 4 * args->primID;
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
  unsigned i = 0;
  for (; args->N % 4 == 0 && i < args->N; i += 4) {  // packets: four rays at a time
    float t[4];
    for (int hits = sphere_hit4(s, lanes4(ray, args->N, i, args->valid), t); hits; hits &= hits - 1) {
      const int k = __builtin_ctz(unsigned(hits));
      sphere_record(args, s, i + unsigned(k), t[k]);
    }
  }
  for (; i < args->N; ++i) {
    float t;
    if (args->valid[i] == -1 && sphere_hit_lane(s, ray, args->N, i, t)) sphere_record(args, s, i, t);
  }
}

void sphere_occluded(const RTCOccludedFunctionNArguments* args) {
  const float* s = static_cast<const float*>(args->geometryUserPtr) + 4 * args->primID;
  RTCRayN* ray = args->ray;
  unsigned i = 0;
  for (; args->N % 4 == 0 && i < args->N; i += 4) {
    float t[4];
    for (int hits = sphere_hit4(s, lanes4(ray, args->N, i, args->valid), t); hits; hits &= hits - 1)
      RTCRayN_tfar(ray, args->N, i + unsigned(__builtin_ctz(unsigned(hits)))) = -INFINITY;
  }
  for (; i < args->N; ++i) {
    float t;
    if (args->valid[i] == -1 && sphere_hit_lane(s, ray, args->N, i, t)) RTCRayN_tfar(ray, args->N, i) = -INFINITY;
  }
}

// The vertex attributes of triangle `prim` at barycentrics (u, v) of its vertices 1 and 2.
HitAttributes interpolate(const GeomInfo& g, uint32_t prim, float u, float v) {
  HitAttributes out;
  if (g.kind == GeomKind::spheres || size_t(prim) >= g.tris.size()) return out;
  const uint32_t* tri = g.indices + 3 * size_t(prim);
  const float w = 1 - u - v;
  auto mix2 = [&](const std::vector<Vec2>& x) {
    return Vec2{x[tri[0]].x * w + x[tri[1]].x * u + x[tri[2]].x * v, x[tri[0]].y * w + x[tri[1]].y * u + x[tri[2]].y * v};
  };
  if (!g.uv0.empty()) out.uv[0] = mix2(g.uv0);
  if (!g.uv1.empty()) out.uv[1] = mix2(g.uv1);
  if (!g.colors.empty()) out.color = g.colors[tri[0]] * w + g.colors[tri[1]] * u + g.colors[tri[2]] * v;
  if (!g.color_alpha.empty())
    out.alpha = g.color_alpha[tri[0]] * w + g.color_alpha[tri[1]] * u + g.color_alpha[tri[2]] * v;
  if (!g.tangents.empty()) {
    const auto &t0 = g.tangents[tri[0]], &t1 = g.tangents[tri[1]], &t2 = g.tangents[tri[2]];
    out.tangent = Vec3(t0[0], t0[1], t0[2]) * w + Vec3(t1[0], t1[1], t1[2]) * u + Vec3(t2[0], t2[1], t2[2]) * v;
    out.sign = t0[3] < 0 ? -1.0f : 1.0f;
  }
  return out;
}

}  // namespace

struct Accel::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  DeviceError error;
  std::vector<GeomInfo> geoms;  // indexed by Embree geometry id
  size_t bytes = 0;             // our side arrays (shading normals, per-triangle material and light)
  std::atomic<long long> embree_bytes{0};
  // The scene's bounds, padded; a ray that misses them skips Embree (most camera rays of the
  // course framing see only background). cull = false when the bounds are not finite.
  // A fourth lane (-inf, +inf) lets may_hit_bounds compare four floats at once.
  float lo[4] = {0, 0, 0, -INFINITY}, hi[4] = {0, 0, 0, INFINITY};
  bool cull = false;
  // Rays a packet: 16 where Embree has 16-wide kernels (AVX-512), else 8. Without them Embree
  // takes a packet of 16 apart through its stream path, and native packets of 8 cost about 2% fewer
  // instructions per pass on AVX2 (docs/performance.md).
  int packet_width = 16;
  bool attributes = false;  // some mesh has uvs or colours: hits interpolate them
  CoverageTest coverage;             // alpha-tested materials (Embree filters on their meshes)
  std::vector<uint8_t> tested;       // per material: kAlphaTested | kUnlit (Embree filters on their meshes)
  bool unlit = false;                // some material is unlit

  void check(const char* what) {
    std::lock_guard<std::mutex> lock(error.mutex);
    if (!error.message.empty()) throw std::runtime_error(std::string(what) + ": " + error.message);
  }
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

constexpr uint8_t kAlphaTested = 1, kUnlit = 2;
constexpr unsigned kCameraRay = 1;  // RTCRay::id of a ray that leaves the camera

// Embree's filter on meshes with alpha-tested or unlit triangles, for intersect and occluded
// queries of every width: a hit the coverage test refuses, or an unlit one by a ray that is not a
// camera ray, is ignored and traversal goes on behind it.
void see_through_filter(const RTCFilterFunctionNArguments* args) {
  const auto& a = *static_cast<const Accel::Impl*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const unsigned geom = RTCHitN_geomID(args->hit, args->N, i), prim = RTCHitN_primID(args->hit, args->N, i);
    const GeomInfo& g = a.geoms[geom];
    const int material = g.tris[prim].material;
    if (material < 0 || size_t(material) >= a.tested.size() || !a.tested[size_t(material)]) continue;
    if ((a.tested[size_t(material)] & kUnlit) && RTCRayN_id(args->ray, args->N, i) != kCameraRay) {
      args->valid[i] = 0;
      continue;
    }
    if (!(a.tested[size_t(material)] & kAlphaTested)) continue;
    const float u = RTCHitN_u(args->hit, args->N, i), v = RTCHitN_v(args->hit, args->N, i);
    const float ray[6] = {RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
                          RTCRayN_org_z(args->ray, args->N, i), RTCRayN_dir_x(args->ray, args->N, i),
                          RTCRayN_dir_y(args->ray, args->N, i), RTCRayN_dir_z(args->ray, args->N, i)};
    if (!a.coverage(material, interpolate(g, prim, u, v), ray_uniform(ray, 6, prim))) args->valid[i] = 0;
  }
}

}  // namespace

Accel::Accel(const SceneDesc& desc, const std::vector<EmitterPanel>& panels,
             const std::vector<std::vector<int>>& mesh_light, CoverageTest coverage)
    : m_impl(std::make_unique<Impl>()) {
  Impl& a = *m_impl;
  a.tested.resize(desc.materials.size());
  bool any_alpha = false;
  for (size_t m = 0; m < desc.materials.size(); ++m) {
    const Material& mat = desc.materials[m];
    if (mat.type != MaterialType::pbr) continue;
    const bool alpha = coverage && mat.pbr.alpha_tested();
    a.tested[m] = uint8_t((alpha ? kAlphaTested : 0) | (mat.pbr.unlit ? kUnlit : 0));
    any_alpha |= alpha;
    a.unlit |= mat.pbr.unlit;
  }
  if (any_alpha) a.coverage = std::move(coverage);
  a.device = rtcNewDevice(nullptr);
  if (!a.device) throw std::runtime_error("Embree: cannot create device (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
  rtcSetDeviceErrorFunction(a.device, on_device_error, &a.error);
  rtcSetDeviceMemoryMonitorFunction(a.device, on_memory, &a.embree_bytes);
  a.packet_width = rtcGetDeviceProperty(a.device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) ? 16 : 8;
  a.scene = rtcNewScene(a.device);
  rtcSetSceneFlags(a.scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(a.scene, RTC_BUILD_QUALITY_MEDIUM);

  // tri_light may be empty (nothing emits).
  auto add_triangles = [&](const std::vector<Vec3>& pos, const std::vector<uint32_t>& idx,
                           const std::vector<int>& tri_material, const std::vector<int>& tri_light, GeomInfo info) {
    RTCGeometry g = rtcNewGeometry(a.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    bool filtered = false;
    for (size_t t = 0; t < tri_material.size() && !filtered; ++t)
      filtered = tri_material[t] >= 0 && size_t(tri_material[t]) < a.tested.size() && a.tested[size_t(tri_material[t])];
    if (filtered) {
      rtcSetGeometryUserData(g, &a);
      rtcSetGeometryIntersectFilterFunction(g, see_through_filter);
      rtcSetGeometryOccludedFilterFunction(g, see_through_filter);
    }
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), pos.size()));
    auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(uint32_t), idx.size() / 3));
    a.check("allocating triangle buffers");
    std::memcpy(vb, pos.data(), pos.size() * sizeof(Vec3));
    std::memcpy(ib, idx.data(), idx.size() * sizeof(uint32_t));
    info.tris.resize(idx.size() / 3);
    for (size_t t = 0; t < info.tris.size(); ++t) {
      const uint32_t* tri = idx.data() + 3 * t;
      Vec3 p0 = pos[tri[0]], p1 = pos[tri[1]], p2 = pos[tri[2]];
      info.tris[t] = {normalize(cross(p1 - p0, p2 - p0)), tri_material[t], tri_light.empty() ? -1 : tri_light[t]};
    }
    a.bytes += info.normals.size() * sizeof(float) + info.tris.size() * sizeof(TriangleInfo) +
               (info.uv0.size() + info.uv1.size()) * sizeof(Vec2) + info.colors.size() * sizeof(Vec3) +
               info.color_alpha.size() * sizeof(float) + info.tangents.size() * 4 * sizeof(float);
    rtcCommitGeometry(g);
    unsigned id = rtcAttachGeometry(a.scene, g);
    rtcReleaseGeometry(g);
    a.check("attaching triangles");
    info.positions = vb;
    info.indices = ib;
    if (a.geoms.size() <= id) a.geoms.resize(id + 1);
    a.geoms[id] = std::move(info);
  };

  for (size_t m = 0; m < desc.meshes.size(); ++m) {
    const MeshDesc& mesh = desc.meshes[m];
    GeomInfo info;
    info.kind = GeomKind::mesh;
    if (!mesh.normals.empty()) {  // padded for refine_triangle's 16-byte loads
      info.normals.reserve(3 * mesh.normals.size() + 1);
      for (Vec3 n : mesh.normals) info.normals.insert(info.normals.end(), {n.x, n.y, n.z});
      info.normals.push_back(0.0f);
    }
    // Attributes with one value a vertex are kept (the loaders give all or none).
    const size_t nv = mesh.positions.size();
    if (mesh.uvs.size() == nv) info.uv0 = mesh.uvs;
    if (mesh.uvs1.size() == nv) info.uv1 = mesh.uvs1;
    if (mesh.colors.size() == nv) info.colors = mesh.colors;
    if (mesh.color_alpha.size() == nv) info.color_alpha = mesh.color_alpha;
    if (mesh.tangents.size() == nv) info.tangents = mesh.tangents;
    static const std::vector<int> none;
    add_triangles(mesh.positions, mesh.indices, mesh.tri_material, m < mesh_light.size() ? mesh_light[m] : none,
                  std::move(info));
  }

  if (!panels.empty()) {
    std::vector<Vec3> pos;
    std::vector<uint32_t> idx;
    std::vector<int> tri_material, tri_light;
    GeomInfo info;
    info.kind = GeomKind::panels;
    for (const EmitterPanel& p : panels) {
      uint32_t base = uint32_t(pos.size());
      for (int i = 0; i < (p.quad ? 4 : 3); ++i) pos.push_back(p.v[i]);
      idx.insert(idx.end(), {base, base + 1, base + 2});
      tri_material.push_back(p.material);
      tri_light.push_back(p.light);
      if (p.quad) {
        idx.insert(idx.end(), {base, base + 2, base + 3});
        tri_material.push_back(p.material);
        tri_light.push_back(p.light);
      }
    }
    add_triangles(pos, idx, tri_material, tri_light, std::move(info));
  }

  if (!desc.spheres.empty()) {
    RTCGeometry g = rtcNewGeometry(a.device, RTC_GEOMETRY_TYPE_USER);
    GeomInfo info;
    info.kind = GeomKind::spheres;
    for (const SphereDesc& s : desc.spheres) {
      info.sphere_data.insert(info.sphere_data.end(), {s.center.x, s.center.y, s.center.z, s.radius});
      info.sphere_material.push_back(s.material);
    }
    info.spheres = info.sphere_data.data();  // stays valid when info moves into a.geoms
    a.bytes += desc.spheres.size() * (4 * sizeof(float) + sizeof(int));
    rtcSetGeometryUserPrimitiveCount(g, unsigned(desc.spheres.size()));
    rtcSetGeometryUserData(g, const_cast<float*>(info.spheres));
    rtcSetGeometryBoundsFunction(g, sphere_bounds, nullptr);
    rtcSetGeometryIntersectFunction(g, sphere_intersect);
    rtcSetGeometryOccludedFunction(g, sphere_occluded);
    rtcCommitGeometry(g);
    unsigned id = rtcAttachGeometry(a.scene, g);
    rtcReleaseGeometry(g);
    a.check("attaching spheres");
    if (a.geoms.size() <= id) a.geoms.resize(id + 1);
    a.geoms[id] = std::move(info);
  }
  for (const GeomInfo& g : a.geoms) a.attributes |= g.has_attributes();
  for (size_t id = 0; id < a.geoms.size(); ++id) {  // the vectors' buffers are where they stay
    GeomInfo& g = a.geoms[id];
    g.triangles = {g.positions, g.indices, g.normals.empty() ? nullptr : g.normals.data(), g.tris.data(),
                   uint32_t(id), g.has_attributes()};
  }

  rtcCommitScene(a.scene);
  a.check("building the BVH");
  RTCBounds b;
  rtcGetSceneBounds(a.scene, &b);
  const float blo[3] = {b.lower_x, b.lower_y, b.lower_z}, bhi[3] = {b.upper_x, b.upper_y, b.upper_z};
  float size = 0;
  bool finite = true;
  for (int k = 0; k < 3; ++k) {
    finite &= std::isfinite(blo[k]) && std::isfinite(bhi[k]) && blo[k] <= bhi[k];
    size = std::max({size, std::fabs(blo[k]), std::fabs(bhi[k]), bhi[k] - blo[k]});
  }
  if (finite) {  // padded far beyond float rounding: culling must never drop a hit
    float pad = 1e-3f * size + 1e-6f;
    for (int k = 0; k < 3; ++k) {
      a.lo[k] = blo[k] - pad;
      a.hi[k] = bhi[k] + pad;
    }
    a.cull = true;
  }
}

Accel::~Accel() = default;

bool Accel::hit_bounds(Vec3& lo, Vec3& hi) const {
  const Impl& a = *m_impl;
  lo = Vec3(a.lo[0], a.lo[1], a.lo[2]);
  hi = Vec3(a.hi[0], a.hi[1], a.hi[2]);
  return a.cull;
}

size_t Accel::memory_bytes() const {
  return m_impl->bytes + size_t(std::max(0LL, m_impl->embree_bytes.load()));
}

namespace {

inline void to_embree(const Ray& r, RTCRay& e, unsigned id = 0) {
  e.org_x = r.o.x, e.org_y = r.o.y, e.org_z = r.o.z;
  e.dir_x = r.d.x, e.dir_y = r.d.y, e.dir_z = r.d.z;
  e.tnear = r.tmin, e.tfar = r.tmax;
  e.time = 0, e.mask = 0xFFFFFFFFu, e.id = id, e.flags = 0;
}

// The hit record from Embree's answer (accel_math.h). `eng()` gives Embree's unnormalised
// geometric normal, read only for a degenerate triangle. Inlined into the packet loop: as a call,
// its eight arguments and prologue cost 1.2% of CBbunny's instructions (docs/performance.md,
// "Design choices that pay").
// `Attributes`: the scene has meshes with uvs or colours; without, not even their check runs.
template <bool Attributes, class EmbreeNormal>
[[gnu::always_inline]] inline void refine_hit(const GeomInfo& g, const Ray& ray, unsigned prim, float t, float u,
                                              float v, EmbreeNormal&& eng, SurfaceHit& hit) {
  if (g.kind == GeomKind::spheres) refine_sphere(g.spheres + 4 * size_t(prim), g.sphere_material[prim], ray, t, hit);
  else refine_triangle<Attributes>(g.triangles, prim, t, u, v, eng, hit);
}

// Embree's packet types and calls for packets of K rays.
template <int K>
struct Packet;
template <>
struct Packet<8> {
  using RayHit = RTCRayHit8;
  using Ray = RTCRay8;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) { rtcIntersect8(valid, s, c, r); }
  static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded8(valid, s, c, r); }
};
template <>
struct Packet<16> {
  using RayHit = RTCRayHit16;
  using Ray = RTCRay16;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) { rtcIntersect16(valid, s, c, r); }
  static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded16(valid, s, c, r); }
};

// One packet lane from a ray.
template <class RayK>
inline void to_lane(const Ray& r, RayK& e, int k) {
  e.org_x[k] = r.o.x, e.org_y[k] = r.o.y, e.org_z[k] = r.o.z;
  e.dir_x[k] = r.d.x, e.dir_y[k] = r.d.y, e.dir_z[k] = r.d.z;
  e.tnear[k] = r.tmin, e.tfar[k] = r.tmax;
}

// The fields every lane shares and Embree only reads: set once per packet, not per ray.
template <int K, class RayK>
inline void set_constant_lanes(RayK& e) {
  for (int k = 0; k < K; ++k) e.time[k] = 0, e.mask[k] = 0xFFFFFFFFu, e.id[k] = 0, e.flags[k] = 0;
}

// The caller's rays, `stride` bytes apart.
struct StridedRays {
  const char* base;
  size_t stride;
  const Ray& operator[](size_t i) const { return *reinterpret_cast<const Ray*>(base + i * stride); }
};

// Which ray of the caller's array each lane of a packet of K holds, and Embree's valid mask.
template <int K>
struct Lanes {
  alignas(64) int valid[K];
  uint32_t ray[K];
  int used = 0;

  template <class Rays, class RayK>
  bool add(const Rays& rays, uint32_t i, RayK& packet, unsigned id = 0) {
    to_lane(rays[i], packet, used);
    packet.id[used] = id;
    ray[used] = i;
    return ++used == K;
  }
  // Before tracing: masked-off lanes of a partial packet also get a valid ray (a copy of lane 0).
  // Where the CPU lacks K-wide kernels Embree splits the packet, and its debug build asserted on
  // the stale rays of lanes it should ignore (seen under valgrind, which has no AVX-512).
  template <class Rays, class RayK>
  void seal(const Rays& rays, RayK& packet) {
    for (int k = 0; k < K; ++k) valid[k] = k < used ? -1 : 0;
    for (int k = used; k < K; ++k) to_lane(rays[ray[0]], packet, k);
  }
};

template <int K, bool Attributes>
void intersect_packets(const Accel::Impl& a, const Ray* rays, size_t stride, size_t n, SurfaceHit* hits, uint8_t* found,
                       const uint8_t* camera) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  alignas(64) typename Packet<K>::RayHit rh;
  set_constant_lanes<K>(rh.ray);
  Lanes<K> lanes;
  const StridedRays at{reinterpret_cast<const char*>(rays), stride};
  auto trace = [&] {
    lanes.seal(at, rh.ray);
    Packet<K>::intersect(lanes.valid, a.scene, &ctx, &rh);
    for (int k = 0; k < lanes.used; ++k) {
      const uint32_t i = lanes.ray[k];
      if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) continue;
      found[i] = 1;
      refine_hit<Attributes>(a.geoms[rh.hit.geomID[k]], at[i], rh.hit.primID[k], rh.ray.tfar[k], rh.hit.u[k], rh.hit.v[k],
                 [&] { return Vec3(rh.hit.Ng_x[k], rh.hit.Ng_y[k], rh.hit.Ng_z[k]); }, hits[i]);
    }
    lanes.used = 0;
  };
  for (size_t i = 0; i < n; ++i) {
    found[i] = 0;
    const Ray& r = at[i];
    if (!embree_accepts(r) || (a.cull && !may_hit_bounds(r, a.lo, a.hi))) continue;
    rh.hit.geomID[lanes.used] = rh.hit.instID[0][lanes.used] = RTC_INVALID_GEOMETRY_ID;
    if (lanes.add(at, uint32_t(i), rh.ray, camera && camera[i] ? kCameraRay : 0)) trace();
  }
  if (lanes.used) trace();
}

template <int K>
void occluded_packets(const Accel::Impl& a, const Ray* rays, size_t n, uint8_t* blocked) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  alignas(64) typename Packet<K>::Ray rk;
  set_constant_lanes<K>(rk);
  Lanes<K> lanes;
  auto trace = [&] {
    lanes.seal(rays, rk);
    Packet<K>::occluded(lanes.valid, a.scene, &ctx, &rk);
    for (int k = 0; k < lanes.used; ++k) blocked[lanes.ray[k]] = rk.tfar[k] < 0;  // -inf on a hit
    lanes.used = 0;
  };
  for (size_t i = 0; i < n; ++i) {
    blocked[i] = 0;
    const Ray& r = rays[i];
    if (!embree_accepts(r)) continue;
    if (lanes.add(rays, uint32_t(i), rk)) trace();
  }
  if (lanes.used) trace();
}

}  // namespace

bool Accel::intersect(const Ray& ray, SurfaceHit& hit, bool camera) const {
  if (!embree_accepts(ray)) return false;
  const Impl& a = *m_impl;
  if (a.cull && !may_hit_bounds(ray, a.lo, a.hi)) return false;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  to_embree(ray, rh.ray, camera ? kCameraRay : 0);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(m_impl->scene, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  auto eng = [&] { return Vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z); };
  const GeomInfo& g = a.geoms[rh.hit.geomID];
  if (a.attributes) refine_hit<true>(g, ray, rh.hit.primID, rh.ray.tfar, rh.hit.u, rh.hit.v, eng, hit);
  else refine_hit<false>(g, ray, rh.hit.primID, rh.ray.tfar, rh.hit.u, rh.hit.v, eng, hit);
  return true;
}

HitAttributes Accel::attributes(const SurfaceHit& hit) const {
  const Impl& a = *m_impl;
  if (hit.geom >= a.geoms.size()) return HitAttributes();
  return interpolate(a.geoms[hit.geom], hit.prim, hit.bu, hit.bv);
}

bool Accel::occluded(const Ray& ray) const {
  if (!embree_accepts(ray)) return false;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r;
  to_embree(ray, r);
  rtcOccluded1(m_impl->scene, &ctx, &r);
  return r.tfar < 0;  // Embree sets tfar = -inf on a hit
}

void Accel::intersect_many(const Ray* rays, size_t stride, size_t n, SurfaceHit* hits, uint8_t* found,
                           const uint8_t* camera) const {
  const Impl& a = *m_impl;
  if (packet_width() == 16) {
    if (a.attributes) intersect_packets<16, true>(a, rays, stride, n, hits, found, camera);
    else intersect_packets<16, false>(a, rays, stride, n, hits, found, camera);
  } else {
    if (a.attributes) intersect_packets<8, true>(a, rays, stride, n, hits, found, camera);
    else intersect_packets<8, false>(a, rays, stride, n, hits, found, camera);
  }
}

bool Accel::has_unlit() const { return m_impl->unlit; }

void Accel::occluded_many(const Ray* rays, size_t n, uint8_t* blocked) const {
  if (packet_width() == 16) occluded_packets<16>(*m_impl, rays, n, blocked);
  else occluded_packets<8>(*m_impl, rays, n, blocked);
}

int Accel::packet_width() const { return forms::packet_width() ? forms::packet_width() : m_impl->packet_width; }

}  // namespace pt
