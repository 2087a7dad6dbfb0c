// A glTF material at a hit (render_scene.h, textured_material): the factors times the textures at
// the hit's texture coordinates (glTF 2.0, 3.9), the vertex colour, and the normal map's bend of
// the shading normal in the tangent frame the mesh gives (3.9.3, MikkTSpace's convention).
#include "render_scene.h"
#include "texture.h"

namespace pt {

namespace {

Vec2 texture_uv(const TextureRef& ref, const HitAttributes& at) {
  Vec2 uv = at.uv[ref.set == 1 ? 1 : 0];
  if (ref.transformed) {
    const float* m = ref.m;
    uv = Vec2{m[0] * uv.x + m[1] * uv.y + m[2], m[3] * uv.x + m[4] * uv.y + m[5]};
  }
  return uv;
}

Vec3 lookup(const RenderScene& scene, const TextureRef& ref, const HitAttributes& at) {
  return eval_texture((*scene.textures)[size_t(ref.texture)], texture_uv(ref, at));
}

// The material textured_material returns, per thread, and the coat normal it found (world space;
// zero: the coat follows the shading normal).
Material& scratch_material() {
  thread_local Material scratch;
  return scratch;
}
thread_local Vec3 t_coat_world;

// The alpha channel, which specularTexture and sheenRoughnessTexture read.
float alpha_lookup(const RenderScene& scene, const TextureRef& ref, const HitAttributes& at) {
  return eval_texture_alpha((*scene.textures)[size_t(ref.texture)], texture_uv(ref, at));
}

// A tangent-space normal map's normal at the hit: components in [-1, 1], x and y scaled.
Vec3 tangent_normal(const RenderScene& scene, const TextureRef& ref, float scale, const HitAttributes& at) {
  Vec3 n_t = lookup(scene, ref, at) * 2.0f - Vec3(1.0f);
  n_t.x *= scale, n_t.y *= scale;
  return n_t;
}

// The shading normal bent by a tangent-space normal n_t (components in [-1, 1], x and y scaled):
// tangent made orthogonal to ns, bitangent = cross(ns, tangent) x sign (glTF 2.0, 3.7.2.1).
Vec3 bend(Vec3 ns, const HitAttributes& at, Vec3 n_t) {
  const Vec3 t = at.tangent - ns * dot(ns, at.tangent);
  if (!(length_squared(t) > 1e-20f)) return ns;
  const Vec3 tu = normalize(t), b = cross(ns, tu) * at.sign;
  const Vec3 n = normalize(tu * n_t.x + b * n_t.y + ns * n_t.z);
  return is_finite(n) && !is_black(n) ? n : ns;
}

}  // namespace

bool alpha_covers(const std::vector<TextureDesc>& textures, const PbrParams& p, const HitAttributes& at, float u) {
  float alpha = p.alpha * at.alpha;
  if (p.base_tex.used() && size_t(p.base_tex.texture) < textures.size())
    alpha *= eval_texture_alpha(textures[size_t(p.base_tex.texture)], texture_uv(p.base_tex, at));
  switch (p.alpha_mode) {
    case AlphaMode::opaque: return true;
    case AlphaMode::mask: return alpha >= p.alpha_cutoff;
    case AlphaMode::blend: return u < alpha;
  }
  return true;
}

void localize_coat(const Material& m, const Frame& frame, bool flipped) {
  if (&m != &scratch_material() || is_black(t_coat_world)) return;
  const Vec3 n = normalize(frame.to_local(flipped ? -t_coat_world : t_coat_world));
  scratch_material().pbr.coat_normal = is_finite(n) ? n : Vec3(0.0f);
}

[[gnu::noinline]] const Material& textured_material(const RenderScene& scene, const Material& m, const SurfaceHit& hit,
                                                    Vec3& ns) {
  Material& scratch = scratch_material();
  const PbrParams& in = m.pbr;
  PbrParams& p = scratch.pbr;
  scratch.type = MaterialType::pbr;
  p = in;
  for (TextureRef* r : p.texture_refs()) *r = TextureRef();
  p.vertex_color = false;
  const HitAttributes at = scene.accel->attributes(hit);
  Vec3& base = in.unlit ? p.emissive : p.base;  // unlit: the base colour is emitted
  if (in.base_tex.used()) base = base * lookup(scene, in.base_tex, at);
  if (in.vertex_color) base = base * at.color;
  if (in.metal_rough_tex.used()) {  // roughness in G, metalness in B
    const Vec3 mr = lookup(scene, in.metal_rough_tex, at);
    p.roughness *= mr.y;
    p.metallic *= mr.z;
  }
  if (in.emissive_tex.used()) p.emissive = p.emissive * lookup(scene, in.emissive_tex, at);
  if (in.transmission_tex.used()) p.transmission *= lookup(scene, in.transmission_tex, at).x;
  if (in.specular_tex.used()) p.specular *= alpha_lookup(scene, in.specular_tex, at);
  if (in.specular_color_tex.used()) p.specular_color = p.specular_color * lookup(scene, in.specular_color_tex, at);
  if (in.clearcoat_tex.used()) p.clearcoat *= lookup(scene, in.clearcoat_tex, at).x;
  if (in.clearcoat_roughness_tex.used()) p.clearcoat_roughness *= lookup(scene, in.clearcoat_roughness_tex, at).y;
  if (in.sheen_color_tex.used()) p.sheen_color = p.sheen_color * lookup(scene, in.sheen_color_tex, at);
  if (in.sheen_roughness_tex.used()) p.sheen_roughness *= alpha_lookup(scene, in.sheen_roughness_tex, at);
  const Vec3 unbent = ns;
  if (in.normal_tex.used()) ns = bend(ns, at, tangent_normal(scene, in.normal_tex, in.normal_scale, at));
  // The coat has its own normal: its map's, else the unbent one (KHR_materials_clearcoat). It is
  // put into the shading frame once the path vertex has built it (localize_coat).
  t_coat_world = Vec3(0.0f);
  if (p.clearcoat > 0 && (in.normal_tex.used() || in.clearcoat_normal_tex.used()))
    t_coat_world = in.clearcoat_normal_tex.used()
                       ? bend(unbent, at, tangent_normal(scene, in.clearcoat_normal_tex, in.clearcoat_normal_scale, at))
                       : unbent;
  return scratch;
}

}  // namespace pt
