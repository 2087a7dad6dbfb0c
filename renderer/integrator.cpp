// The path loop: emission, direct lighting (light sampling with MIS, or the course's uniform
// hemisphere estimator), BSDF bounces with the course's depth semantics, Russian roulette.
//
// Depth: a camera ray has max_depth levels; each bounce (diffuse, glossy or specular) uses one.
// m = 0 shows emitters only; m = 1 adds direct light; all bounce orders up to m are summed.
// MIS: Veach 1997 ch. 9, power heuristic, light sampling taking `light_samples` samples.
#include "materials.h"
#include "render.h"
#include "sampler.h"

namespace pt {

namespace {

// Russian roulette starts at bounce 5, as Mitsuba 3's path integrator does (rr_depth = 5).
// Starting at 3 cut rays but cost more variance than it saved time on caustic-heavy scenes:
// efficiency on CBspheres -17% (m = 5) and -14% (m = 100), CBdragon -6%, CBbunny +6%
// (bench/vs_mitsuba.py, docs/performance.md).
constexpr int kRouletteStart = 5;

// BSDF dispatch reduced to the material kinds the scene has (feature bits, render.h): a scene
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
};

int samples_for(const Light& light, const RenderParams& params) {
  return light.is_delta() ? 1 : params.light_samples;
}

// Light sampling at a non-delta vertex, every light, MIS-weighted against BSDF sampling.
template <uint32_t F>
Vec3 direct_light_sampling(const RenderScene& scene, const RenderParams& params, const Vertex& v, Sampler& rng,
                           uint64_t& rays) {
  Vec3 sum(0.0f);
  for (const Light& light : scene.lights) {
    int n = samples_for(light, params);
    for (int k = 0; k < n; ++k) {
      LightSample ls;
      Vec2 u = rng.next_2d();
      if (!sample_light(light, v.hit.p, u, ls)) continue;
      if (dot(ls.wi, v.ng) <= 0) continue;  // below the surface
      Vec3 wi = v.frame.to_local(ls.wi);
      Vec3 f = eval_f<F>(v.material, v.wo, wi);
      if (is_black(f) || is_black(ls.radiance)) continue;
      Ray shadow = ls.infinite ? spawn_ray(v.hit, ls.wi) : spawn_ray_to(v.hit, ls.point);
      ++rays;
      if (scene.accel->occluded(shadow)) continue;
      float w = light.is_delta() ? 1.0f : power_heuristic(n * ls.pdf, pdf_f<F>(v.material, v.wo, wi));
      sum += f * ls.radiance * (std::fabs(wi.z) * w / (ls.pdf * n));
    }
  }
  return sum;
}

// The course's -H estimator: (lights x light_samples) uniform hemisphere rays that count what
// emits where they land.
template <uint32_t F>
Vec3 direct_hemisphere(const RenderScene& scene, const RenderParams& params, const Vertex& v, Sampler& rng,
                       uint64_t& rays) {
  int n = int(scene.lights.size()) * params.light_samples;
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

template <uint32_t F>
Vec3 trace_path_t(const RenderScene& scene, const RenderParams& params, Ray ray, Sampler& rng, uint64_t& rays) {
  Vec3 radiance(0.0f), beta(1.0f);
  bool specular = true;  // the camera ray counts as specular: emitters it sees get full weight
  // Where the path stands against the light tracer's share (caustics.h), paths E D+ S+ L: non-delta
  // vertices only so far (1), then delta bounces only (2), or neither (0).
  int caustic_phase = 0;
  float prev_pdf = 0;
  Vec3 prev_p;
  int depth_left = params.max_depth;
  for (int bounce = 0;; ++bounce) {
    SurfaceHit hit;
    ++rays;
    if (!scene.accel->intersect(ray, hit)) {
      if constexpr ((F & kFeatInfinite) == 0) break;
      for (int i : scene.infinite_lights) {
        const Light& light = scene.lights[i];
        if (bounce == 0 && i != scene.environment_light) continue;  // ambient is not seen directly
        Vec3 le = infinite_light_radiance(light, ray.d);
        if (is_black(le)) continue;
        float w = 1;
        if (!specular)
          w = params.hemisphere ? 0.0f
                                : power_heuristic(prev_pdf, samples_for(light, params) * infinite_light_pdf(light, ray.d));
        radiance += beta * le * w;
      }
      break;
    }

    const Material& material = scene.materials[hit.material];
    Vec3 wo_world = -ray.d;
    if (material.type == MaterialType::emission) {
      Vec3 le = emitted_radiance(material, Vec3(0, 0, dot(wo_world, hit.ng)));
      bool light_traced = false;
      if constexpr ((F & kFeatDelta) != 0)
        light_traced = params.caustics_light_traced && caustic_phase == 2 && hit.light >= 0;
      if (!is_black(le) && !light_traced) {
        float w = 1;
        if (!specular) {
          if (params.hemisphere) w = 0;
          else if (hit.light >= 0) {
            const Light& light = scene.lights[hit.light];
            w = power_heuristic(prev_pdf, samples_for(light, params) * area_light_pdf(light, prev_p, hit.p, hit.ng));
          }
        }
        radiance += beta * le * w;
      }
      break;  // emitters reflect nothing
    }
    if (depth_left == 0) break;

    // Shading frame. Opaque surfaces are two-sided: turn the normals towards the viewer.
    Vec3 ng = hit.ng, ns = hit.ns;
    bool transmissive = has_transmission<F>(material);
    face_viewer(wo_world, transmissive, ng, ns);
    Vertex v{hit, material, Frame(ns), ng, Vec3()};
    v.wo = v.frame.to_local(wo_world);

    if (!has_delta<F>(material))
      radiance += beta * (params.hemisphere ? direct_hemisphere<F>(scene, params, v, rng, rays)
                                            : direct_light_sampling<F>(scene, params, v, rng, rays));

    BsdfSample bs;
    // Only glass and refraction choose a lobe; other materials skip that draw unevaluated.
    float u_lobe = 0;
    if (transmissive) u_lobe = rng.next_float();
    else rng.skip_1d();
    Vec2 u = rng.next_2d();
    if (!sample_f<F>(material, v.wo, u_lobe, u, bs)) break;
    Vec3 wi_world = v.frame.to_world(bs.wi);
    // Reflection must leave on the viewer's side of the true surface (no shading-normal leaks).
    if (!transmissive && dot(wi_world, ng) <= 0) break;
    beta *= bs.weight;
    if (is_black(beta) || !is_finite(beta)) break;
    specular = bs.delta;
    if (bounce == 0) caustic_phase = bs.delta ? 0 : 1;
    else if (caustic_phase == 1 && bs.delta) caustic_phase = 2;
    else if (caustic_phase == 2 && !bs.delta) caustic_phase = 0;
    prev_pdf = bs.pdf;
    prev_p = hit.p;
    --depth_left;

    // Russian roulette from kRouletteStart: unbiased, and it bounds the path length for any -m.
    if (bounce >= kRouletteStart) {
      float q = std::min(0.95f, max_component(beta));
      if (rng.next_float() >= q) break;
      beta /= q;
    }
    ray = spawn_ray(hit, wi_world);
  }
  return radiance;
}

}  // namespace

Vec3 trace_path(const RenderScene& scene, const RenderParams& params, Ray ray, Sampler& rng, uint64_t& rays) {
  return trace_path_t<kFeatAll>(scene, params, ray, rng, rays);
}

PathTracer path_tracer_for(uint32_t bits) {
  static const PathTracer table[] = {
      trace_path_t<0>, trace_path_t<1>, trace_path_t<2>, trace_path_t<3>,
      trace_path_t<4>, trace_path_t<5>, trace_path_t<6>, trace_path_t<7>,
  };
  static_assert(sizeof(table) / sizeof(table[0]) == kFeatAll + 1, "one instantiation per feature combination");
  return table[bits & kFeatAll];
}

}  // namespace pt
