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

namespace pt {

void compute_tangents(MeshDesc& mesh, int set) {
  const std::vector<Vec2>& uv = set == 1 ? mesh.uvs1 : mesh.uvs;
  const size_t nv = mesh.positions.size();
  if (uv.size() != nv) return;
  std::vector<Vec3> tan(nv, Vec3(0.0f)), bit(nv, Vec3(0.0f)), nrm(nv, Vec3(0.0f));
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t* i = &mesh.indices[t];
    const Vec3 e1 = mesh.positions[i[1]] - mesh.positions[i[0]], e2 = mesh.positions[i[2]] - mesh.positions[i[0]];
    const float du1 = uv[i[1]].x - uv[i[0]].x, dv1 = uv[i[1]].y - uv[i[0]].y;
    const float du2 = uv[i[2]].x - uv[i[0]].x, dv2 = uv[i[2]].y - uv[i[0]].y;
    const float det = du1 * dv2 - du2 * dv1;
    const Vec3 face = cross(e1, e2);
    for (int k = 0; k < 3; ++k) nrm[i[k]] += face;
    if (!(std::fabs(det) > 1e-20f)) continue;  // no uv area: no direction to give
    // dP/du and dP/dv over the triangle (Lengyel 2001), weighted by its area in uv.
    const float s = det > 0 ? 1.0f : -1.0f;
    const Vec3 t_dir = (e1 * dv2 - e2 * dv1) * s, b_dir = (e2 * du1 - e1 * du2) * s;
    for (int k = 0; k < 3; ++k) tan[i[k]] += t_dir, bit[i[k]] += b_dir;
  }
  mesh.tangents.assign(nv, {0, 0, 0, 1});
  for (size_t v = 0; v < nv; ++v) {
    const Vec3 n = normalize(mesh.normals.size() == nv ? mesh.normals[v] : nrm[v]);
    const Vec3 t = normalize(tan[v] - n * dot(n, tan[v]));
    if (!is_finite(t) || is_black(t)) continue;
    // glTF's v runs down the image and its normal maps' +Y up it: the bitangent, cross(n, t) x w,
    // points along -dP/dv.
    const float w = dot(cross(n, t), bit[v]) > 0 ? -1.0f : 1.0f;
    mesh.tangents[v] = {t.x, t.y, t.z, w};
  }
}

}  // namespace pt
