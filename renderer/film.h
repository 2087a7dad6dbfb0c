// Sample passes that render on different machines and merge exactly. A pass is the whole frame
// rendered for sample indices [first, first + count) of every pixel not yet converged; since each
// sample's random numbers depend only on (seed, pixel, index), merging the per-pixel sums and
// counts of disjoint passes gives the image one machine would have made.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "image.h"
#include "render.h"

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
  uint64_t rays = 0, nonfinite = 0;
  double seconds = 0;

  // A compact little-endian encoding for the wire, and its strict inverse: decode throws
  // std::runtime_error saying what is wrong with a short, oversized or inconsistent buffer.
  std::string encode() const;
  static FilmPass decode(const std::string& bytes, int expect_width, int expect_height);
};

// Renders one pass. `skip` (one byte per pixel, may be empty) marks converged pixels; `cancel`
// stops early (the pass then holds what was done and comes back marked incomplete).
FilmPass render_film_pass(const RenderScene& scene, const RenderParams& params, uint32_t first, uint32_t count,
                          const std::vector<uint8_t>& skip, const std::atomic<bool>* cancel, bool* complete = nullptr);

// The merged image: what the server keeps while passes arrive from workers. Mirrors the session's
// statistics (mean, adaptive test, error estimate) over merged sums.
class FilmAccumulator {
 public:
  FilmAccumulator(const RenderParams& params, int width, int height);

  void merge(const FilmPass& pass);
  int width() const { return m_w; }
  int height() const { return m_h; }
  // Pixels that need no more samples: the sample budget is spent or, with adaptive sampling, the
  // course's confidence test passed on the merged statistics.
  const std::vector<uint8_t>& done() const { return m_done; }
  bool finished() const { return m_remaining == 0; }
  size_t remaining() const { return m_remaining; }  // pixels still taking samples
  double progress() const;
  double error_estimate() const;  // computed once after each merge
  uint64_t samples() const { return m_samples; }
  uint64_t rays() const { return m_rays; }
  uint64_t nonfinite() const { return m_nonfinite; }
  uint64_t light_paths() const { return m_lt_paths; }  // caustic light paths merged
  ImageRGB image() const;
  void read_tile(const Tile& t, std::vector<Vec3>& out) const;

 private:
  RenderParams m_params;
  int m_w, m_h;
  std::vector<Vec3> m_sum;
  std::vector<double> m_s1, m_s2;
  std::vector<uint32_t> m_count;
  // Passes alternate between two halves (by samples so far); the error estimate compares the
  // halves' means, as the session compares its power-of-two halves.
  std::vector<double> m_half_s1;
  std::vector<uint32_t> m_half_n;
  uint64_t m_half_samples = 0, m_other_samples = 0;
  std::vector<uint8_t> m_done;
  size_t m_remaining;
  // Caustic splat sums and their luminance, split into the same halves as the camera samples.
  std::vector<Vec3> m_lt_sum;
  std::vector<double> m_lt_s1, m_lt_half_s1;
  uint64_t m_lt_paths = 0, m_lt_half_paths = 0;
  CachedEstimate m_estimate;  // error_estimate() of what was merged so far
  Vec3 pixel_mean(size_t i) const;
  uint64_t m_samples = 0, m_rays = 0, m_nonfinite = 0;
};

// One byte per pixel <-> one bit per pixel, for sending the converged mask with each pass.
std::string pack_mask(const std::vector<uint8_t>& mask);
std::vector<uint8_t> unpack_mask(const std::string& bits, size_t pixels);

}  // namespace pt
