// Sample passes that render on different machines and merge exactly. A pass is the whole frame
// rendered for sample indices [first, first + count) of every pixel not yet converged; since each
// sample's random numbers depend only on (seed, pixel, index), merging the per-pixel sums and
// counts of disjoint passes (Film::merge) gives the image one machine would have made.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "math.h"

namespace pt {

struct FilmPass {
  int width = 0, height = 0;
  uint32_t first = 0, count = 0;   // the sample-index range asked for
  std::vector<Vec3> sum;           // radiance sums per pixel
  std::vector<float> lum2;         // luminance-squared sums (adaptive sampling's variance)
  std::vector<uint32_t> samples;   // samples taken per pixel (0 for skipped pixels)
  // Light-traced caustics (caustics.h): splat sums per pixel over `light_paths` paths, the pass's
  // share of them; empty when the job renders caustics by path tracing alone.
  std::vector<Vec3> caustic_sum;
  uint64_t light_paths = 0;
  // The denoiser's features (Film::add_features): albedo and normal sums per pixel; empty when
  // the job is not denoised.
  std::vector<Vec3> albedo_sum, normal_sum;
  uint64_t rays = 0, nonfinite = 0;
  double seconds = 0;

  // A compact little-endian encoding for the wire, and its strict inverse: decode throws
  // std::runtime_error saying what is wrong with a short, oversized or inconsistent buffer.
  std::string encode() const;
  static FilmPass decode(const std::string& bytes, int expect_width, int expect_height);
};

// One byte per pixel <-> one bit per pixel, for sending the converged mask with each pass.
std::string pack_mask(const std::vector<uint8_t>& mask);
std::vector<uint8_t> unpack_mask(const std::string& bits, size_t pixels);

}  // namespace pt
