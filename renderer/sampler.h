// The per-sample random numbers of a camera path: an Owen-scrambled, shuffled 2D Sobol (0,2)
// sequence for every dimension pair ("padded" Sobol), or independent PCG32 numbers.
//
// Burley, "Practical Hash-based Owen Scrambling", JCGT 9(4), 2020: each pixel's sample index is
// shuffled by a nested uniform scramble and each dimension pair gets its own scrambled (0,2)
// sequence, so every pair is stratified over the pixel's samples and pairs are independent.
// The numbers depend only on (seed, pixel, sample index, dimension): images do not depend on the
// thread count or tile order.
#pragma once

#include <cstdint>
#include <optional>

#include "lane_math.h"
#include "math.h"
#include "rng.h"

namespace pt::lane1 {
#include "sobol.inc"
}  // namespace pt::lane1

namespace pt {

enum class SamplerKind { sobol, independent };

// The draws' integer hashes (sobol.inc, which the AVX2 lanes share), at width 1.
using lane1::hash_u32;
using lane1::laine_karras_permutation;
using lane1::u32_to_unit;
inline uint32_t reverse_bits32(uint32_t x) { return lane1::reverse_bits(x); }
// The second Sobol dimension, the (0,2)-sequence partner of van der Corput's bit reversal.
inline uint32_t sobol_dim1(uint32_t i) { return reverse_bits32(lane1::sobol_dim1_reversed_from_reversed(i)); }

class Sampler {
 public:
  // Past this many draws (pixel, lens, and light + BSDF samples of the first two vertices)
  // stratification buys little: the rest of the path uses the cheaper independent stream.
  static constexpr uint32_t kSobolDimensions = 8;

  // The independent stream is seeded on its first draw: most paths never get that far.
  Sampler(SamplerKind kind, uint64_t seed, uint64_t pixel, uint32_t sample)
      : Sampler(kind, seed, pixel, sample, pixel_base(seed, pixel), 0) {}
  // The same from the pixel's part of the state (pixel_base, computed once for all its samples),
  // as it is after `drawn` 2D draws that the caller took for it (sobol_draws; Sobol only).
  Sampler(SamplerKind kind, uint64_t seed, uint64_t pixel, uint32_t sample, uint32_t base, uint32_t drawn)
      : m_base(base), m_index_reversed(reverse_bits32(sample)),
        m_dim(kind == SamplerKind::independent ? kSobolDimensions : drawn), m_seed(seed), m_pixel(pixel),
        m_index(sample) {}
  static uint32_t pixel_base(uint64_t seed, uint64_t pixel) {
    return uint32_t(mix64(seed * 0x2545f4914f6cdd1dull + pixel));
  }

  // Burley 2020, listing 2 (lane1::sobol_2d), then the independent stream.
  Vec2 next_2d() {
    if (m_dim >= kSobolDimensions) return rng().next_2d();
    Vec2 u;
    lane1::sobol_2d(m_base, m_index_reversed, ++m_dim, u.x, u.y);
    return u;
  }
  float next_float() {
    if (m_dim >= kSobolDimensions) return rng().next_float();
    return lane1::sobol_1d(m_base, m_index_reversed, ++m_dim);
  }
  // Consumes the draw next_float() would return without computing it, for a number the caller
  // does not need: the draws after it stay the same.
  void skip_1d() {
    if (m_dim >= kSobolDimensions) rng().next_u32();
    else ++m_dim;
  }
  // The same for the pair next_2d() would return.
  void skip_2d() {
    if (m_dim >= kSobolDimensions) {
      rng().next_u32();
      rng().next_u32();
    } else {
      ++m_dim;
    }
  }

  // next_2d() of samplers s[0], ..., s[n - 1], bit for bit: the Sobol draws eight at a time in
  // AVX2 lanes where the CPU has them (sampler_lanes.cpp), the rest one at a time. `lanes` false
  // draws every one alone (for tests and comparisons).
  static void next_2d_many(Sampler* s, size_t n, Vec2* out);
  static void next_2d_many(Sampler* const* s, size_t n, Vec2* out);
  // Draw number `draw` (1 for the first) of the fresh Sobol samplers (base[i], sample[i]), i < n,
  // as their next_2d() would give it, without the samplers: for the camera's draws of many
  // samples at once. Needs lanes_available().
  static void sobol_draws(const uint32_t* base, const uint32_t* sample, size_t n, uint32_t draw, Vec2* out);
  // Whether next_2d_many and sobol_draws draw in lanes on this CPU.
  static bool lanes_available();

 private:
  friend struct SamplerLanes;
  Pcg32& rng() {
    if (!m_rng) m_rng.emplace(make_sample_rng(m_seed, m_pixel, m_index));
    return *m_rng;
  }

  uint32_t m_base;
  uint32_t m_index_reversed;
  uint32_t m_dim;
  uint64_t m_seed, m_pixel;
  uint32_t m_index;
  std::optional<Pcg32> m_rng;
};

}  // namespace pt
