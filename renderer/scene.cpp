// SceneDesc helpers: counts, bounds and the course's area-weighted vertex normals.
#include "scene.h"

namespace pt {

size_t SceneDesc::triangle_count() const {
  size_t n = 0;
  for (const MeshDesc& m : meshes) n += m.indices.size() / 3;
  return n;
}

Bounds3 SceneDesc::geometry_bounds() const {
  Bounds3 b;
  for (const MeshDesc& m : meshes)
    for (const Vec3& p : m.positions) b.expand(p);
  for (const SphereDesc& s : spheres) {
    b.expand(s.center - Vec3(s.radius));
    b.expand(s.center + Vec3(s.radius));
  }
  return b;
}

void compute_vertex_normals(MeshDesc& mesh) {
  std::vector<Vec3> acc(mesh.positions.size(), Vec3(0.0f));
  size_t tris = mesh.indices.size() / 3;
  for (size_t t = 0; t < tris; ++t) {
    const uint32_t* i = &mesh.indices[3 * t];
    // The unnormalised cross product weighs each face by its area.
    Vec3 n = cross(mesh.positions[i[1]] - mesh.positions[i[0]], mesh.positions[i[2]] - mesh.positions[i[0]]);
    for (int k = 0; k < 3; ++k) acc[i[k]] += n;
  }
  bool flat = true;
  for (size_t t = 0; t < tris && flat; ++t) {
    const uint32_t* i = &mesh.indices[3 * t];
    Vec3 fn = normalize(cross(mesh.positions[i[1]] - mesh.positions[i[0]], mesh.positions[i[2]] - mesh.positions[i[0]]));
    for (int k = 0; k < 3; ++k)
      if (dot(normalize(acc[i[k]]), fn) < 0.99999f) flat = false;
  }
  if (flat) {
    mesh.normals.clear();
    return;
  }
  for (Vec3& n : acc) n = normalize(n);
  mesh.normals = std::move(acc);
}

}  // namespace pt
