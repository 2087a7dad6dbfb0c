// Caustics by light tracing: the paths light -> specular chain -> diffuse surface -> camera.
//
// A path tracer finds these paths only when a BSDF-sampled direction from the diffuse point
// happens to reach the (small) light through the specular chain, which makes them the bulk of the
// noise in scenes with glass and mirrors. Traced from the light instead (Veach 1997, section 10.2,
// "light tracing"), each such path reaches the camera by one connection. The two methods split
// the paths between them, so their sum is unbiased:
// - the path tracer drops emitter hits of area and mesh lights reached by one or more delta
//   bounces after one or more non-delta vertices, the first camera vertex among them (E D+ S+ L);
// - the light tracer produces exactly those paths: it leaves an area or mesh light, follows one or
//   more delta bounces, and connects every non-delta vertex after them to the camera (L S+ D+ E).
//   Where an emitter shares its plane with another surface, it keeps only the light points the
//   path tracer would see from its first vertex (emitters_share_a_plane).
// Light paths are aimed at bounding spheres of the delta geometry (a directional pdf over the cones
// they subtend), since every other direction starts a path the path tracer keeps.
#pragma once

#include <cstdint>
#include <vector>

#include "caustic_scene.h"
#include "math.h"

namespace pt {

struct Material;
struct RenderParams;
struct RenderScene;
struct SceneDesc;

// Whether a view of the scene with these options renders caustics by light tracing: it needs a
// delta material, an area or mesh light, more than one sample per pixel (one sample is the pixel
// centre, which splats cannot match), light sampling (not -H), and a pinhole or a thin lens
// focused at a positive distance.
bool caustic_tracing_applies(const RenderScene& scene, const RenderParams& params);

// Where on the film a point is seen: the full frame and the film window inside it (top-left).
struct CausticFilm {
  int frame_w = 0, frame_h = 0;
  int x0 = 0, y0 = 0, w = 0, h = 0;
};

struct CausticSplat {
  uint32_t pixel;  // film index, row-major from the top-left
  Vec3 value;      // to be divided by the number of light paths
};

// Traces light paths [first, first + count) (their random numbers depend only on the seed and the
// path's index) and appends their splats, in path order. Counts their rays in `rays`.
void trace_caustic_paths(const RenderScene& scene, const RenderParams& params, const CausticFilm& film,
                         uint64_t first, uint64_t count, std::vector<CausticSplat>& out, uint64_t& rays);

}  // namespace pt
