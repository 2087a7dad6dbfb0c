// The path loop: one camera path's radiance, one path at a time (integrator.cpp) or many at once in
// Embree packets (path_pool.cpp), both running path_vertex.h's vertex, specialised on the scene's
// feature bits. Below the session, which drives it.
#pragma once

#include <cstdint>

#include "path_settings.h"
#include "render_scene.h"
#include "sampler.h"

namespace pt {

// A path's features for the denoiser (PathState::albedo, normal).
struct PathFeatures {
  Vec3 albedo, normal;
};

// Camera paths' radiance, by the path loop specialised for a set of feature bits (one
// instantiation per combination): traces camera_rays[0, n) with samplers rngs[0, n) (each already
// past its pixel and lens draws) and writes each path's radiance to out[i], and its features to
// features[i] unless `features` is null. `rays` counts every ray cast.
using PathTracer = void (*)(const RenderScene&, const PathSettings&, const Ray* camera_rays, class Sampler* rngs,
                            size_t n, Vec3* out, PathFeatures* features, uint64_t& rays);
// The tracer the session runs: the paths in a pool whose rays go to Embree in packets
// (Accel::intersect_many; path_pool.cpp) where `packets` and the settings allow it, else one path
// after another, each ray query answered at once (integrator.cpp).
PathTracer path_tracer_for(uint32_t feature_bits, const PathSettings& settings, bool packets);
// The pool alone: nullptr where the path-by-path loop must run (-H).
PathTracer path_batch_tracer_for(uint32_t feature_bits, const PathSettings& settings);
// Whether diffuse vertices take the lanes' text (diffuse_lanes.h), in SIMD lanes in the batched
// loop and at width 1 in the path-by-path one: every light an area light (rectangle or mesh),
// light sampling (not -H).
bool diffuse_lanes_apply(const RenderScene& scene, const PathSettings& settings);
// Whether packets take their Sobol draws eight at a time (Sampler::next_2d_many / sobol_draws):
// the Sobol sampler and a CPU with AVX2.
bool sobol_draws_in_lanes(const RenderParams& params);
// Whether the session traces camera paths in packets (not with -H).
bool packets_apply(const RenderParams& params);

}  // namespace pt
