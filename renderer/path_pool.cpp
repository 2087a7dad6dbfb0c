// The path loop many paths at once (integrator.h's PathTracer): a pool of camera paths whose
// rays go to Embree in packets, their diffuse vertices in SIMD lanes (diffuse_lanes.h), the rest
// through path_vertex.h's path_step one slot at a time.
#include "integrator.h"

#include <memory>

#include "diffuse_lanes.h"
#include "path_vertex.h"

namespace pt {

namespace {

using namespace path_loop;

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

// Slot i's shadow ray out of the lanes' light_pass, written into r (as spawn_ray_to ends it).
void lane_shadow_ray(const lanes::DiffuseVertices& v, int i, Ray& r) {
  r.o = Vec3(v.sox[i], v.soy[i], v.soz[i]);
  r.d = Vec3(v.sdx[i], v.sdy[i], v.sdz[i]);
  r.tmin = 0;
  r.tmax = kShadowRayEnd;
}

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
  // The draws of path_step's order (light samples, the BSDF's component pick, the bounce), taken
  // for all vertices at once: each sampler still sees its own draws in that order.
  for (size_t l = 0; l < nl; ++l)  // light sample l of every vertex: u_light[l n, (l + 1) n)
    Sampler::next_2d_many(samplers.data(), size_t(n), u_light.data() + l * size_t(n));
  for (Sampler* rng : samplers) rng->skip_1d();
  Sampler::next_2d_many(samplers.data(), size_t(n), u.data());
  for (int j = 0; j < padded; ++j) {
    const uint32_t i = which[j < n ? j : 0];  // padding lanes repeat the first vertex
    PathState& st = slots[i].st;
    const SurfaceHit& h = hits[i];
    const Material& m = scene.materials[h.material];
    const Vec3 albedo = m.albedo;  // textured materials are glTF's, never diffuse
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
    if (st.want_features) st.set_features(albedo, dot(h.ns, st.ray.d) > 0 ? -h.ns : h.ns);
    v.roulette[j] = st.bounce >= kRouletteStart;
    v.urr[j] = v.roulette[j] ? samplers[size_t(j)]->next_float() : 0.0f;
    st.start_diffuse_vertex();
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
        normal = facing_normal(light, normal, Vec3(v.px[j], v.py[j], v.pz[j]) - q);
        v.qx[j] = q.x, v.qy[j] = q.y, v.qz[j] = q.z;
        v.lx[j] = normal.x, v.ly[j] = normal.y, v.lz[j] = normal.z;
      }
    }
    lanes::light_pass(v, padded, light, settings.light_samples);
    shadows.make_room(size_t(n));  // at most a shadow ray a vertex
    const size_t first = shadows.n;
    for (int j = 0; j < n; ++j) {
      if (!v.shadow[j]) continue;
      lane_shadow_ray(v, j, shadows.rays[shadows.n]);
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
    st.took_diffuse_bounce(bounce, v.pdf[j], hits[i].p);
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
                   size_t n, Vec3* out, PathFeatures* features, uint64_t& rays) {
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
    std::vector<uint8_t> camera = std::vector<uint8_t>(kSlots);  // a slot's ray leaves the camera (unlit surfaces)
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
      slots[live].st.start(camera_rays[next], settings.max_depth, features != nullptr);
      slots[live].job = uint32_t(next);
    }
    if (live == 0) return;
    const size_t m = live;
    rays += m;
    // The rays where they lie in the slots (PathState::ray), not copied out.
    const bool unlit = scene.accel->has_unlit();  // only then does a ray's origin matter to Embree
    if (unlit)
      for (size_t i = 0; i < m; ++i) pool.camera[i] = slots[i].st.bounce == 0;
    scene.accel->intersect_many(&slots[0].st.ray, sizeof(Slot), m, hits.data(), found.data(),
                                unlit ? pool.camera.data() : nullptr);
    shadows.n = 0;
    size_t n_lanes = 0;  // slots the lanes take: a diffuse hit with depth left
    for (size_t i = 0; i < m; ++i) {
      if (use_lanes && found[i] && slots[i].st.depth_left > 0 &&
          scene.materials[hits[i].material].type == MaterialType::diffuse) {
        in_lanes[n_lanes++] = uint32_t(i);
        continue;
      }
      struct {  // the step's shadow rays, traced together after it
        ShadowBatch& batch;
        uint32_t slot;
        Ray& ray() {
          batch.make_room(1);
          return batch.rays[batch.n];
        }
        void add(Vec3 contribution) {
          Shadow& s = batch.pending[batch.n++];
          s.slot = slot;
          s.contribution = contribution;
        }
      } shadow{shadows, uint32_t(i)};
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
      if (features) features[slots[i].job] = {slots[i].st.albedo, slots[i].st.normal};
      if (next < n) {
        slots[i].st.start(camera_rays[next], settings.max_depth, features != nullptr);
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

// Textured scenes take the generic loop rather than eight more instantiations of each loop (build
// time, code size); they pay its run-time checks of the material kinds they lack.
PathTracer path_batch_tracer_for(uint32_t bits, const PathSettings& settings) {
  if (settings.hemisphere) return nullptr;  // -H casts its direct-light rays one at a time
  if (bits & kFeatTexture) return trace_paths_t<kFeatAll>;
  static const PathTracer table[] = {
      trace_paths_t<0>, trace_paths_t<1>, trace_paths_t<2>, trace_paths_t<3>,
      trace_paths_t<4>, trace_paths_t<5>, trace_paths_t<6>, trace_paths_t<7>,
  };
  static_assert(sizeof(table) / sizeof(table[0]) == kFeatTexture, "one instantiation per untextured feature combination");
  return table[bits & (kFeatTexture - 1)];
}

}  // namespace pt
