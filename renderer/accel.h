// Ray queries. Every intersection in the renderer goes through this interface; accel.cpp is the
// one file that includes Embree.
#pragma once

#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <vector>

#include "lane_math.h"
#include "math.h"
#include "scene.h"

namespace pt {

// A rectangle or triangle that emits and is visible to rays (area-light panels).
struct EmitterPanel {
  Vec3 v[4];       // corners; triangle panels repeat v[2] in v[3]
  bool quad = true;
  int material = -1;  // index into the materials list (emission)
  int light = -1;     // index into the render scene's lights
};

struct SurfaceHit {
  Vec3 p;            // hit point, refined from barycentrics or the sphere equation
  Vec3 ng;           // unit geometric normal: triangle winding side / sphere outside
  Vec3 ns;           // unit shading normal on the same side as ng
  int material = -1;
  int light = -1;    // >= 0 when the surface is an emitter registered as a light
  float offset = 0;  // how far to push spawned rays off the surface (scale-aware)
  // Where the hit lies on a mesh that carries attributes (uvs, colours, tangents): written only in
  // scenes with such meshes, read only by Accel::attributes for textured materials. The record
  // stays at 64 bytes, a power of two: the path loops index arrays of hits with a shift.
  uint32_t geom = 0, prim = 0;
  float bu = 0, bv = 0;  // barycentrics of vertices 1 and 2
};
static_assert(sizeof(SurfaceHit) == 64, "SurfaceHit: 64 bytes, a power of two");

// A mesh's vertex attributes interpolated at a hit (Accel::attributes): what the mesh lacks reads
// as uv (0, 0), colour white, no tangent.
struct HitAttributes {
  Vec2 uv[2];
  Vec3 color{1, 1, 1};
  Vec3 tangent;     // world space, not normalised; zero when the mesh has none
  float sign = 1;   // the bitangent's handedness
  float alpha = 1;  // COLOR_0's alpha (MeshDesc::color_alpha)
};

// Whether a ray that meets an alpha-tested material (PbrParams::alpha_tested) at a point with
// attributes `at` stops there; `u` is uniform in [0, 1), drawn from the ray and the triangle, for
// stochastic pass-through. Accel asks it during traversal, for every kind of ray.
using CoverageTest = std::function<bool(int material, const HitAttributes& at, float u)>;

class Accel {
 public:
  // Builds the acceleration structure once. `mesh_light` gives, per mesh and triangle, the light
  // index of emissive triangles (or -1); it may be empty. `coverage` decides the hits on
  // triangles of alpha-tested materials; without it they are opaque.
  Accel(const SceneDesc& scene, const std::vector<EmitterPanel>& panels,
        const std::vector<std::vector<int>>& mesh_light, CoverageTest coverage = {});
  ~Accel();
  Accel(const Accel&) = delete;
  Accel& operator=(const Accel&) = delete;

  // `camera`: the ray leaves the camera. Unlit surfaces (KHR_materials_unlit) are seen by camera
  // rays only, as Blender renders them: every other ray, shadow rays included, passes through.
  bool intersect(const Ray& ray, SurfaceHit& hit, bool camera = false) const;
  // The vertex attributes at a hit on a mesh that carries them (SurfaceHit::geom, prim, bu, bv).
  HitAttributes attributes(const SurfaceHit& hit) const;
  // True when anything blocks the ray within [ray.tmin, ray.tmax].
  bool occluded(const Ray& ray) const;
  // The same queries for n rays at once, traced in Embree packets of packet_width() rays (faster
  // than one at a time: docs/performance.md, "Ray packets"). found[i] / blocked[i] are 1 or 0;
  // hits[i] is written where found[i]. Packet traversal may round a few hits differently from the
  // single-ray kernel (5 in 100,000 random rays in the last bit of t, u, v or Ng; none of them
  // turned a hit into a miss).
  void intersect_many(const Ray* rays, size_t n, SurfaceHit* hits, uint8_t* found) const {
    intersect_many(rays, sizeof(Ray), n, hits, found);
  }
  // The same with ray i at byte offset i * stride from `rays`: rays inside the caller's records
  // (the path pool's states) are read where they are, not copied out first.
  // camera[i] (when given): ray i leaves the camera.
  void intersect_many(const Ray* rays, size_t stride, size_t n, SurfaceHit* hits, uint8_t* found,
                      const uint8_t* camera = nullptr) const;
  // Whether a ray's camera flag matters: the scene has unlit surfaces.
  bool has_unlit() const;
  void occluded_many(const Ray* rays, size_t n, uint8_t* blocked) const;
  // Rays per Embree packet in intersect_many / occluded_many: Embree's native width, 16 on
  // AVX-512 and 8 below it (loop_forms.h: the test build may take the other).
  int packet_width() const;
  // Bytes held for rendering: everything Embree allocated (BVH, vertex and index buffers, as its
  // memory monitor reports) plus our per-triangle shading data.
  size_t memory_bytes() const;
  // The box every hit lies in (the scene bounds, padded as the miss shortcut pads them); false when
  // the bounds are not finite (nothing may be assumed about misses then).
  bool hit_bounds(Vec3& lo, Vec3& hi) const;

  struct Impl;

 private:
  std::unique_ptr<Impl> m_impl;
};

// Ray origins pushed off the surface so that the ray cannot hit it again, in a scale-aware way
// (Waechter & Binder 2019): lane_physics.inc, which the lanes share.
using lane1::offset_ray_origin;

// A ray leaving the surface in direction d, origin pushed off to the side d points to.
// Rays that go into arrays are written in place (the out-parameter forms): a returned Ray is
// built with narrow stores and copied with wide loads, which cannot take their data from those
// stores and wait until they retire (docs/performance.md, "store forwarding").
// Always inlined: the path loops call these at every vertex, and LTO stopped inlining them on its
// own once the loops grew a little (0.7% more instructions on cornell, callgrind).
[[gnu::always_inline]] inline void spawn_ray(const SurfaceHit& hit, Vec3 d, Ray& r) {
  r.o = lane1::spawn_origin(hit.p, hit.ng, hit.offset, d);
  r.d = d;
  r.tmin = 0;
  r.tmax = kInf;
}
inline Ray spawn_ray(const SurfaceHit& hit, Vec3 d) {
  Ray r;
  spawn_ray(hit, d, r);
  return r;
}
// Where a shadow ray from spawn_ray_to ends, as a fraction of the way to its target: short of the
// target surface itself.
constexpr float kShadowRayEnd = 1 - 1e-4f;
// A shadow ray from the surface to a point on another surface (target excluded).
[[gnu::always_inline]] inline void spawn_ray_to(const SurfaceHit& hit, Vec3 target, Ray& r) {
  r.o = lane1::spawn_origin(hit.p, hit.ng, hit.offset, target - hit.p);
  r.d = target - r.o;
  r.tmin = 0;
  r.tmax = kShadowRayEnd;
}

}  // namespace pt
