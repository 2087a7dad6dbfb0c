// The path loop's most common vertex: a diffuse surface lit by area lights (rectangles and
// emissive meshes), then a cosine-weighted bounce. One text (diffuse_lanes_body.inc) in the
// vocabulary of lane_math.h, built on lane_physics.inc's functions (Frame, face_viewer,
// sample_area_light, diffuse_*, power_heuristic, russian_roulette, spawn_origin), compiled at
// two widths: 4 in SSE2 lanes and 8 in AVX2 lanes where the CPU has it (the pool's vertices,
// path_pool.cpp). Both compute the bits of path_step's generic vertex, which the path-by-path loop
// runs (test_packets.cpp). The pool gathers its diffuse vertices into these arrays, runs the
// lanes, and scatters the results back.
#pragma once

#include <cstdint>

#include "lights.h"

namespace pt::lanes {

constexpr int kMaxLanes = 256;  // the pool's slots

// Structure of arrays, one entry per vertex; the count is padded to a multiple of 8 by the caller.
template <int N>
struct DiffuseVerticesN {
  // In: the hit, the arriving ray's direction, the path's throughput and its random numbers.
  alignas(32) float px[N], py[N], pz[N];
  alignas(32) float gx[N], gy[N], gz[N];  // geometric normal, as Embree's hit
  alignas(32) float nx[N], ny[N], nz[N];  // shading normal
  alignas(32) float offset[N];
  alignas(32) float ax[N], ay[N], az[N];  // albedo
  alignas(32) float dx[N], dy[N], dz[N];  // arriving direction
  alignas(32) float bx[N], by[N], bz[N];  // throughput, replaced by the bounce's
  alignas(32) float ulx[N], uly[N];               // light sample (one light at a time)
  alignas(32) float qx[N], qy[N], qz[N];  // or the point it picked on a mesh light
  alignas(32) float lx[N], ly[N], lz[N];  // and the light's normal there
  alignas(32) float ubx[N], uby[N];               // BSDF sample
  alignas(32) int roulette[N];                             // whether Russian roulette is played
  alignas(32) float urr[N];                                // and its random number
  // Out of light_pass: whether a shadow ray is needed, the ray, and what it carries if unblocked.
  alignas(32) int shadow[N];
  alignas(32) float sox[N], soy[N], soz[N];
  alignas(32) float sdx[N], sdy[N], sdz[N];
  alignas(32) float cx[N], cy[N], cz[N];
  // Out of bounce_pass: whether the path goes on, its next ray (from o along the next direction),
  // and the BSDF pdf.
  alignas(32) int alive[N];
  alignas(32) float ox[N], oy[N], oz[N];
  alignas(32) float wx[N], wy[N], wz[N];
  alignas(32) float pdf[N];
};
using DiffuseVertices = DiffuseVerticesN<kMaxLanes>;

// One of `samples` light samples per vertex from area light `light` (its color not black),
// MIS-weighted against the diffuse lobe, for vertices [0, n). A rectangle's points come from
// (ulx, uly); a mesh light's from (qx, qy, qz) and (lx, ly, lz), which the caller fills with
// sample_area_light_point (a discrete pick of a triangle: no lanes there).
void light_pass(DiffuseVertices& v, int n, const Light& light, int samples);
// The cosine-weighted bounce, throughput update and Russian roulette for vertices [0, n).
void bounce_pass(DiffuseVertices& v, int n);

// The lanes' width: 8 where the CPU has AVX2 (forms::use_avx2, loop_forms.h), else 4.
int lane_width();

}  // namespace pt::lanes
