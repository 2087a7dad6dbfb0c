// The path loop: emission, direct lighting (light sampling with MIS, or the course's uniform
// hemisphere estimator), BSDF bounces with the course's depth semantics, Russian roulette.
//
// Depth: a camera ray has max_depth levels; each bounce (diffuse, glossy or specular) uses one.
// m = 0 shows emitters only; m = 1 adds direct light; all bounce orders up to m are summed.
// MIS: Veach 1997 ch. 9, power heuristic, light sampling taking `light_samples` samples.
#include <memory>

#include "diffuse_lanes.h"
#include "materials.h"
#include "integrator.h"
#include "sampler.h"

namespace pt {

namespace {

// Russian roulette starts at bounce 5, as Mitsuba 3's path integrator does (rr_depth = 5).
// Starting at 3 cut rays but cost more variance than it saved time on caustic-heavy scenes:
// efficiency on CBspheres -17% (m = 5) and -14% (m = 100), CBdragon -6%, CBbunny +6%
// (bench/vs_mitsuba.py, docs/performance.md).
constexpr int kRouletteStart = 5;

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
};

int samples_for(const Light& light, const PathSettings& settings) {
  return light.is_delta() ? 1 : settings.light_samples;
}

// The shadow ray of a light sample, written into r.
inline void shadow_ray(const SurfaceHit& hit, const LightSample& ls, Ray& r) {
  if (ls.infinite) spawn_ray(hit, ls.wi, r);
  else spawn_ray_to(hit, ls.point, r);
}

// Light sampling at a non-delta vertex, every light, MIS-weighted against BSDF sampling. Each
// sample that needs a shadow ray hands it to `shadow(hit, sample, contribution)`, which adds the
// contribution to the vertex's sum unless its shadow_ray is blocked (at once, or after a batch).
template <uint32_t F, class ShadowSink>
void direct_light_sampling(const RenderScene& scene, const PathSettings& settings, const Vertex& v, Sampler& rng,
                           uint64_t& rays, ShadowSink&& shadow) {
  for (const Light& light : scene.lights) {
    int n = samples_for(light, settings);
    for (int k = 0; k < n; ++k) {
      LightSample ls;
      Vec2 u = rng.next_2d();
      if (!sample_light(light, v.hit.p, u, ls)) continue;
      if (!lane1::above_surface(ls.wi, v.ng)) continue;
      Vec3 wi = v.frame.to_local(ls.wi);
      Vec3 f = eval_f<F>(v.material, v.wo, wi);
      if (is_black(f) || is_black(ls.radiance)) continue;
      ++rays;
      float w = light.is_delta() ? 1.0f : power_heuristic(n * ls.pdf, pdf_f<F>(v.material, v.wo, wi));
      shadow(v.hit, ls, lane1::light_sample_share(f, ls.radiance, wi.z, w, ls.pdf, float(n)));
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

  PathState() { start(Ray(), 0); }
  PathState(const Ray& camera_ray, int max_depth) { start(camera_ray, max_depth); }
  // Every field set in place (a pool slot takes its next path here; see spawn_ray in accel.h).
  void start(const Ray& camera_ray, int max_depth) {
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
// paths from the same random numbers.
template <uint32_t F, class ShadowSink>
bool path_step(const RenderScene& scene, const PathSettings& settings, PathState& st, bool found, const SurfaceHit& hit,
               Sampler& rng, uint64_t& rays, ShadowSink&& shadow) {
  const int bounce = st.bounce++;
  if (!found) {
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
  if constexpr ((F & kFeatTexture) != 0) file_material = &material_at(scene, *file_material, hit);  // used within this call
  const Material& material = *file_material;
  Vec3 wo_world = -st.ray.d;
  if (material.type == MaterialType::emission) {
    Vec3 le = emitted_radiance(material, Vec3(0, 0, dot(wo_world, hit.ng)));
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
    return false;  // emitters reflect nothing
  }
  if (st.depth_left == 0) return false;

  // Shading frame. Opaque surfaces are two-sided: turn the normals towards the viewer.
  Vec3 ng = hit.ng, ns = hit.ns;
  bool transmissive = has_transmission<F>(material);
  face_viewer(wo_world, transmissive, ng, ns);
  Vertex v{hit, material, Frame(ns), ng, Vec3()};
  v.wo = v.frame.to_local(wo_world);

  if (!has_delta<F>(material)) {
    st.has_direct = true;
    st.direct_beta = st.beta;
    if (settings.hemisphere) st.direct_sum = direct_hemisphere<F>(scene, settings, v, rng, rays);
    else direct_light_sampling<F>(scene, settings, v, rng, rays, shadow);
  }

  BsdfSample bs;
  // Only glass and refraction choose a lobe; other materials skip that draw unevaluated.
  float u_lobe = 0;
  if (transmissive) u_lobe = rng.next_float();
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

// One path at a time: every ray query answered at once.
template <uint32_t F>
Vec3 trace_path_t(const RenderScene& scene, const PathSettings& settings, Ray ray, Sampler& rng, uint64_t& rays) {
  PathState st(ray, settings.max_depth);
  auto shadow = [&](const SurfaceHit& hit, const LightSample& ls, Vec3 contribution) {
    Ray r;
    shadow_ray(hit, ls, r);
    if (!scene.accel->occluded(r)) st.direct_sum += contribution;
  };
  for (;;) {
    SurfaceHit hit;
    ++rays;
    bool found = scene.accel->intersect(st.ray, hit);
    bool more = path_step<F>(scene, settings, st, found, hit, rng, rays, shadow);
    st.resolve_direct();
    if (!more) return st.radiance;
  }
}

// A path of the pool, and a shadow ray's share of its vertex's light.
struct PoolSlot {
  PathState st;
  uint32_t job = 0;
};
struct PendingShadow {
  uint32_t slot;
  Vec3 contribution;
};
// A pool step's shadow rays [0, n) and what each adds where unblocked. The arrays only grow and
// their entries are written in place: resized every step, they would first store a default Ray
// and PendingShadow (both have member initialisers) for every entry.
struct ShadowBatch {
  std::vector<Ray> rays;
  std::vector<PendingShadow> pending;
  size_t n = 0;
  void make_room(size_t more) {
    if (rays.size() < n + more) rays.resize(n + more), pending.resize(n + more);
  }
};

// path_step for the pool's slots which[0, n), all of them at a diffuse hit with depth left, in lanes
// (diffuse_lanes.h): the draws in path_step's order (light samples, the unused lobe number, the bounce,
// roulette), light passes light by light, the bounce. The same bits as path_step.
void diffuse_in_lanes(const RenderScene& scene, const PathSettings& settings, lanes::DiffuseVertices& v, const uint32_t* which,
                      int n, std::vector<PoolSlot>& slots, Sampler* rngs, const SurfaceHit* hits, uint8_t* alive,
                      uint64_t& rays, ShadowBatch& shadows) {
  const int padded = (n + 7) & ~7;  // whole vectors of either width
  const size_t nl = scene.lights.size() * size_t(settings.light_samples);  // draws, light by light
  static thread_local std::vector<Vec2> u_light, u;
  static thread_local std::vector<Sampler*> samplers;
  u_light.resize(size_t(n) * nl);
  u.resize(size_t(n));
  samplers.resize(size_t(n));
  for (int j = 0; j < n; ++j) samplers[size_t(j)] = &rngs[slots[which[j]].job];
  const bool textures = scene.features.textured;
  // The draws of path_step's order (light samples, the BSDF's component pick, the bounce), taken
  // for all vertices at once: each sampler still sees its own draws in that order.
  for (size_t l = 0; l < nl; ++l)  // light sample l of every vertex: u_light[l n, (l + 1) n)
    Sampler::next_2d_many(samplers.data(), size_t(n), u_light.data() + l * size_t(n), scene.loop.lanes);
  for (Sampler* rng : samplers) rng->skip_1d();
  Sampler::next_2d_many(samplers.data(), size_t(n), u.data(), scene.loop.lanes);
  for (int j = 0; j < padded; ++j) {
    const uint32_t i = which[j < n ? j : 0];  // padding lanes repeat the first vertex
    PathState& st = slots[i].st;
    const SurfaceHit& h = hits[i];
    const Material& m = scene.materials[h.material];
    const Vec3 albedo = textures && m.textured() ? albedo_at(scene, m, h) : m.albedo;
    v.px[j] = h.p.x, v.py[j] = h.p.y, v.pz[j] = h.p.z;
    v.gx[j] = h.ng.x, v.gy[j] = h.ng.y, v.gz[j] = h.ng.z;
    v.nx[j] = h.ns.x, v.ny[j] = h.ns.y, v.nz[j] = h.ns.z;
    v.offset[j] = h.offset;
    v.ax[j] = albedo.x, v.ay[j] = albedo.y, v.az[j] = albedo.z;
    v.dx[j] = st.ray.d.x, v.dy[j] = st.ray.d.y, v.dz[j] = st.ray.d.z;
    v.bx[j] = st.beta.x, v.by[j] = st.beta.y, v.bz[j] = st.beta.z;
    if (j >= n) {
      v.ubx[j] = v.ubx[0], v.uby[j] = v.uby[0], v.roulette[j] = v.roulette[0], v.urr[j] = v.urr[0];
      continue;
    }
    v.ubx[j] = u[size_t(j)].x, v.uby[j] = u[size_t(j)].y;
    v.roulette[j] = st.bounce >= kRouletteStart;
    v.urr[j] = v.roulette[j] ? samplers[size_t(j)]->next_float() : 0.0f;
    st.has_direct = true;
    st.direct_beta = st.beta;
  }
  for (size_t l = 0; l < nl; ++l) {
    const Light& light = scene.lights[l / size_t(settings.light_samples)];
    if (is_black(light.color)) continue;
    for (int j = 0; j < padded; ++j) {
      Vec2 u = u_light[l * size_t(n) + size_t(j < n ? j : 0)];
      v.ulx[j] = u.x, v.uly[j] = u.y;
      if (light.kind == LightKind::mesh) {
        Vec3 q, normal;
        sample_area_light_point(light, u, q, normal);
        v.qx[j] = q.x, v.qy[j] = q.y, v.qz[j] = q.z;
        v.lx[j] = normal.x, v.ly[j] = normal.y, v.lz[j] = normal.z;
      }
    }
    lanes::light_pass(v, padded, light, settings.light_samples);
    shadows.make_room(size_t(n));  // at most a shadow ray a vertex
    const size_t first = shadows.n;
    for (int j = 0; j < n; ++j) {
      if (!v.shadow[j]) continue;
      Ray& r = shadows.rays[shadows.n];
      r.o = Vec3(v.sox[j], v.soy[j], v.soz[j]);
      r.d = Vec3(v.sdx[j], v.sdy[j], v.sdz[j]);
      r.tmin = 0;
      r.tmax = kShadowRayEnd;  // as spawn_ray_to
      PendingShadow& s = shadows.pending[shadows.n++];
      s.slot = which[j];
      s.contribution = Vec3(v.cx[j], v.cy[j], v.cz[j]);
    }
    rays += shadows.n - first;
  }
  lanes::bounce_pass(v, padded);
  for (int j = 0; j < n; ++j) {
    const uint32_t i = which[j];
    PathState& st = slots[i].st;
    const int bounce = st.bounce++;
    alive[i] = v.alive[j] != 0;
    if (!alive[i]) continue;
    st.beta = Vec3(v.bx[j], v.by[j], v.bz[j]);
    st.specular = false;
    if (bounce == 0) st.caustic_phase = 1;
    else if (st.caustic_phase == 2) st.caustic_phase = 0;
    st.prev_pdf = v.pdf[j];
    st.prev_p = hits[i].p;
    --st.depth_left;
    st.ray.o = Vec3(v.ox[j], v.oy[j], v.oz[j]);
    st.ray.d = Vec3(v.wx[j], v.wy[j], v.wz[j]);
    st.ray.tmin = 0;
    st.ray.tmax = kInf;
  }
}

// Many paths at once (Embree packets, Accel::intersect_many): a pool of paths advances one vertex at a time, all
// their rays traced together, then all their shadow rays; a finished path's slot takes the next
// one. The same paths as the scalar loop, up to the packet kernel's rounding of a few hits.
template <uint32_t F>
void trace_paths_t(const RenderScene& scene, const PathSettings& settings, const Ray* camera_rays, Sampler* rngs,
                   size_t n, Vec3* out, uint64_t& rays) {
  constexpr size_t kSlots = lanes::kMaxLanes;  // 64 to 4096 measured the same on CBdragon
  using Slot = PoolSlot;
  using Shadow = PendingShadow;
  const bool use_lanes = diffuse_lanes_apply(scene, settings);
  // The pool's arrays live on the thread between calls: a call per flush of a few thousand paths
  // would otherwise zero some 60 KB each time.
  struct Pool {
    std::unique_ptr<lanes::DiffuseVertices> lane_data;
    std::vector<uint32_t> in_lanes = std::vector<uint32_t>(kSlots);
    std::vector<Slot> slots = std::vector<Slot>(kSlots);

    std::vector<SurfaceHit> hits = std::vector<SurfaceHit>(kSlots);
    std::vector<uint8_t> found = std::vector<uint8_t>(kSlots), alive = std::vector<uint8_t>(kSlots), blocked;
    ShadowBatch shadows;
  };
  static thread_local Pool pool;
  if (use_lanes && !pool.lane_data) pool.lane_data = std::make_unique<lanes::DiffuseVertices>();
  // References, not a structured binding: C++17 lambdas cannot capture those (clang).
  auto& lane_data = pool.lane_data;
  auto& in_lanes = pool.in_lanes;
  auto& slots = pool.slots;
  auto& hits = pool.hits;
  auto& found = pool.found;
  auto& alive = pool.alive;
  auto& blocked = pool.blocked;
  auto& shadows = pool.shadows;
  size_t live = 0;  // slots [0, live) hold paths
  size_t next = 0;
  for (;;) {
    for (; live < kSlots && next < n; ++live, ++next) {
      slots[live].st.start(camera_rays[next], settings.max_depth);
      slots[live].job = uint32_t(next);
    }
    if (live == 0) return;
    const size_t m = live;
    rays += m;
    // The rays where they lie in the slots (PathState::ray), not copied out.
    scene.accel->intersect_many(&slots[0].st.ray, sizeof(Slot), m, hits.data(), found.data());
    shadows.n = 0;
    size_t n_lanes = 0;  // slots the lanes take: a diffuse hit with depth left
    for (size_t i = 0; i < m; ++i) {
      if (use_lanes && found[i] && slots[i].st.depth_left > 0 &&
          scene.materials[hits[i].material].type == MaterialType::diffuse) {
        in_lanes[n_lanes++] = uint32_t(i);
        continue;
      }
      auto shadow = [&](const SurfaceHit& hit, const LightSample& ls, Vec3 contribution) {
        shadows.make_room(1);
        shadow_ray(hit, ls, shadows.rays[shadows.n]);  // in place: see spawn_ray
        Shadow& s = shadows.pending[shadows.n++];
        s.slot = uint32_t(i);
        s.contribution = contribution;
      };
      alive[i] = path_step<F>(scene, settings, slots[i].st, found[i] != 0, hits[i], rngs[slots[i].job], rays, shadow);
    }
    if (n_lanes)
      diffuse_in_lanes(scene, settings, *lane_data, in_lanes.data(), int(n_lanes), slots, rngs, hits.data(), alive.data(),
                       rays, shadows);
    if (blocked.size() < shadows.n) blocked.resize(shadows.n);
    scene.accel->occluded_many(shadows.rays.data(), shadows.n, blocked.data());
    for (size_t k = 0; k < shadows.n; ++k)  // in order: each vertex sums its lights as the scalar loop does
      if (!blocked[k]) slots[shadows.pending[k].slot].st.direct_sum += shadows.pending[k].contribution;
    // A finished path's slot takes the next camera ray in place; once there are none, the last
    // slot moves into it (a copy of the whole state: only while the pool drains).
    for (size_t i = 0; i < live;) {
      slots[i].st.resolve_direct();
      if (alive[i]) {
        ++i;
        continue;
      }
      out[slots[i].job] = slots[i].st.radiance;
      if (next < n) {
        slots[i].st.start(camera_rays[next], settings.max_depth);
        slots[i].job = uint32_t(next++);
        ++i;
        continue;
      }
      --live;
      slots[i] = slots[live];
      alive[i] = alive[live];
    }
  }
}

}  // namespace

bool diffuse_lanes_apply(const RenderScene& scene, const PathSettings& settings) {
  if (!scene.loop.lanes || settings.hemisphere || settings.light_samples < 1) return false;
  for (const Light& light : scene.lights)  // the lanes know no other light
    if (light.kind != LightKind::rect && light.kind != LightKind::mesh) return false;
  return true;
}

Vec3 trace_path(const RenderScene& scene, const PathSettings& settings, Ray ray, Sampler& rng, uint64_t& rays) {
  return trace_path_t<kFeatAll>(scene, settings, ray, rng, rays);
}

// Textured scenes take the generic loop rather than eight more instantiations of each loop (build
// time, code size); they pay its run-time checks of the material kinds they lack.
PathBatchTracer path_batch_tracer_for(uint32_t bits, const PathSettings& settings) {
  if (settings.hemisphere) return nullptr;  // -H casts its direct-light rays one at a time
  if (bits & kFeatTexture) return trace_paths_t<kFeatAll>;
  static const PathBatchTracer table[] = {
      trace_paths_t<0>, trace_paths_t<1>, trace_paths_t<2>, trace_paths_t<3>,
      trace_paths_t<4>, trace_paths_t<5>, trace_paths_t<6>, trace_paths_t<7>,
  };
  static_assert(sizeof(table) / sizeof(table[0]) == kFeatTexture, "one instantiation per untextured feature combination");
  return table[bits & (kFeatTexture - 1)];
}

PathTracer path_tracer_for(uint32_t bits) {
  if (bits & kFeatTexture) return trace_path_t<kFeatAll>;
  static const PathTracer table[] = {
      trace_path_t<0>, trace_path_t<1>, trace_path_t<2>, trace_path_t<3>,
      trace_path_t<4>, trace_path_t<5>, trace_path_t<6>, trace_path_t<7>,
  };
  static_assert(sizeof(table) / sizeof(table[0]) == kFeatTexture, "one instantiation per untextured feature combination");
  return table[bits & (kFeatTexture - 1)];
}

}  // namespace pt
