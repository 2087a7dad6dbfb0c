// The path loop one path after another, and the specialised loops' tables (integrator.h). The vertex
// both loops run is path_vertex.h's; the pool of paths in packets is path_pool.cpp's.
#include "integrator.h"

#include "loop_forms.h"
#include "path_vertex.h"

namespace pt {

namespace {

using namespace path_loop;

// One path at a time: every ray query answered at once.
template <uint32_t F>
Vec3 trace_path_t(const RenderScene& scene, const PathSettings& settings, Ray ray, Sampler& rng, PathFeatures* features,
                  uint64_t& rays) {
  PathState st(ray, settings.max_depth, features != nullptr);
  struct {  // each shadow ray traced at once
    const Accel& accel;
    PathState& st;
    Ray r;
    Ray& ray() { return r; }
    void add(Vec3 contribution) {
      if (!accel.occluded(r)) st.direct_sum += contribution;
    }
  } shadow{*scene.accel, st, Ray()};
  for (;;) {
    SurfaceHit hit;
    ++rays;
    bool found = scene.accel->intersect(st.ray, hit, st.bounce == 0);
    bool more = path_step<F>(scene, settings, st, found, hit, rng, rays, shadow);
    st.resolve_direct();
    if (more) continue;
    if (features) *features = {st.albedo, st.normal};
    return st.radiance;
  }
}

template <uint32_t F>
void trace_paths_one_by_one(const RenderScene& scene, const PathSettings& settings, const Ray* camera_rays,
                            Sampler* rngs, size_t n, Vec3* out, PathFeatures* features, uint64_t& rays) {
  for (size_t i = 0; i < n; ++i)
    out[i] = trace_path_t<F>(scene, settings, camera_rays[i], rngs[i], features ? features + i : nullptr, rays);
}

}  // namespace

bool diffuse_lanes_apply(const RenderScene& scene, const PathSettings& settings) {
  if (!forms::lanes() || settings.hemisphere || settings.light_samples < 1) return false;
  for (const Light& light : scene.lights)  // the lanes know no other light
    if (light.kind != LightKind::rect && light.kind != LightKind::mesh) return false;
  return true;
}

bool packets_apply(const RenderParams& params) { return forms::packets() && !params.hemisphere; }

PathTracer path_tracer_for(uint32_t bits, const PathSettings& settings, bool packets) {
  if (packets)
    if (PathTracer pool = path_batch_tracer_for(bits, settings)) return pool;
  if (bits & kFeatTexture) return trace_paths_one_by_one<kFeatAll>;
  static const PathTracer table[] = {
      trace_paths_one_by_one<0>, trace_paths_one_by_one<1>, trace_paths_one_by_one<2>, trace_paths_one_by_one<3>,
      trace_paths_one_by_one<4>, trace_paths_one_by_one<5>, trace_paths_one_by_one<6>, trace_paths_one_by_one<7>,
  };
  static_assert(sizeof(table) / sizeof(table[0]) == kFeatTexture, "one instantiation per untextured feature combination");
  return table[bits & (kFeatTexture - 1)];
}

}  // namespace pt
