// The least a packet path tracer can do around Embree, as a yardstick for bench_ceiling's PT/raw:
// how close to the raw packet replay a loop gets that keeps nothing but the rays. A pool of 256
// paths (the path tracer's pool size), camera rays through the scene's own camera, one shadow ray a
// vertex to a point on the first light, a cosine-weighted bounce with a constant albedo, at
// most five hits a path, no roulette, no materials, no MIS, no sample statistics. Everything goes through Accel
// (intersect_many / occluded_many: packets of the native width, hit refinement included), as the
// path tracer's rays do. The path tracer's own work a ray over this loop's says how much of the
// gap to the raw ceiling its features cost; this loop's own ratio says what no loop of this shape
// would beat on the host.
#pragma once

#include <chrono>
#include <cstdint>
#include <vector>

#include "session.h"
#include "rng.h"
#include "sampling.h"

namespace bench {

struct MinimalLoopResult {
  uint64_t rays = 0;     // every ray passed to Accel (intersect and shadow)
  double seconds = 0;
  double radiance = 0;   // the sum of what the paths gathered, so that nothing is optimised away
};

// Traces spp paths through each of `pixels` (y w + x, y down) on the calling thread.
inline MinimalLoopResult minimal_loop_pass(const pt::RenderScene& scene, const std::vector<int>& pixels, int w, int h,
                                           int spp) {
  using namespace pt;
  struct Path {
    Ray ray;  // first, so that intersect_many reads the pool's rays in place
    Vec3 beta;
    int depth, pixel;
    Pcg32 rng;
  };
  constexpr size_t kPool = 256;
  constexpr int kHits = 5;  // m = 5, as bench_ceiling renders
  constexpr float kAlbedo = 0.6f;
  const Accel& accel = *scene.accel;
  std::vector<Path> pool(kPool);
  std::vector<SurfaceHit> hits(kPool);
  std::vector<uint8_t> found(kPool), blocked(kPool);
  std::vector<Ray> shadow(kPool);
  std::vector<size_t> shadow_path(kPool);
  std::vector<float> film(size_t(w) * size_t(h), 0.0f);
  // The shadow rays' target: a point on the first light when it has a position (area, point,
  // spot), else along the normal (directional and environment lights: an unbounded ray).
  const Light* light = scene.lights.empty() ? nullptr : &scene.lights[0];
  const bool aimed = light && !light->is_infinite();

  const uint64_t n_pixels = pixels.size(), total = n_pixels * uint64_t(spp);
  uint64_t next = 0;
  MinimalLoopResult r;
  size_t live = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (;;) {
    for (; live < kPool && next < total; ++next) {
      Path& s = pool[live++];
      s.pixel = pixels[size_t(next % n_pixels)];
      s.rng = make_sample_rng(1, uint64_t(s.pixel), next / n_pixels);
      const Vec2 u = s.rng.next_2d();
      scene.camera.generate_ray((float(s.pixel % w) + u.x) / float(w), 1 - (float(s.pixel / w) + u.y) / float(h),
                                s.rng.next_2d(), s.ray);
      s.beta = Vec3(1, 1, 1);
      s.depth = 0;
    }
    if (live == 0) break;
    accel.intersect_many(&pool[0].ray, sizeof(Path), live, hits.data(), found.data());
    size_t n_shadow = 0;
    for (size_t i = 0; i < live; ++i) {
      if (!found[i]) continue;
      const SurfaceHit& hit = hits[i];
      Path& s = pool[i];
      const Vec2 u = s.rng.next_2d();
      if (aimed)
        spawn_ray_to(hit, light->position + light->dim_x * (u.x - 0.5f) + light->dim_y * (u.y - 0.5f), shadow[n_shadow]);
      else
        spawn_ray(hit, dot(s.ray.d, hit.ns) < 0 ? hit.ns : -hit.ns, shadow[n_shadow]);
      shadow_path[n_shadow++] = i;
    }
    accel.occluded_many(shadow.data(), n_shadow, blocked.data());
    r.rays += live + n_shadow;
    for (size_t k = 0; k < n_shadow; ++k)
      if (!blocked[k]) film[size_t(pool[shadow_path[k]].pixel)] += pool[shadow_path[k]].beta.x;
    size_t kept = 0;  // the paths that go on, packed to the front of the pool
    for (size_t i = 0; i < live; ++i) {
      Path& s = pool[i];
      if (!found[i] || ++s.depth >= kHits) continue;
      const SurfaceHit& hit = hits[i];
      if (hit.light >= 0) film[size_t(s.pixel)] += s.beta.x;
      const Vec3 n = dot(s.ray.d, hit.ns) < 0 ? hit.ns : -hit.ns;
      const Vec3 d = Frame(n).to_world(sample_cosine_hemisphere(s.rng.next_2d()));
      s.beta = s.beta * kAlbedo;
      spawn_ray(hit, d, s.ray);
      if (kept != i) pool[kept] = s;
      ++kept;
    }
    live = kept;
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (float v : film) r.radiance += double(v);
  return r;
}

// The pixels a render session would query: those it does not know to see only background.
inline std::vector<int> scene_pixels(const pt::RenderScene& scene, const pt::RenderParams& params) {
  pt::RenderSession session(scene, params);
  std::vector<int> out;
  for (int y = 0; y < params.height; ++y)
    for (int x = 0; x < params.width; ++x)
      if (!session.sees_only_background(x, params.height - 1 - y)) out.push_back(y * params.width + x);
  return out;
}

}  // namespace bench
