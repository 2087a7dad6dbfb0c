// The path loop's most common vertex, many paths at a time: a diffuse surface lit by area lights
// (rectangles and emissive meshes), then a cosine-weighted bounce. The functions the scalar
// path_step calls (lane_physics.inc: Frame, face_viewer, sample_area_light, diffuse_*,
// power_heuristic, russian_roulette, spawn_origin), four at a time in SSE2 lanes or eight in AVX2
// where the CPU has it: the images are bit-identical. The pool gathers its diffuse vertices into
// these arrays, runs the lanes, and scatters the results back (integrator.cpp).
#pragma once

#include <cstdint>

#include "lights.h"

namespace pt::lanes {

constexpr int kMaxLanes = 256;  // the pool's slots

// Structure of arrays, one entry per vertex; the count is padded to a multiple of 8 by the caller.
struct DiffuseVertices {
  // In: the hit, the arriving ray's direction, the path's throughput and its random numbers.
  alignas(32) float px[kMaxLanes], py[kMaxLanes], pz[kMaxLanes];
  alignas(32) float gx[kMaxLanes], gy[kMaxLanes], gz[kMaxLanes];  // geometric normal, as Embree's hit
  alignas(32) float nx[kMaxLanes], ny[kMaxLanes], nz[kMaxLanes];  // shading normal
  alignas(32) float offset[kMaxLanes];
  alignas(32) float ax[kMaxLanes], ay[kMaxLanes], az[kMaxLanes];  // albedo
  alignas(32) float dx[kMaxLanes], dy[kMaxLanes], dz[kMaxLanes];  // arriving direction
  alignas(32) float bx[kMaxLanes], by[kMaxLanes], bz[kMaxLanes];  // throughput, replaced by the bounce's
  alignas(32) float ulx[kMaxLanes], uly[kMaxLanes];               // light sample (one light at a time)
  alignas(32) float qx[kMaxLanes], qy[kMaxLanes], qz[kMaxLanes];  // or the point it picked on a mesh light
  alignas(32) float lx[kMaxLanes], ly[kMaxLanes], lz[kMaxLanes];  // and the light's normal there
  alignas(32) float ubx[kMaxLanes], uby[kMaxLanes];               // BSDF sample
  alignas(32) int roulette[kMaxLanes];                             // whether Russian roulette is played
  alignas(32) float urr[kMaxLanes];                                // and its random number
  // Out of light_pass: whether a shadow ray is needed, the ray, and what it carries if unblocked.
  alignas(32) int shadow[kMaxLanes];
  alignas(32) float sox[kMaxLanes], soy[kMaxLanes], soz[kMaxLanes];
  alignas(32) float sdx[kMaxLanes], sdy[kMaxLanes], sdz[kMaxLanes];
  alignas(32) float cx[kMaxLanes], cy[kMaxLanes], cz[kMaxLanes];
  // Out of bounce_pass: whether the path goes on, its next ray (from o along the next direction),
  // and the BSDF pdf.
  alignas(32) int alive[kMaxLanes];
  alignas(32) float ox[kMaxLanes], oy[kMaxLanes], oz[kMaxLanes];
  alignas(32) float wx[kMaxLanes], wy[kMaxLanes], wz[kMaxLanes];
  alignas(32) float pdf[kMaxLanes];
};

// One of `samples` light samples per vertex from area light `light` (its color not black),
// MIS-weighted against the diffuse lobe, for vertices [0, n). A rectangle's points come from
// (ulx, uly); a mesh light's from (qx, qy, qz) and (lx, ly, lz), which the caller fills with
// sample_area_light_point (a discrete pick of a triangle: no lanes there).
void light_pass(DiffuseVertices& v, int n, const Light& light, int samples);
// The cosine-weighted bounce, throughput update and Russian roulette for vertices [0, n).
void bounce_pass(DiffuseVertices& v, int n);

// The lanes' width: 8 where the CPU has AVX2 (and simd::allow_avx2 allows it), else 4.
int lane_width();

}  // namespace pt::lanes
