// The path loop one path at a time, and the specialised loops' tables (integrator.h). The vertex
// both loops run is path_vertex.h's; the pool of paths in packets is path_pool.cpp's.
#include "integrator.h"

#include "path_vertex.h"

namespace pt {

namespace {

using namespace path_loop;

// One path at a time: every ray query answered at once.
template <uint32_t F>
Vec3 trace_path_t(const RenderScene& scene, const PathSettings& settings, Ray ray, Sampler& rng, uint64_t& rays) {
  PathState st(ray, settings.max_depth);
  struct {  // each shadow ray traced at once
    const Accel& accel;
    PathState& st;
    Ray r;
    Ray& ray() { return r; }
    void add(Vec3 contribution) {
      if (!accel.occluded(r)) st.direct_sum += contribution;
    }
  } shadow{*scene.accel, st, Ray()};
  const bool diffuse_lit = diffuse_lanes_apply(scene, settings);
  for (;;) {
    SurfaceHit hit;
    ++rays;
    bool found = scene.accel->intersect(st.ray, hit, st.bounce == 0);
    bool more = path_step<F>(scene, settings, st, found, hit, rng, rays, shadow, diffuse_lit);
    st.resolve_direct();
    if (!more) return st.radiance;
  }
}


}  // namespace

bool diffuse_lanes_apply(const RenderScene& scene, const PathSettings& settings) {
  if (!scene.loop.lanes || settings.hemisphere || settings.light_samples < 1) return false;
  for (const Light& light : scene.lights)  // the lanes know no other light
    if (light.kind != LightKind::rect && light.kind != LightKind::mesh) return false;
  return true;
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
