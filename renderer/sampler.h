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

#include "math.h"
#include "rng.h"

namespace pt {

enum class SamplerKind { sobol, independent };

inline uint32_t reverse_bits32(uint32_t x) {
  x = __builtin_bswap32(x);
  x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
  x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
  x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
  return x;
}
// Reverses the bits of two 32-bit words at the cost of one: reverse_bits64(a << 32 | b) is
// reverse_bits32(b) << 32 | reverse_bits32(a).
inline uint64_t reverse_bits64(uint64_t x) {
  x = __builtin_bswap64(x);
  x = ((x & 0x0f0f0f0f0f0f0f0full) << 4) | ((x & 0xf0f0f0f0f0f0f0f0ull) >> 4);
  x = ((x & 0x3333333333333333ull) << 2) | ((x & 0xccccccccccccccccull) >> 2);
  x = ((x & 0x5555555555555555ull) << 1) | ((x & 0xaaaaaaaaaaaaaaaaull) >> 1);
  return x;
}

// Laine-Karras style permutation (each bit depends only on the bits below it), with the improved
// constants of Burley 2020, section 3.
inline uint32_t laine_karras_permutation(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}
// With bit reversal around it, a nested uniform (Owen) scramble (Burley 2020, listing 2).
inline uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
  return reverse_bits32(laine_karras_permutation(reverse_bits32(x), seed));
}

// The second Sobol dimension with its input and output bit-reversed: sobol_dim1_reversed(j) is
// reverse_bits32(sobol_dim1(reverse_bits32(j))). The generator matrix is linear over GF(2), and so
// is bit reversal: an XOR of one precomputed table entry per byte of j.
struct SobolDim1ReversedTables {
  uint32_t t[4][256] = {};
  constexpr SobolDim1ReversedTables() {
    uint32_t dir[32] = {};  // dir[k]: sobol_dim1 of index bit k (direction numbers of x^1 + 1)
    uint32_t v = 1u << 31;
    for (int k = 0; k < 32; ++k, v ^= v >> 1) dir[k] = v;
    for (int b = 0; b < 4; ++b)
      for (uint32_t x = 0; x < 256; ++x) {
        uint32_t r = 0;
        for (int q = 0; q < 8; ++q)
          if (x & (1u << q)) {
            uint32_t d = dir[31 - (8 * b + q)], rev = 0;  // bit 8b+q of j is bit 31-(8b+q) of the index
            for (int k = 0; k < 32; ++k) rev |= ((d >> k) & 1u) << (31 - k);
            r ^= rev;
          }
        t[b][x] = r;
      }
  }
};
inline constexpr SobolDim1ReversedTables kSobolDim1Reversed{};
inline uint32_t sobol_dim1_reversed(uint32_t j) {
  const auto& t = kSobolDim1Reversed.t;
  return t[0][j & 255] ^ t[1][(j >> 8) & 255] ^ t[2][(j >> 16) & 255] ^ t[3][j >> 24];
}
// The first two Sobol dimensions: van der Corput and its (0,2)-sequence partner.
inline uint32_t sobol_dim0(uint32_t i) { return reverse_bits32(i); }
inline uint32_t sobol_dim1(uint32_t i) { return reverse_bits32(sobol_dim1_reversed(reverse_bits32(i))); }

inline float u32_to_unit(uint32_t x) { return float(x >> 8) * 0x1p-24f; }  // [0, 1), never 1

// A cheap 32-bit integer hash (Wellons' "lowbias32") for per-dimension seeds.
inline uint32_t hash_u32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

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

  // Burley 2020, listing 2, with the bit reversals that cancel taken out: the shuffled index is
  // i = reverse(j), sobol_dim0(i) = j, and nested_uniform_scramble(j) = reverse(lk(i)).
  Vec2 next_2d() {
    if (m_dim >= kSobolDimensions) return rng().next_2d();
    uint32_t seed = hash_u32(m_base + 0x9e3779b9u * ++m_dim);
    uint32_t j = laine_karras_permutation(m_index_reversed, seed);
    uint32_t x = laine_karras_permutation(reverse_bits32(j), seed ^ 0xa511e9b3u);
    uint32_t y = laine_karras_permutation(sobol_dim1_reversed(j), seed ^ 0x63d83595u);
    uint64_t r = reverse_bits64(uint64_t(y) << 32 | x);  // reverse(x) << 32 | reverse(y)
    return {u32_to_unit(uint32_t(r >> 32)), u32_to_unit(uint32_t(r))};
  }
  float next_float() {
    if (m_dim >= kSobolDimensions) return rng().next_float();
    uint32_t seed = hash_u32(m_base + 0x9e3779b9u * ++m_dim);
    uint32_t j = laine_karras_permutation(m_index_reversed, seed);
    return u32_to_unit(reverse_bits32(laine_karras_permutation(reverse_bits32(j), seed ^ 0xa511e9b3u)));
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
  static void next_2d_many(Sampler* s, size_t n, Vec2* out, bool lanes = true);
  static void next_2d_many(Sampler* const* s, size_t n, Vec2* out, bool lanes = true);
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
