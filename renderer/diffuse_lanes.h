// The path loop's most common vertex, four paths at a time: a diffuse surface lit by area lights
// (rectangles and emissive meshes), then a cosine-weighted bounce. The same arithmetic as the scalar
// path_step (Frame, face_viewer, sample_light, diffuse_*, power_heuristic, spawn_ray*), operation
// for operation, in SSE2 lanes: the images are bit-identical. The pool gathers its diffuse vertices
// into these arrays, runs the lanes, and scatters the results back (integrator.cpp).
#pragma once

#include <cstdint>

#include "lights.h"

namespace pt::lanes {

constexpr int kMaxLanes = 256;  // the pool's slots

// Structure of arrays, one entry per vertex; the count is padded to a multiple of 4 by the caller.
struct DiffuseVertices {
  // In: the hit, the arriving ray's direction, the path's throughput and its random numbers.
  alignas(16) float px[kMaxLanes], py[kMaxLanes], pz[kMaxLanes];
  alignas(16) float gx[kMaxLanes], gy[kMaxLanes], gz[kMaxLanes];  // geometric normal, as Embree's hit
  alignas(16) float nx[kMaxLanes], ny[kMaxLanes], nz[kMaxLanes];  // shading normal
  alignas(16) float offset[kMaxLanes];
  alignas(16) float ax[kMaxLanes], ay[kMaxLanes], az[kMaxLanes];  // albedo
  alignas(16) float dx[kMaxLanes], dy[kMaxLanes], dz[kMaxLanes];  // arriving direction
  alignas(16) float bx[kMaxLanes], by[kMaxLanes], bz[kMaxLanes];  // throughput, replaced by the bounce's
  alignas(16) float ulx[kMaxLanes], uly[kMaxLanes];               // light sample (one light at a time)
  alignas(16) float qx[kMaxLanes], qy[kMaxLanes], qz[kMaxLanes];  // or the point it picked on a mesh light
  alignas(16) float lx[kMaxLanes], ly[kMaxLanes], lz[kMaxLanes];  // and the light's normal there
  alignas(16) float ubx[kMaxLanes], uby[kMaxLanes];               // BSDF sample
  alignas(16) float urr[kMaxLanes];                                // roulette; 2 where it is not played
  // Out of light_pass: whether a shadow ray is needed, the ray, and what it carries if unblocked.
  alignas(16) int shadow[kMaxLanes];
  alignas(16) float sox[kMaxLanes], soy[kMaxLanes], soz[kMaxLanes];
  alignas(16) float sdx[kMaxLanes], sdy[kMaxLanes], sdz[kMaxLanes];
  alignas(16) float cx[kMaxLanes], cy[kMaxLanes], cz[kMaxLanes];
  // Out of bounce_pass: whether the path goes on, its next ray (from o along the next direction),
  // and the BSDF pdf.
  alignas(16) int alive[kMaxLanes];
  alignas(16) float ox[kMaxLanes], oy[kMaxLanes], oz[kMaxLanes];
  alignas(16) float wx[kMaxLanes], wy[kMaxLanes], wz[kMaxLanes];
  alignas(16) float pdf[kMaxLanes];
};

// One of `samples` light samples per vertex from area light `light` (its color not black),
// MIS-weighted against the diffuse lobe, for vertices [0, n). A rectangle's points come from
// (ulx, uly); a mesh light's from (qx, qy, qz) and (lx, ly, lz), which the caller fills with
// sample_area_light_point (a discrete pick of a triangle: no lanes there).
void light_pass(DiffuseVertices& v, int n, const Light& light, int samples);
// The cosine-weighted bounce, throughput update and Russian roulette for vertices [0, n).
void bounce_pass(DiffuseVertices& v, int n);

}  // namespace pt::lanes
