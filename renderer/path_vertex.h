// The path vertex (integrator.cpp, path_pool.cpp): what one camera path does with the answer to
// its ray query. Emission, direct lighting (light sampling with MIS, or the course's uniform
// hemisphere estimator), BSDF bounces with the course's depth semantics, Russian roulette. Both
// loops run it, path by path and in the pool, so they trace the same paths from the same draws.
//
// Depth: a camera ray has max_depth levels; each bounce (diffuse, glossy or specular) uses one.
// m = 0 shows emitters only; m = 1 adds direct light; all bounce orders up to m are summed.
// MIS: Veach 1997 ch. 9, power heuristic, light sampling taking `light_samples` samples.
#pragma once

#include "lane_math.h"
#include "path_settings.h"
#include "render_scene.h"
#include "materials.h"
#include "sampler.h"

namespace pt::path_loop {

// BSDF dispatch reduced to the material kinds the scene has (feature bits, render_scene.h): a scene
// without microfacet or delta materials calls the inline Lambertian lobe directly.
template <uint32_t F>
inline bool has_delta(const Material& m) {
  if constexpr ((F & kFeatDelta) != 0) return is_delta(m);
  else return false;
}
template <uint32_t F>
inline bool has_transmission(const Material& m) {
  if constexpr ((F & kFeatDelta) != 0) return is_transmissive(m);
  else return false;
}
template <uint32_t F>
inline Vec3 eval_f(const Material& m, Vec3 wo, Vec3 wi) {
  if constexpr ((F & kFeatMicrofacet) != 0) return eval_bsdf(m, wo, wi);
  else return m.type == MaterialType::diffuse ? diffuse_eval(m, wo, wi) : Vec3(0.0f);
}
template <uint32_t F>
inline float pdf_f(const Material& m, Vec3 wo, Vec3 wi) {
  if constexpr ((F & kFeatMicrofacet) != 0) return bsdf_pdf(m, wo, wi);
  else return m.type == MaterialType::diffuse ? diffuse_pdf(wo, wi) : 0.0f;
}
template <uint32_t F>
inline bool sample_f(const Material& m, Vec3 wo, float u_lobe, Vec2 u, BsdfSample& s) {
  if constexpr ((F & (kFeatMicrofacet | kFeatDelta)) != 0) return sample_bsdf(m, wo, u_lobe, u, s);
  else return m.type == MaterialType::diffuse && diffuse_sample(m, wo, u, s);
}

struct Vertex {
  const SurfaceHit& hit;
  const Material& material;
  Frame frame;
  Vec3 ng;  // geometric normal, flipped to the viewer's side for opaque surfaces
  Vec3 wo;  // local
  bool transmissive;  // light may arrive from either side
};

inline int samples_for(const Light& light, const PathSettings& settings) {
  return light.is_delta() ? 1 : settings.light_samples;
}

// The shadow ray of a light sample, written into r.
inline void shadow_ray(const SurfaceHit& hit, const LightSample& ls, Ray& r) {
  if (ls.infinite) spawn_ray(hit, ls.wi, r);
  else spawn_ray_to(hit, ls.point, r);
}

// Light sampling at a non-delta vertex, every light, MIS-weighted against BSDF sampling. Each
// sample that needs a shadow ray writes it to `shadow.ray()` and hands it over with `shadow.add(c)`,
// which adds c to the vertex's sum unless the ray is blocked (at once, or after a batch).
template <uint32_t F, class ShadowSink>
void direct_light_sampling(const RenderScene& scene, const PathSettings& settings, const Vertex& v, Sampler& rng,
                           uint64_t& rays, ShadowSink& shadow) {
  for (const Light& light : scene.lights) {
    int n = samples_for(light, settings);
    for (int k = 0; k < n; ++k) {
      LightSample ls;
      Vec2 u = rng.next_2d();
      if (!sample_light(light, v.hit.p, u, ls)) continue;
      if (!v.transmissive && !lane1::above_surface(ls.wi, v.ng)) continue;
      Vec3 wi = v.frame.to_local(ls.wi);
      Vec3 f = eval_f<F>(v.material, v.wo, wi);
      if (is_black(f) || is_black(ls.radiance)) continue;
      ++rays;
      float w = light.is_delta() ? 1.0f : power_heuristic(n * ls.pdf, pdf_f<F>(v.material, v.wo, wi));
      shadow_ray(v.hit, ls, shadow.ray());  // in place: see spawn_ray
      shadow.add(lane1::light_sample_share(f, ls.radiance, wi.z, w, ls.pdf, float(n)));
    }
  }
}

// The course's -H estimator: (lights x light_samples) uniform hemisphere rays that count what
// emits where they land.
template <uint32_t F>
Vec3 direct_hemisphere(const RenderScene& scene, const PathSettings& settings, const Vertex& v, Sampler& rng,
                       uint64_t& rays) {
  int n = int(scene.lights.size()) * settings.light_samples;
  if (n == 0) return Vec3(0.0f);
  Vec3 sum(0.0f);
  for (int k = 0; k < n; ++k) {
    Vec3 wi = sample_uniform_hemisphere(rng.next_2d());
    Vec3 wi_world = v.frame.to_world(wi);
    if (dot(wi_world, v.ng) <= 0) continue;
    Vec3 f = eval_f<F>(v.material, v.wo, wi);
    if (is_black(f)) continue;
    SurfaceHit h;
    ++rays;
    Vec3 le(0.0f);
    if (scene.accel->intersect(spawn_ray(v.hit, wi_world), h)) {
      const Material& m = scene.materials[h.material];
      le = emitted_radiance(m, Vec3(0, 0, dot(-wi_world, h.ng)));
    } else {
      if constexpr ((F & kFeatInfinite) != 0)
        for (int i : scene.infinite_lights) le += infinite_light_radiance(scene.lights[i], wi_world);
    }
    sum += f * le * wi.z;
  }
  return sum * (2 * kPi / n);
}

// One camera path between ray queries: the ray to trace next, what it has gathered so far, and
// the light sampling of its current vertex until that vertex's shadow rays are answered.
// Its starting values are set in one place, start().
struct PathState {
  Ray ray;
  Vec3 radiance, beta;
  Vec3 direct_beta, direct_sum;  // radiance += direct_beta * direct_sum once resolved
  bool has_direct;
  bool specular;  // the camera ray counts as specular: emitters it sees get full weight
  // Where the path stands against the light tracer's share (caustics.h), paths E D+ S+ L: non-delta
  // vertices only so far (1), then delta bounces only (2), or neither (0).
  int caustic_phase;
  float prev_pdf;
  Vec3 prev_p;
  int depth_left;
  int bounce;
  // The denoiser's features (denoiser.h) at the first vertex that is not a perfect mirror or glass,
  // or where the path leaves the scene: its albedo (x the delta bounces' tint before it) and its
  // shading normal turned to the viewer. Zero where the path ends before; `want_features` until set.
  bool want_features;
  Vec3 albedo, normal;

  PathState() { start(Ray(), 0); }
  PathState(const Ray& camera_ray, int max_depth, bool features = false) { start(camera_ray, max_depth, features); }
  // Every field set in place (a pool slot takes its next path here; see spawn_ray in accel.h).
  void start(const Ray& camera_ray, int max_depth, bool features = false) {
    want_features = features;
    albedo = Vec3(0.0f), normal = Vec3(0.0f);
    ray = camera_ray;
    radiance = Vec3(0.0f), beta = Vec3(1.0f);
    direct_beta = Vec3(0.0f), direct_sum = Vec3(0.0f);
    has_direct = false;
    specular = true;
    caustic_phase = 0;
    prev_pdf = 0;
    prev_p = Vec3();
    depth_left = max_depth;
    bounce = 0;
  }
  // The features of the vertex the path stands at (or of the background it left to).
  void set_features(Vec3 surface_albedo, Vec3 facing_normal) {
    const Vec3 tint = min(beta, Vec3(1.0f));  // the delta bounces' colour so far
    albedo = surface_albedo * tint, normal = facing_normal;
    want_features = false;
  }
  // A diffuse vertex's start and its bounce, as the lanes' text takes them at any width: its light
  // sampling weighed by the throughput it arrived with, then the bounce's bookkeeping (vertex
  // number `bounce`, its pdf, at point p).
  void start_diffuse_vertex() {
    has_direct = true;
    direct_beta = beta;
  }
  void took_diffuse_bounce(int bounce, float pdf, Vec3 p) {
    specular = false;
    if (bounce == 0) caustic_phase = 1;
    else if (caustic_phase == 2) caustic_phase = 0;
    prev_pdf = pdf;
    prev_p = p;
    --depth_left;
  }
  // Adds the current vertex's light sampling, after its shadow rays (and before the next vertex).
  void resolve_direct() {
    if (has_direct) radiance += direct_beta * direct_sum;
    has_direct = false;
    direct_sum = Vec3(0.0f);
  }
};

// What one path does with the answer to its ray query: emission, light sampling (shadow rays go to
// `shadow`), the BSDF bounce and Russian roulette. Returns false when the path ends; otherwise
// st.ray is the next ray. The scalar loop and the batched one both run it, so they trace the same
// paths from the same random numbers. (The pool takes diffuse vertices under area lights to its
// SIMD lanes instead, whose bits are this vertex's: diffuse_lanes.h.)
template <uint32_t F, class ShadowSink>
bool path_step(const RenderScene& scene, const PathSettings& settings, PathState& st, bool found, const SurfaceHit& hit,
               Sampler& rng, uint64_t& rays, ShadowSink& shadow) {
  const int bounce = st.bounce++;
  if (!found) {
    if (st.want_features) {  // the background's colour, no normal (OIDN's convention for no surface)
      Vec3 le(0.0f);
      if constexpr ((F & kFeatInfinite) != 0)
        if (scene.environment_light >= 0) le = infinite_light_radiance(scene.lights[scene.environment_light], st.ray.d);
      st.set_features(min(le, Vec3(1.0f)), Vec3(0.0f));
    }
    if constexpr ((F & kFeatInfinite) != 0) {
      for (int i : scene.infinite_lights) {
        const Light& light = scene.lights[i];
        if (bounce == 0 && i != scene.environment_light) continue;  // ambient is not seen directly
        Vec3 le = infinite_light_radiance(light, st.ray.d);
        if (is_black(le)) continue;
        float w = 1;
        if (!st.specular)
          w = settings.hemisphere ? 0.0f
                                : power_heuristic(st.prev_pdf, samples_for(light, settings) * infinite_light_pdf(light, st.ray.d));
        st.radiance += st.beta * le * w;
      }
    }
    return false;
  }

  const Material* file_material = &scene.materials[hit.material];
  Vec3 ns = hit.ns;  // a normal map may bend it
  if constexpr ((F & kFeatTexture) != 0) file_material = &material_at(scene, *file_material, hit, ns);  // used within this call
  const Material& material = *file_material;
  Vec3 wo_world = -st.ray.d;
  if (st.want_features && !has_delta<F>(material))
    st.set_features(feature_albedo(material), dot(ns, wo_world) < 0 ? -ns : ns);
  if constexpr ((F & kFeatTexture) != 0) {
    // KHR_materials_volume: the segment just travelled lay inside the mesh (Beer-Lambert).
    const Vec3 sigma = material.pbr.attenuation;
    if (material.type == MaterialType::pbr && !is_black(sigma) && dot(st.ray.d, hit.ng) > 0) {
      const float d = length(hit.p - st.ray.o);
      st.beta = st.beta * Vec3(std::exp(-sigma.x * d), std::exp(-sigma.y * d), std::exp(-sigma.z * d));
    }
  }
  if (material.type == MaterialType::emission || (material.type == MaterialType::pbr && is_emissive(material))) {
    Vec3 le = emitted_radiance(material, Vec3(0, 0, dot(wo_world, hit.ng)));
    if (material.type == MaterialType::pbr && material.pbr.unlit && bounce > 0) le = Vec3(0.0f);  // camera rays only
    bool light_traced = false;
    if constexpr ((F & kFeatDelta) != 0)
      light_traced = settings.caustics_light_traced && st.caustic_phase == 2 && hit.light >= 0;
    if (!is_black(le) && !light_traced) {
      float w = 1;
      if (!st.specular) {
        if (settings.hemisphere) w = 0;
        else if (hit.light >= 0) {
          const Light& light = scene.lights[hit.light];
          w = power_heuristic(st.prev_pdf, samples_for(light, settings) * area_light_pdf(light, st.prev_p, hit.p, hit.ng));
        }
      }
      st.radiance += st.beta * le * w;
    }
    if (material.type == MaterialType::emission) return false;  // the course's emitters reflect nothing
  }
  if (st.depth_left == 0) return false;

  // Shading frame. Opaque surfaces are two-sided: turn the normals towards the viewer.
  Vec3 ng = hit.ng;
  bool transmissive = has_transmission<F>(material);
  const Vec3 ns_hit = ns;
  face_viewer(wo_world, transmissive, ng, ns);
  Vertex v{hit, material, Frame(ns), ng, Vec3(), transmissive};
  if constexpr ((F & kFeatTexture) != 0)
    if (material.pbr.clearcoat > 0) localize_coat(material, v.frame, dot(ns_hit, ns) < 0);
  v.wo = v.frame.to_local(wo_world);

  if (!has_delta<F>(material)) {
    st.has_direct = true;
    st.direct_beta = st.beta;
    if (settings.hemisphere) st.direct_sum = direct_hemisphere<F>(scene, settings, v, rng, rays);
    else direct_light_sampling<F>(scene, settings, v, rng, rays, shadow);
  }

  BsdfSample bs;
  // Only glass, refraction and the glTF material choose a lobe; others skip that draw unevaluated.
  float u_lobe = 0;
  if (transmissive || material.type == MaterialType::pbr) u_lobe = rng.next_float();
  else rng.skip_1d();
  Vec2 u;  // delta lobes need no direction sample: skipped, the draws after it stay the same
  if (has_delta<F>(material)) rng.skip_2d();
  else u = rng.next_2d();
  if (!sample_f<F>(material, v.wo, u_lobe, u, bs)) return false;
  Vec3 wi_world = v.frame.to_world(bs.wi);
  // Reflection must leave on the viewer's side of the true surface (no shading-normal leaks).
  if (!transmissive && !lane1::above_surface(wi_world, ng)) return false;
  st.beta *= bs.weight;
  if (!lane1::is_live(st.beta)) return false;
  st.specular = bs.delta;
  if (bounce == 0) st.caustic_phase = bs.delta ? 0 : 1;
  else if (st.caustic_phase == 1 && bs.delta) st.caustic_phase = 2;
  else if (st.caustic_phase == 2 && !bs.delta) st.caustic_phase = 0;
  st.prev_pdf = bs.pdf;
  st.prev_p = hit.p;
  --st.depth_left;

  // Russian roulette from kRouletteStart: unbiased, and it bounds the path length for any -m.
  if (bounce >= kRouletteStart && !lane1::russian_roulette(true, rng.next_float(), st.beta)) return false;
  spawn_ray(hit, wi_world, st.ray);
  return true;
}

}  // namespace pt::path_loop
