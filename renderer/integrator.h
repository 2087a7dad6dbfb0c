// The path loop: one camera path's radiance, one path at a time (integrator.cpp) or many at once in
// Embree packets (path_pool.cpp), both running path_vertex.h's vertex, specialised on the scene's
// feature bits. Below the session, which drives it.
#pragma once

#include <cstdint>

#include "render_scene.h"
#include "sampler.h"

namespace pt {

// What the path loop reads of the render options, and the session's choice of who renders the
// caustic paths: a small value the loop's every form takes instead of all of RenderParams.
struct PathSettings {
  int max_depth = 1;       // -m
  int light_samples = 1;   // -l
  bool hemisphere = false; // -H
  // The session's light tracer renders the paths E D+ S+ L (caustics.h), so the loop leaves them out.
  bool caustics_light_traced = false;

  PathSettings() = default;
  explicit PathSettings(const RenderParams& p, bool light_traced = false)
      : max_depth(p.max_depth), light_samples(p.light_samples), hemisphere(p.hemisphere),
        caustics_light_traced(light_traced) {}
};

// One camera path's radiance (integrator.cpp), by the generic loop. `rays` counts every ray cast.
Vec3 trace_path(const RenderScene& scene, const PathSettings& settings, Ray ray, class Sampler& rng, uint64_t& rays);
// The path loop specialised for a set of feature bits (one instantiation per combination).
using PathTracer = Vec3 (*)(const RenderScene&, const PathSettings&, Ray, class Sampler&, uint64_t&);
PathTracer path_tracer_for(uint32_t feature_bits);
// The same paths, many at once: traces camera_rays[0, n) with samplers rngs[0, n) (each already
// past its pixel and lens draws) and writes each path's radiance to out[i]. Rays go to Embree in
// packets (Accel::intersect_many). nullptr where the scalar loop must run (-H).
using PathBatchTracer = void (*)(const RenderScene&, const PathSettings&, const Ray* camera_rays, class Sampler* rngs,
                                 size_t n, Vec3* out, uint64_t& rays);
PathBatchTracer path_batch_tracer_for(uint32_t feature_bits, const PathSettings& settings);
// Whether diffuse vertices take the lanes' text (diffuse_lanes.h), in SIMD lanes in the batched
// loop and at width 1 in the path-by-path one: lanes on (LoopForms), every light an area light
// (rectangle or mesh), light sampling (not -H).
bool diffuse_lanes_apply(const RenderScene& scene, const PathSettings& settings);
// Whether packets take their Sobol draws eight at a time (Sampler::next_2d_many / sobol_draws):
// the Sobol sampler, lanes on, and a CPU with AVX2.
bool sobol_draws_in_lanes(const RenderScene& scene, const RenderParams& params);
// Whether the session traces camera paths in packets (LoopForms::packets, and not -H).
inline bool packets_apply(const RenderScene& scene, const RenderParams& params) {
  return scene.loop.packets && !params.hemisphere;
}

}  // namespace pt
