// Scene analysis for the caustic light tracer (caustic_scene.h).
#include "caustic_scene.h"

#include <cmath>

#include "materials.h"
#include "scene.h"

namespace pt {

std::vector<CausticTarget> find_caustic_targets(const SceneDesc& desc, const std::vector<Material>& materials) {
  std::vector<CausticTarget> out;
  // Padding keeps grazing hits inside the cones despite rounding.
  auto padded = [](Vec3 c, float r) { return CausticTarget{c, r * 1.001f + 1e-6f * max_component(abs(c))}; };
  for (const SphereDesc& s : desc.spheres)
    if (is_delta(materials[s.material])) out.push_back(padded(s.center, s.radius));
  for (const MeshDesc& mesh : desc.meshes) {
    Bounds3 b;
    for (size_t t = 0; t < mesh.tri_material.size(); ++t)
      if (is_delta(materials[mesh.tri_material[t]]))
        for (int k = 0; k < 3; ++k) b.expand(mesh.positions[mesh.indices[3 * t + k]]);
    if (!b.empty()) out.push_back(padded(b.center(), 0.5f * length(b.diagonal())));
  }
  if (out.size() > kMaxCausticTargets) {  // one sphere around them all: coarser aim, still every path
    Bounds3 b;
    for (const CausticTarget& t : out) {
      b.expand(t.center - Vec3(t.radius, t.radius, t.radius));
      b.expand(t.center + Vec3(t.radius, t.radius, t.radius));
    }
    out.assign(1, padded(b.center(), 0.5f * length(b.diagonal())));
  }
  return out;
}

namespace {

// The plane of an emitting face (an area light's rectangle or an emissive triangle) and its box.
struct EmitterFace {
  Vec3 n;
  float d;
  Bounds3 box;
  int owner;  // a mesh index, or meshes.size() + the area light's index
};

bool boxes_touch(const Bounds3& a, const Bounds3& b, float pad) {
  return a.lo.x <= b.hi.x + pad && b.lo.x <= a.hi.x + pad && a.lo.y <= b.hi.y + pad && b.lo.y <= a.hi.y + pad &&
         a.lo.z <= b.hi.z + pad && b.lo.z <= a.hi.z + pad;
}

}  // namespace

bool emitters_share_a_plane(const SceneDesc& desc, const std::vector<Material>& materials) {
  constexpr size_t kMaxFaces = 32;  // past this many emitting faces, assume they may
  std::vector<EmitterFace> faces;
  // A planar face through corners v[0, count): its plane from the first three, its box from all.
  auto face = [&](const Vec3* v, int count, int owner) {
    Vec3 n = cross(v[1] - v[0], v[2] - v[0]);
    float len = length(n);
    if (!(len > 0)) return;
    EmitterFace f{n / len, 0, {}, owner};
    f.d = dot(f.n, v[0]);
    for (int k = 0; k < count; ++k) f.box.expand(v[k]);
    faces.push_back(f);
  };
  const int meshes = int(desc.meshes.size());
  for (size_t i = 0; i < desc.lights.size(); ++i) {
    if (desc.lights[i].type != LightType::area) continue;
    Vec3 corners[4];
    area_light_corners(desc.lights[i], corners);
    face(corners, 4, meshes + int(i));
  }
  for (size_t m = 0; m < desc.meshes.size(); ++m) {
    const MeshDesc& mesh = desc.meshes[m];
    for (size_t t = 0; t < mesh.tri_material.size() && faces.size() <= kMaxFaces; ++t) {
      if (!is_emissive(materials[size_t(mesh.tri_material[t])])) continue;
      const uint32_t* v = &mesh.indices[3 * t];
      const Vec3 corners[3] = {mesh.positions[v[0]], mesh.positions[v[1]], mesh.positions[v[2]]};
      face(corners, 3, int(m));
    }
  }
  if (faces.size() > kMaxFaces) return true;
  // Within rounding of a spawned ray's offset (Waechter and Binder scale theirs with the
  // coordinates), generously.
  auto in_plane = [](const EmitterFace& f, Vec3 p) {
    return std::fabs(dot(f.n, p) - f.d) <= 1e-4f * (1 + max_component(abs(p)));
  };
  // Whether triangle (a, b, c) of `owner` lies in the plane of another emitter and overlaps its box.
  auto overlaps = [&](Vec3 a, Vec3 b, Vec3 c, int owner, bool emissive) {
    Bounds3 box;
    for (Vec3 v : {a, b, c}) box.expand(v);
    for (const EmitterFace& f : faces) {
      if (f.owner == owner && (emissive || owner >= meshes)) continue;  // an emitter's own faces
      if (!boxes_touch(box, f.box, 1e-4f * (1 + max_component(abs(f.box.hi)))) || !in_plane(f, a) || !in_plane(f, b) ||
          !in_plane(f, c))
        continue;
      return true;
    }
    return false;
  };
  for (size_t m = 0; m < desc.meshes.size(); ++m) {
    const MeshDesc& mesh = desc.meshes[m];
    for (size_t t = 0; t < mesh.tri_material.size(); ++t) {
      const uint32_t* v = &mesh.indices[3 * t];
      if (overlaps(mesh.positions[v[0]], mesh.positions[v[1]], mesh.positions[v[2]], int(m),
                   is_emissive(materials[size_t(mesh.tri_material[t])])))
        return true;
    }
  }
  for (size_t i = 0; i < desc.lights.size(); ++i) {
    if (desc.lights[i].type != LightType::area) continue;
    Vec3 q[4];
    area_light_corners(desc.lights[i], q);
    if (overlaps(q[0], q[1], q[2], meshes + int(i), true) || overlaps(q[0], q[2], q[3], meshes + int(i), true))
      return true;
  }
  return false;
}

}  // namespace pt
