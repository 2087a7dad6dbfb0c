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

// Laine-Karras style permutation; with bit reversal around it, a nested uniform (Owen) scramble
// (Burley 2020, listing 2, with the improved constants of that paper's section 3).
inline uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
  x = reverse_bits32(x);
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return reverse_bits32(x);
}

// The first two Sobol dimensions: van der Corput and its (0,2)-sequence partner.
inline uint32_t sobol_dim0(uint32_t i) { return reverse_bits32(i); }
// The generator matrix is linear over GF(2): XOR of one precomputed table entry per index byte.
struct SobolDim1Tables {
  uint32_t t[4][256];
  SobolDim1Tables() {
    uint32_t dir[32];
    uint32_t v = 1u << 31;
    for (int k = 0; k < 32; ++k, v ^= v >> 1) dir[k] = v;
    for (int b = 0; b < 4; ++b)
      for (uint32_t x = 0; x < 256; ++x) {
        uint32_t r = 0;
        for (int k = 0; k < 8; ++k)
          if (x & (1u << k)) r ^= dir[8 * b + k];
        t[b][x] = r;
      }
  }
};
inline uint32_t sobol_dim1(uint32_t i) {
  static const SobolDim1Tables tables;
  return tables.t[0][i & 255] ^ tables.t[1][(i >> 8) & 255] ^ tables.t[2][(i >> 16) & 255] ^ tables.t[3][i >> 24];
}

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

  Sampler(SamplerKind kind, uint64_t seed, uint64_t pixel, uint32_t sample)
      : m_kind(kind), m_base(uint32_t(mix64(seed * 0x2545f4914f6cdd1dull + pixel))), m_index(sample),
        m_rng(make_sample_rng(seed, pixel, sample)) {}

  Vec2 next_2d() {
    if (m_kind == SamplerKind::independent || m_dim >= kSobolDimensions) return m_rng.next_2d();
    uint32_t seed = hash_u32(m_base + 0x9e3779b9u * ++m_dim);
    uint32_t i = nested_uniform_scramble(m_index, seed);  // shuffle: decorrelates dimension pairs
    return {u32_to_unit(nested_uniform_scramble(sobol_dim0(i), seed ^ 0xa511e9b3u)),
            u32_to_unit(nested_uniform_scramble(sobol_dim1(i), seed ^ 0x63d83595u))};
  }
  float next_float() {
    if (m_kind == SamplerKind::independent || m_dim >= kSobolDimensions) return m_rng.next_float();
    uint32_t seed = hash_u32(m_base + 0x9e3779b9u * ++m_dim);
    uint32_t i = nested_uniform_scramble(m_index, seed);
    return u32_to_unit(nested_uniform_scramble(sobol_dim0(i), seed ^ 0xa511e9b3u));
  }

 private:
  SamplerKind m_kind;
  uint32_t m_base;
  uint32_t m_index;
  uint32_t m_dim = 0;
  Pcg32 m_rng;
};

}  // namespace pt
